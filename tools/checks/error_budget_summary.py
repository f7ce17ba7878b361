#!/usr/bin/env python3
"""The table of tools/bench-error-budget: bench_error_budget's lines of many sessions, added up.

  error_budget_summary.py CSV     (lines "seed,motion,...", "seed,extrinsic,...", "seed,final,...",
                                   "seed,feedback,...")

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


def solve(a, b):
    """x with a x = b (Gaussian elimination with partial pivoting; a is small and well conditioned)."""
    n = len(a)
    m = [row[:] + [b[i]] for i, row in enumerate(a)]
    for c in range(n):
        p = max(range(c, n), key=lambda r: abs(m[r][c]))
        m[c], m[p] = m[p], m[c]
        for r in range(n):
            if r != c and m[c][c] != 0:
                f = m[r][c] / m[c][c]
                m[r] = [x - f * y for x, y in zip(m[r], m[c])]
    return [m[i][n] / m[i][i] if m[i][i] != 0 else 0.0 for i in range(n)]


def shared_map(inputs, outputs):
    """The map M with outputs ~ M inputs (least squares over all motions): rows of M, one per output."""
    k = len(inputs[0])
    ata = [[sum(x[i] * x[j] for x in inputs) for j in range(k)] for i in range(k)]
    rows = []
    for o in range(3):
        atb = [sum(x[i] * y[o] for x, y in zip(inputs, outputs)) for i in range(k)]
        rows.append(solve(ata, atb))
    return rows


def rms(values):
    return math.sqrt(sum(v * v for v in values) / len(values))


def print_shared_maps(vectors):
    """d_rot = G w, d_t = H t + K w fitted over all motions of all sessions: the part every session shares."""
    print("\nShared maps of the motions' errors (d_rot = G w, d_t = H t + K w, least squares over all motions),")
    print("rms of the entries (all / off the diagonal):\n")
    print("| motions | G | H | K (mm/rad) |")
    print("|---|---|---|---|")
    for kind, rows in vectors.items():
        if len(rows) < 12:
            continue
        w = [r[6:9] for r in rows]
        G = shared_map(w, [r[0:3] for r in rows])
        HK = shared_map([r[9:12] + r[6:9] for r in rows], [r[3:6] for r in rows])
        H = [row[:3] for row in HK]
        K = [[1e3 * v for v in row[3:]] for row in HK]
        cell = []
        for M, form in ((G, ".1e"), (H, ".1e"), (K, ".2f")):
            entries = [v for row in M for v in row]
            off = [M[i][j] for i in range(3) for j in range(3) if i != j]
            cell.append(f"{rms(entries):{form}} / {rms(off):{form}}")
        print(f"| {kind} | " + " | ".join(cell) + " |")


def print_errors_by_axis(vectors):
    """Rotation errors of the motions grouped by the axis they mostly turn about (the sensor's own frame)."""
    print("\nRotation errors by the axis a motion mostly turns about: rms of d_rot (urad) about x, y, z\n")
    print("| motions | turning about | count | mean angle (deg) | x | y | z |")
    print("|---|---|---|---|---|---|---|")
    for kind, rows in vectors.items():
        groups = {}
        for r in rows:
            w = r[6:9]
            groups.setdefault(max(range(3), key=lambda k: abs(w[k])), []).append(r)
        for axis, group in sorted(groups.items()):
            angle = sum(math.sqrt(sum(v * v for v in r[6:9])) for r in group) / len(group) * 180 / math.pi
            cells = " | ".join(f"{1e6 * rms([r[c] for r in group]):.0f}" for c in range(3))
            print(f"| {kind} | {'xyz'[axis]} | {len(group)} | {angle:.1f} | {cells} |")


def main(path):
    motions = {"camera": [], "lidar": []}
    extrinsic = {"both": [], "camera": [], "lidar": []}
    shared = []  # the solve from both sensors, error / std with the shared errors in the std
    errors = {}  # seed -> case -> (6 errors, 6 std)
    feedback = []
    final = {}  # model -> per session, |error| / std of the pipeline's last result per axis
    vectors = {}  # kind -> [d_rot, d_t, w, t] per motion
    for line in open(path).read().splitlines():
        f = line.split(",")
        if len(f) < 3:
            continue
        if f[1] == "motion":
            motions[f[2]].append((float(f[6]), float(f[8])))
            if len(f) >= 21:
                vectors.setdefault(f[2], []).append([float(x) for x in f[9:21]])
        elif f[1] == "extrinsic":
            v = [float(x) for x in f[3:15]]
            errors.setdefault(f[0], {})[f[2]] = (v[:6], v[6:])
        elif f[1] == "feedback":
            feedback.append(float(f[2]))
        elif f[1] == "final":
            v = [float(x) for x in f[3:15]]
            final.setdefault(f[2], []).append([abs(v[k]) / v[k + 6] if v[k + 6] > 0 else math.inf for k in range(6)])
    # In units of the std the user gets (both sensors' solve), so that the rows add up.
    for cases in errors.values():
        if "both" not in cases:
            continue
        std = cases["both"][1]
        for case, (error, own_std) in cases.items():
            if case == "shared":
                shared.append([error[k] / own_std[k] for k in range(6)])
            else:
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
    print_shared_maps(vectors)
    print_errors_by_axis(vectors)
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
            cells.append(f"{mean:+.2f} ({t:+.1f}), {rms(column):.2f}")
        print(f"| {label[case]} | " + " | ".join(cells) + " |")
    for title, rows in (("std from the residuals alone", extrinsic["both"]), ("with the shared errors", shared)):
        if rows:
            within = [100.0 * sum(abs(r[k]) <= 1.0 for r in rows) / len(rows) for k in range(6)]
            print(f"\nWithin one std ({title}): " + ", ".join(
                f"{name} {w:.0f} %" for name, w in zip(["rot x", "rot y", "rot z", "t x", "t y", "t z"], within)))
    if final:
        print("\nThe pipeline's last results within one std (logged: as reported; other models: the camera's shared")
        print("errors of --model, each axis's std scaled by that model's over the pipeline's own, at the final pairs)\n")
        print("| model | sessions | rot x | rot y | rot z | t x | t y | t z |")
        print("|---|---|---|---|---|---|---|---|")
        for model, rows in final.items():
            within = [100.0 * sum(r[k] <= 1.0 for r in rows) / len(rows) for k in range(6)]
            print(f"| {model} | {len(rows)} | " + " | ".join(f"{w:.0f} %" for w in within) + " |")
        print("\nThe same results' rms of error / std per axis (1 for an honest std; above 1: the std too small)\n")
        print("| model | sessions | rot x | rot y | rot z | t x | t y | t z |")
        print("|---|---|---|---|---|---|---|---|")
        for model, rows in final.items():
            ratios = [rms([r[k] for r in rows]) for k in range(6)]
            print(f"| {model} | {len(rows)} | " + " | ".join(f"{q:.2f}" for q in ratios) + " |")
    if feedback:
        feedback.sort()
        print(f"\nFeedback of the alternation, largest |eigenvalue| of J: median {feedback[len(feedback) // 2]:.3f}, "
              f"max {feedback[-1]:.3f} over {len(feedback)} sessions")


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: error_budget_summary.py CSV")
    main(sys.argv[1])
