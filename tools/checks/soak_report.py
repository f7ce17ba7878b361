#!/usr/bin/env python3
"""The sampler and the table of tools/bench-soak (a long live session: does memory stay flat, does the
output folder grow as expected, does the station-to-extrinsic latency hold up after hundreds of stations).

  soak_report.py --sample WORK_DIR RUN_DIR ANCESTOR_PID T0 BIN_DIR
      once per second until ANCESTOR_PID is gone (or SIGTERM/SIGINT): appends the RSS of each fusecal
      process to WORK_DIR/rss.csv (t_s,process,pid,rss_mb) and the bytes under RUN_DIR to
      WORK_DIR/disk.csv (t_s,bytes); t_s is seconds since T0 (epoch seconds). Counted: processes whose
      executable lies in BIN_DIR and is named fusecal or fusecal-* (the name is the executable's basename,
      /proc/PID/comm truncates to 15 characters) and that descend from ANCESTOR_PID, so fusecal runs of
      other checkouts, and other runs of this one, are left out.
  soak_report.py WORK_DIR
      reads WORK_DIR/{rss.csv,disk.csv,soak.meta,run.txt,run/latency.csv,soak-eval.json,baseline-eval.json},
      writes WORK_DIR/summary.csv (one row per process, one row `pipeline`) and prints the table.
"""
import csv
import json
import math
import os
import re
import signal
import subprocess
import sys
import time

CHECKPOINT_STATION = 100  # memory should be flat after this many stations
LAST_STATIONS = 100       # the latency p95 of the last this many stations

COLUMNS = ["process", "pids", "peak_rss_mb", "rss_at_checkpoint_mb", "rss_end_mb", "rss_growth_mb",
           "stations", "answered", "unanswered", "checkpoint_station", "checkpoint_t_s",
           "latency_p95_s", "latency_p95_last100_s", "out_bytes_end", "out_bytes_peak",
           "rot_err_deg", "trans_err_mm", "baseline_rot_err_deg", "baseline_trans_err_mm",
           "replay_speed", "wall_s", "wall_over_span"]


# ---------------------------------------------------------------------------------------------- sampler

def read_ppid(pid):
    try:
        with open(f"/proc/{pid}/stat") as f:
            stat = f.read()
    except OSError:
        return None
    # pid (comm) state ppid ...: comm may hold spaces and parentheses, so split after the last ')'
    return int(stat[stat.rfind(")") + 2:].split()[1])


def fusecal_name(pid, bin_dir):
    """The executable's basename when it is BIN_DIR/fusecal or BIN_DIR/fusecal-*, else None."""
    try:
        exe = os.readlink(f"/proc/{pid}/exe")
    except OSError:
        return None
    if exe.endswith(" (deleted)"):  # the binary was rebuilt while the process ran
        exe = exe[:-len(" (deleted)")]
    name = os.path.basename(exe)
    if os.path.dirname(exe) != bin_dir or not (name == "fusecal" or name.startswith("fusecal-")):
        return None
    return name


def rss_mb(pid):
    try:
        with open(f"/proc/{pid}/status") as f:
            for line in f:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1]) / 1024.0
    except OSError:
        pass
    return None


def descends_from(pid, ancestor, ppids):
    while pid and pid in ppids:
        if pid == ancestor:
            return True
        pid = ppids[pid]
    return pid == ancestor


def folder_bytes(path):
    if not os.path.isdir(path):
        return 0
    # du may complain about files that vanish while it walks; its total is still good
    out = subprocess.run(["du", "-sb", path], capture_output=True, text=True, check=False).stdout
    return int(out.split()[0]) if out.split() else 0


def sample(work, run_dir, ancestor, t0, bin_dir):
    stop = []
    signal.signal(signal.SIGTERM, lambda *_: stop.append(1))
    signal.signal(signal.SIGINT, lambda *_: stop.append(1))
    bin_dir = os.path.realpath(bin_dir)
    with open(os.path.join(work, "rss.csv"), "w") as rss, open(os.path.join(work, "disk.csv"), "w") as disk:
        rss.write("t_s,process,pid,rss_mb\n")
        disk.write("t_s,bytes\n")
        tick = 0
        while not stop:
            try:
                os.kill(ancestor, 0)
            except OSError:
                break
            t = time.time() - t0
            pids = [int(p) for p in os.listdir("/proc") if p.isdigit()]
            candidates = {pid: fusecal_name(pid, bin_dir) for pid in pids}
            candidates = {pid: name for pid, name in candidates.items() if name}
            if candidates:
                ppids = {}
                for pid in pids:
                    ppid = read_ppid(pid)
                    if ppid is not None:
                        ppids[pid] = ppid
                for pid, name in sorted(candidates.items()):
                    mb = rss_mb(pid)
                    if mb is not None and pid != ancestor and descends_from(pid, ancestor, ppids):
                        rss.write(f"{t:.1f},{name},{pid},{mb:.1f}\n")
            disk.write(f"{t:.1f},{folder_bytes(run_dir)}\n")
            rss.flush()
            disk.flush()
            # the next whole second after T0; ticks missed on a busy machine are skipped
            tick = max(tick + 1, math.floor(time.time() - t0) + 1)
            delay = t0 + tick - time.time()
            if delay > 0 and not stop:
                time.sleep(delay)


