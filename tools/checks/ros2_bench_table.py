#!/usr/bin/env python3
"""The table of tools/bench-ros2: per run (peer, QoS and bus) what reached fusecal-ros2-input and how fast,
when the last EXTRINSIC came after the peer's last sample (both on this host's clock), and every stage's
realtime factor beside the live replay of the same log.

For a stream of several passes (--minutes), also the first minute against the last: how far stations and
answers lag behind the stream, and each process's resident memory (WORK_DIR/RUN.memory.csv).

Usage: ros2_bench_table.py WORK_DIR OUT_CSV RUN...   (WORK_DIR/RUN/ is a `fusecal run --ros2` output
folder, WORK_DIR/RUN.play.json what the peer published, WORK_DIR/replay/ the baseline)."""
import csv
import json
import os
import subprocess
import sys


def ros2_input_counters(session_log):
    """The last STATUS counters of ros2_input in a session log."""
    dump = subprocess.run(["build/bin/fusecal", "log", "dump", session_log, "--channel", "STATUS", "--full"],
                          capture_output=True, text=True, check=False).stdout
    counters = {}
    for line in dump.splitlines():
        message = json.loads(line).get("msg", {})
        if message.get("name") == "ros2_input":
            counters = message.get("counters", {})
    return counters


def realtime_factors(stages_csv):
    if not os.path.exists(stages_csv):
        return {}
    with open(stages_csv) as f:
        return {row["stage"]: float(row["realtime_factor"]) for row in csv.DictReader(f)}


def result_line(text_file):
    with open(text_file) as f:
        for line in f:
            if line.startswith("result:"):
                return line[len("result:"):].strip()
    return "no result"


def play_summary(play_json):
    """The peer's closing line: what it published and when its first and last sample left."""
    try:
        with open(play_json) as f:
            return json.loads(f.read().strip().splitlines()[-1])
    except (OSError, ValueError, IndexError):
        return {}


def published(line):
    """Images and clouds the peer published, and when its last sample left (unix seconds), from its closing
    line (play_summary)."""
    counts = line.get("published")
    if counts is None:
        return None, None, None
    images = sum(n for topic, n in counts.items() if "image" in topic)
    clouds = sum(n for topic, n in counts.items() if "points" in topic)
    return images, clouds, line.get("end_unix_s")


def dump(session_log, channel):
    out = subprocess.run(["build/bin/fusecal", "log", "dump", session_log, "--channel", channel],
                         capture_output=True, text=True, check=False).stdout
    return [json.loads(line) for line in out.splitlines() if line.strip()]


ROUND_ENDED = {"converged", "not_converged", "degenerate", "failed"}


def lags(session_log, play):
    """(stream time, lag) per station, in seconds from the end of its stop as the peer published it
    (first_utime left at start_unix_s, at recorded pace): when the STATION reached the session log, and
    when the pipeline had dealt with it (as `run` paces a replay): both motions ending at it out and then
    a round ended (an EXTRINSIC converged, not converged, degenerate or failed)."""
    start, first = play["start_unix_s"], play["first_utime"]

    def wall(stamp_utime):
        return start + (stamp_utime - first) * 1e-6

    stop_end, motions_out = {}, {}
    station_lags, answer_lags = [], []
    for event in dump(session_log, "^STATION$"):
        m = event["msg"]
        stop_end[m["id"]] = wall(m["still_to_utime"])
        station_lags.append((stop_end[m["id"]] - start, event["utime"] * 1e-6 - stop_end[m["id"]]))
    for channel in ("^LIDAR_MOTION$", "^CAMERA_MOTION$"):
        for event in dump(session_log, channel):
            motions_out.setdefault(event["msg"]["station_j"], []).append(event["utime"] * 1e-6)
    round_ends = sorted(e["utime"] * 1e-6 for e in dump(session_log, "^EXTRINSIC$")
                        if e["msg"]["status"] in ROUND_ENDED)
    for station, times in motions_out.items():
        if station not in stop_end or len(times) < 2:
            continue
        both_out = sorted(times)[1]
        settled = next((t for t in round_ends if t >= both_out), None)
        if settled is not None:
            answer_lags.append((stop_end[station] - start, settled - stop_end[station]))
    return station_lags, answer_lags


def windows(samples, length_s=60.0):
    """The samples of the first and of the last `length_s` seconds of the stream."""
    if not samples:
        return [], []
    end = max(t for t, _ in samples)
    return [v for t, v in samples if t < length_s], [v for t, v in samples if t >= end - length_s]


