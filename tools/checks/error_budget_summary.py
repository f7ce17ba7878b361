#!/usr/bin/env python3
"""The table of tools/bench-error-budget: bench_error_budget's lines of many sessions, added up.

  error_budget_summary.py CSV     (lines "seed,motion,...", "seed,extrinsic,...", "seed,feedback,...")

A mean far from zero in units of its standard error (|t| > 3) is a bias: the same error in every session,
which no uncertainty computed from one session's residuals can see.
"""
import math
import sys


def mean_t(values):
    n = len(values)
    mean = sum(values) / n
    sd = math.sqrt(sum((v - mean) ** 2 for v in values) / max(n - 1, 1))
    return mean, (mean / (sd / math.sqrt(n)) if sd > 0 else float("nan"))


def main(path):
    motions = {"camera": [], "lidar": []}
    extrinsic = {"both": [], "camera": [], "lidar": []}
    errors = {}  # seed -> case -> (6 errors, 6 std)
    feedback = []
    for line in open(path).read().splitlines():
        f = line.split(",")
        if len(f) < 3:
            continue
        if f[1] == "motion":
            motions[f[2]].append((float(f[6]), float(f[8])))
        elif f[1] == "extrinsic":
            v = [float(x) for x in f[3:15]]
            errors.setdefault(f[0], {})[f[2]] = (v[:6], v[6:])
        elif f[1] == "feedback":
            feedback.append(float(f[2]))
    # In units of the std the user gets (both sensors' solve), so that the rows add up.
    for cases in errors.values():
        if "both" not in cases:
            continue
        std = cases["both"][1]
        for case, (error, _) in cases.items():
            extrinsic[case].append([error[k] / std[k] for k in range(6)])
    sessions = len(extrinsic["both"])
    print(f"{sessions} sessions")
    print("\nMotions at the true extrinsic (camera: fused again at the truth; LiDAR: as logged)\n")
    print("| motions | count | angle error, mean (mdeg) | t | length error, mean (%) | t |")
    print("|---|---|---|---|---|---|")
    for kind, rows in motions.items():
        if not rows:
            continue
        angle, t_angle = mean_t([r[0] * 1e3 for r in rows])
        length, t_length = mean_t([r[1] * 100 for r in rows])
        print(f"| {kind} | {len(rows)} | {angle:+.2f} | {t_angle:+.1f} | {length:+.3f} | {t_length:+.1f} |")
    print("\nError of one scaled solve at the truth over the std of the solve from both sensors: mean (t), rms\n")
    print("| motions from | rot x | rot y | rot z | t x | t y | t z |")
    print("|---|---|---|---|---|---|---|")
    label = {"both": "both sensors", "camera": "camera (LiDAR true)", "lidar": "LiDAR (camera true)"}
    for case, rows in extrinsic.items():
        if not rows:
            continue
        cells = []
        for k in range(6):
            column = [r[k] for r in rows]
            mean, t = mean_t(column)
            rms = math.sqrt(sum(v * v for v in column) / len(column))
            cells.append(f"{mean:+.2f} ({t:+.1f}), {rms:.2f}")
        print(f"| {label[case]} | " + " | ".join(cells) + " |")
    if feedback:
        feedback.sort()
        print(f"\nFeedback of the alternation, largest |eigenvalue| of J: median {feedback[len(feedback) // 2]:.3f}, "
              f"max {feedback[-1]:.3f} over {len(feedback)} sessions")


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: error_budget_summary.py CSV")
    main(sys.argv[1])