# ----------------------------------------------------------------------------------------------- report

def read_csv(path):
    if not os.path.exists(path):
        return []
    with open(path) as f:
        return list(csv.DictReader(f))


def read_meta(path):
    meta = {}
    if os.path.exists(path):
        with open(path) as f:
            for line in f:
                key, _, value = line.strip().partition("=")
                if key:
                    meta[key] = value
    return meta


def read_error(path):
    """(rot_err_deg, trans_err_mm) from the JSON of `fusecal evaluate`, or (None, None)."""
    try:
        with open(path) as f:
            error = json.loads(f.read().strip().splitlines()[0])
        return float(error["rot_err_deg"]), float(error["trans_err_m"]) * 1000.0
    except (OSError, ValueError, KeyError, IndexError):
        return None, None


def p95(values):
    """Nearest-rank 95th percentile (None when there are no values)."""
    if not values:
        return None
    ordered = sorted(values)
    return ordered[max(0, math.ceil(0.95 * len(ordered)) - 1)]


def fmt(value, digits=1):
    if value is None:
        return ""
    if isinstance(value, (int, str)):
        return str(value)
    return f"{value:.{digits}f}"


def process_rows(rss_rows, t_checkpoint):
    """Per process name (summed over its pids at each sample, a restarted stage gets a new pid): peak,
    at the checkpoint, at the end. Also the same for the sum over all processes (the `pipeline` row)."""
    series, pids, totals = {}, {}, {}
    for row in rss_rows:
        t, name, mb = float(row["t_s"]), row["process"], float(row["rss_mb"])
        series.setdefault(name, {})
        series[name][t] = series[name].get(t, 0.0) + mb
        pids.setdefault(name, set()).add(row["pid"])
        totals[t] = totals.get(t, 0.0) + mb
    rows = {}
    for name, by_time in sorted(series.items()):
        times = sorted(by_time)
        at_checkpoint = None
        if t_checkpoint is not None:
            after = [t for t in times if t >= t_checkpoint]
            # the first sample after the checkpoint; the last one if the process ended before it
            at_checkpoint = by_time[after[0]] if after else by_time[times[-1]]
        end = by_time[times[-1]]
        rows[name] = {"process": name, "pids": len(pids[name]), "peak_rss_mb": max(by_time.values()),
                      "rss_at_checkpoint_mb": at_checkpoint, "rss_end_mb": end,
                      "rss_growth_mb": None if at_checkpoint is None else end - at_checkpoint}
    total = {"peak_rss_mb": max(totals.values()) if totals else None}
    if rows:
        total["rss_end_mb"] = sum(r["rss_end_mb"] for r in rows.values())
        if t_checkpoint is not None:
            total["rss_at_checkpoint_mb"] = sum(r["rss_at_checkpoint_mb"] for r in rows.values())
            total["rss_growth_mb"] = total["rss_end_mb"] - total["rss_at_checkpoint_mb"]
        total["pids"] = sum(r["pids"] for r in rows.values())
    return rows, total


