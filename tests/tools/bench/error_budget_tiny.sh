#!/usr/bin/env bash
# The error budget on a calibration of the tiny scenario: each motion fused again at the true extrinsic,
# and each LiDAR motion, is within 0.1 deg and 2 cm (along its translation) of the truth; the solve from
# both sensors is within 5 std of the truth; the shared errors widen its std of t (they never narrow
# one); the alternation contracts at the truth (every |eigenvalue| of its feedback < 1); the summary
# adds the lines up.
# Usage: error_budget_tiny.sh BIN_DIR WORK_DIR
set -euo pipefail
bin="$1" work="$2"
root="$(cd "$(dirname "$0")/../../.." && pwd)"
rm -rf "$work" && mkdir -p "$work"
"$bin/fusecal" simulate --scenario "$root/configs/scenarios/tiny-equirect.yaml" --out "$work/sim.lcmlog" >/dev/null
"$bin/fusecal" calibrate --log "$work/sim.lcmlog" --out "$work/out" >/dev/null
"$bin/bench_error_budget" "$work/out/session.lcmlog" --feedback | sed 's/^/1,/' >"$work/budget.csv"
cat "$work/budget.csv"
python3 - "$work/budget.csv" <<'PY'
import sys
lines = [l.split(",") for l in open(sys.argv[1]).read().splitlines()]
motions = [l for l in lines if l[1] == "motion"]
assert len(motions) >= 6, f"{len(motions)} motion lines, expected both sensors' of at least 3 pairs"
for l in motions:
    assert abs(float(l[6])) < 0.1 and abs(float(l[7]) * float(l[8])) < 0.02, f"motion error too large: {l}"
both = [l for l in lines if l[1:3] == ["extrinsic", "both"]]
assert len(both) == 1, "no solve from both sensors"
v = [float(x) for x in both[0][3:15]]
assert all(abs(v[k]) < 5 * v[k + 6] for k in range(6)), f"extrinsic beyond 5 std: {v}"
shared = [l for l in lines if l[1:3] == ["extrinsic", "shared"]]
assert len(shared) == 1, "no solve with the shared errors"
s = [float(x) for x in shared[0][3:15]]
assert all(s[k + 6] >= v[k + 6] * (1 - 1e-9) for k in range(6)), f"shared errors lowered a std: {s} vs {v}"
assert any(s[k + 6] > v[k + 6] for k in range(3, 6)), f"shared errors add nothing to t: {s} vs {v}"
feedback = [l for l in lines if l[1] == "feedback"]
assert feedback and max(float(x) for x in feedback[0][2:]) < 1.0, f"feedback does not contract: {feedback}"
PY
summary="$(python3 "$root/tools/checks/error_budget_summary.py" "$work/budget.csv")"
echo "$summary"
grep -q "^1 sessions$" <<<"$summary"
grep -q "^Shared maps" <<<"$summary"
echo "error budget: ok"