def median(values):
    values = sorted(values)
    return values[len(values) // 2] if values else float("nan")


def memory_windows(memory_csv):
    """Per process: the most resident memory (MB) in the first and in the last minute."""
    if not os.path.exists(memory_csv):
        return {}
    per_process = {}
    with open(memory_csv) as f:
        for row in csv.DictReader(f):
            per_process.setdefault(row["process"], []).append((float(row["elapsed_s"]), float(row["rss_mb"])))
    return {p: tuple(max(w, default=float("nan")) for w in windows(samples)) for p, samples in per_process.items()}


def print_long_stream(work, runs):
    """First minute against last, for the runs whose peer played more than one pass."""
    long_runs = [r for r in runs if play_summary(os.path.join(work, r + ".play.json")).get("passes", 1) > 1]
    if not long_runs:
        return
    print()
    print("| run, stream length | station out after its stop, first / last minute: median, max (s) | "
          "station dealt with after its stop, first / last minute: median, max (s) | "
          "resident memory, first / last minute (MB) |")
    print("|---|---|---|---|")
    for run in long_runs:
        play = play_summary(os.path.join(work, run + ".play.json"))
        station_lags, answer_lags = lags(os.path.join(work, run, "session.lcmlog"), play)

        def figures(samples):
            first, last = windows(samples)
            return (f"{median(first):.2f}, {max(first, default=float('nan')):.2f} / "
                    f"{median(last):.2f}, {max(last, default=float('nan')):.2f}")

        memory = memory_windows(os.path.join(work, run + ".memory.csv"))
        memory_text = "; ".join(f"{p.replace('fusecal-', '')} {a:.0f} / {b:.0f}" for p, (a, b) in sorted(memory.items()))
        length = play["end_unix_s"] - play["start_unix_s"]
        print(f"| {run}, {length / 60:.1f} min ({play['passes']} passes) | {figures(station_lags)} | "
              f"{figures(answer_lags)} | {memory_text} |")


def last_answer_utime(session_log):
    """When the run logged its last EXTRINSIC (the session log's receive time, microseconds since 1970)."""
    dump = subprocess.run(["build/bin/fusecal", "log", "dump", session_log, "--channel", "^EXTRINSIC$"],
                          capture_output=True, text=True, check=False).stdout
    lines = [line for line in dump.splitlines() if line.strip()]
    return json.loads(lines[-1])["utime"] if lines else None


def main():
    work, out_csv, runs = sys.argv[1], sys.argv[2], sys.argv[3:]
    replay = realtime_factors(os.path.join(work, "replay", "stages.csv"))
    rows, factors = [], {"replay (log, live)": replay}
    for run in runs:
        c = ros2_input_counters(os.path.join(work, run, "session.lcmlog"))
        play = play_summary(os.path.join(work, run + ".play.json"))
        images, clouds, end_unix_s = published(play)
        last = last_answer_utime(os.path.join(work, run, "session.lcmlog"))
        row = {
            "run": run,
            "images_published": images, "images_received": int(c.get("image_received", 0)),
            "clouds_published": clouds, "clouds_received": int(c.get("cloud_received", 0)),
            "image_latency_mean_ms": 1000 * c.get("image_latency_mean_s", float("nan")),
            "image_latency_max_ms": 1000 * c.get("image_latency_max_s", float("nan")),
            "cloud_latency_mean_ms": 1000 * c.get("cloud_latency_mean_s", float("nan")),
            "cloud_latency_max_ms": 1000 * c.get("cloud_latency_max_s", float("nan")),
            # what the stage judged lost from stamp gaps, less the gaps the player's turns leave (--minutes)
            "judged_lost": int(c.get("image_lost", 0) + c.get("cloud_lost", 0))
                           - int(play.get("stamp_gaps", 0)),
            "malformed": int(c.get("image_malformed", 0) + c.get("cloud_malformed", 0)),
            "last_answer_after_stream_s": (last * 1e-6 - end_unix_s) if last and end_unix_s else float("nan"),
            "result": result_line(os.path.join(work, run + ".txt")),
        }
        rows.append(row)
        factors[run] = realtime_factors(os.path.join(work, run, "stages.csv"))
    with open(out_csv, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0].keys()) if rows else ["run"])
        writer.writeheader()
        writer.writerows(rows)

    def fraction(received, sent):
        return f"{received}/{sent} ({100.0 * received / sent:.1f} %)" if sent else f"{received}/?"

    print("| peer, QoS, bus | images delivered | clouds delivered | image latency mean / max (ms) | "
          "cloud latency mean / max (ms) | judged lost | last answer after the stream (s) | result |")
    print("|---|---:|---:|---:|---:|---:|---:|---|")
    for r in rows:
        print(f"| {r['run']} | {fraction(r['images_received'], r['images_published'])} | "
              f"{fraction(r['clouds_received'], r['clouds_published'])} | "
              f"{r['image_latency_mean_ms']:.1f} / {r['image_latency_max_ms']:.1f} | "
              f"{r['cloud_latency_mean_ms']:.1f} / {r['cloud_latency_max_ms']:.1f} | {r['judged_lost']} | "
              f"{r['last_answer_after_stream_s']:.2f} | {r['result']} |")
    print()
    stages = sorted({s for f in factors.values() for s in f})
    print("| realtime factor (busy / stream time) | " + " | ".join(factors) + " |")
    print("|---|" + "---:|" * len(factors))
    for stage in stages:
        print(f"| {stage} | " + " | ".join(f"{f[stage]:.3f}" if stage in f else "-" for f in factors.values()) + " |")
    print_long_stream(work, runs)


if __name__ == "__main__":
    main()
