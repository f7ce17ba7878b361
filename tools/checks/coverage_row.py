#!/usr/bin/env python3
"""One row of tools/bench-coverage: the true error of a result in the covariance's coordinates.

  coverage_row.py SEED RESULT.yaml GROUND_TRUTH_JSON   -> a CSV row
  coverage_row.py --summary CSV                        -> the coverage table

The covariance of extrinsic.yaml is over [d_rot ; d_t] with R = R_hat Exp(d_rot), t = t_hat + d_t
(docs/design.md section 2), so the true error is d_rot = Log(R_hat^T R_true), d_t = t_true - t_hat.
"""
import json
import math
import re
import sys


def read_list(text, key):
    match = re.search(r"^" + key + r": \[([^\]]*)\]", text, re.M)
    return [float(v) for v in match.group(1).split(",")] if match else None


def matmul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3)] for i in range(3)]


def transpose(a):
    return [[a[j][i] for j in range(3)] for i in range(3)]


def log_so3(r):
    cos = max(-1.0, min(1.0, (r[0][0] + r[1][1] + r[2][2] - 1.0) / 2.0))
    angle = math.acos(cos)
    v = [r[2][1] - r[1][2], r[0][2] - r[2][0], r[1][0] - r[0][1]]
    factor = 0.5 if angle < 1e-9 else angle / (2.0 * math.sin(angle))
    return [factor * x for x in v]


def row(seed, result_path, truth_json):
    try:
        text = open(result_path).read()
    except OSError:
        return f"{seed},missing" + ",nan" * 12
    status = re.search(r"^status: (\S+)", text, re.M).group(1)
    m = read_list(text, "T_camera_lidar")
    cov = read_list(text, "covariance")
    truth = json.loads(truth_json)["msg"]["T_camera_lidar"]
    r_hat = [m[0:3], m[4:7], m[8:11]]
    r_true = [truth[0:3], truth[4:7], truth[8:11]]
    d_rot = log_so3(matmul(transpose(r_hat), r_true))
    d_t = [truth[3] - m[3], truth[7] - m[7], truth[11] - m[11]]
    sigmas = [math.sqrt(max(cov[7 * k], 0.0)) if cov else float("nan") for k in range(6)]
    values = d_rot + d_t + sigmas
    return f"{seed},{status}," + ",".join(f"{v:.6g}" for v in values)


def summary(csv_path):
    rows = [line.strip().split(",") for line in open(csv_path).read().splitlines()[1:]]
    rows = [r for r in rows if r[1] == "converged"]
    names = ["rot x", "rot y", "rot z", "t x", "t y", "t z"]
    print(f"{len(rows)} converged results")
    print("| axis | within 1 sigma | median sigma | median abs error |")
    print("|---|---:|---:|---:|")
    totals = {"rotation": [0, 0], "translation": [0, 0]}
    for k, name in enumerate(names):
        errors = [abs(float(r[2 + k])) for r in rows]
        sigmas = [float(r[8 + k]) for r in rows]
        inside = sum(e <= s for e, s in zip(errors, sigmas))
        group = "rotation" if k < 3 else "translation"
        totals[group][0] += inside
        totals[group][1] += len(rows)
        unit, scale = ("deg", 180 / math.pi) if k < 3 else ("mm", 1000.0)
        median = lambda v: sorted(v)[len(v) // 2] if v else float("nan")
        print(f"| {name} | {100.0 * inside / max(len(rows), 1):.0f} % | {median(sigmas) * scale:.4f} {unit} "
              f"| {median(errors) * scale:.4f} {unit} |")
    for group, (inside, count) in totals.items():
        print(f"{group}: {100.0 * inside / max(count, 1):.1f} % within 1 sigma (target 68 %, band 55-80 %)")


if __name__ == "__main__":
    if sys.argv[1] == "--summary":
        summary(sys.argv[2])
    else:
        print(row(sys.argv[1], sys.argv[2], sys.argv[3]))