def report(work):
    meta = read_meta(os.path.join(work, "soak.meta"))
    speed = float(meta.get("speed", "1"))
    latency = read_csv(os.path.join(work, "run", "latency.csv"))
    answered = [r for r in latency if int(r["extrinsic_version"]) >= 0]
    checkpoint_station = min(CHECKPOINT_STATION, len(latency))
    # The wall clock of a station's end, approximated as end_s / speed after the start of the run (the
    # replay really starts after the stages are up, `startup` in run.txt's time line, well under a second
    # of the soak's hundreds; the RSS samples are a second apart anyway).
    t_checkpoint = float(latency[checkpoint_station - 1]["end_s"]) / speed if checkpoint_station else None

    procs, total = process_rows(read_csv(os.path.join(work, "rss.csv")), t_checkpoint)
    disk = [int(r["bytes"]) for r in read_csv(os.path.join(work, "disk.csv"))]
    rot, trans = read_error(os.path.join(work, "soak-eval.json"))
    base_rot, base_trans = read_error(os.path.join(work, "baseline-eval.json"))
    wall_over_span = None
    run_txt = os.path.join(work, "run.txt")
    if os.path.exists(run_txt):
        with open(run_txt) as f:
            match = re.search(r"^time: .*\(([0-9.]+) x the recording", f.read(), re.M)
            wall_over_span = float(match.group(1)) if match else None

    latencies = [float(r["latency_s"]) for r in answered]
    last = [float(r["latency_s"]) for r in latency[-LAST_STATIONS:] if int(r["extrinsic_version"]) >= 0]
    pipeline = dict(total, process="pipeline", stations=len(latency), answered=len(answered),
                    unanswered=len(latency) - len(answered), checkpoint_station=checkpoint_station or None,
                    checkpoint_t_s=t_checkpoint, latency_p95_s=p95(latencies), latency_p95_last100_s=p95(last),
                    out_bytes_end=disk[-1] if disk else None, out_bytes_peak=max(disk) if disk else None,
                    rot_err_deg=rot, trans_err_mm=trans, baseline_rot_err_deg=base_rot,
                    baseline_trans_err_mm=base_trans, replay_speed=speed,
                    wall_s=float(meta["wall_s"]) if meta.get("wall_s") else None, wall_over_span=wall_over_span)
    digits = {"checkpoint_t_s": 1, "latency_p95_s": 3, "latency_p95_last100_s": 3, "rot_err_deg": 4,
              "trans_err_mm": 3, "baseline_rot_err_deg": 4, "baseline_trans_err_mm": 3, "replay_speed": 2,
              "wall_s": 1, "wall_over_span": 2}
    rows = list(procs.values()) + [pipeline]
    with open(os.path.join(work, "summary.csv"), "w") as f:
        f.write(",".join(COLUMNS) + "\n")
        for row in rows:
            f.write(",".join(fmt(row.get(c), digits.get(c, 1)) for c in COLUMNS) + "\n")

    table = [["process", "pids", "peak_rss_mb", "rss_at_checkpoint_mb", "rss_end_mb", "rss_growth_mb"]]
    for row in rows:
        table.append([row["process"]] + [fmt(row.get(c)) for c in table[0][1:]])
    widths = [max(len(r[i]) for r in table) for i in range(len(table[0]))]
    for r in table:
        print("  ".join(r[0].ljust(widths[0]) if i == 0 else r[i].rjust(widths[i]) for i in range(len(r))))
    print(f"(pipeline: the sum over the processes; checkpoint: the end of station {checkpoint_station}, "
          f"~{fmt(t_checkpoint)} s into the run)" if checkpoint_station else "(no station: no checkpoint)")

    def mb(value):
        return "" if value is None else f"{value / 1e6:.1f} MB"
    lines = [
        ("stations", f"{len(latency)} ({len(answered)} answered, {len(latency) - len(answered)} unanswered)"),
        ("latency p95", f"{fmt(p95(latencies), 3)} s all, {fmt(p95(last), 3)} s last {min(LAST_STATIONS, len(latency))}"),
        ("output folder", f"{mb(pipeline['out_bytes_end'])} at the end, {mb(pipeline['out_bytes_peak'])} peak"),
        ("error, soak", f"{fmt(rot, 4)} deg, {fmt(trans, 3)} mm"),
        ("error, 10-motion baseline", f"{fmt(base_rot, 4)} deg, {fmt(base_trans, 3)} mm"),
        ("wall", f"{fmt(pipeline['wall_s'])} s at speed {fmt(speed, 2)} ({fmt(wall_over_span, 2)} x the recording)"),
    ]
    width = max(len(k) for k, _ in lines)
    for key, value in lines:
        print(f"{key.ljust(width)}  {value}")


def main(argv):
    if len(argv) == 7 and argv[1] == "--sample":
        sample(argv[2], argv[3], int(argv[4]), float(argv[5]), argv[6])
    elif len(argv) == 2 and not argv[1].startswith("-"):
        report(argv[1])
    else:
        sys.exit("usage: soak_report.py WORK_DIR | soak_report.py --sample WORK_DIR RUN_DIR ANCESTOR_PID T0 BIN_DIR")


if __name__ == "__main__":
    main(sys.argv)
