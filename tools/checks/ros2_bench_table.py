#!/usr/bin/env python3
"""The table of tools/bench-ros2: per run (peer, QoS and bus) what reached fusecal-ros2-input and how fast,
when the last EXTRINSIC came after the peer's last sample (both on this host's clock), and every stage's
realtime factor beside the live replay of the same log.

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


def published(play_json):
    """Images and clouds the peer published, and when its last sample left (unix seconds)."""
    try:
        with open(play_json) as f:
            line = json.loads(f.read().strip().splitlines()[-1])
        counts = line["published"]
    except (OSError, ValueError, KeyError, IndexError):
        return None, None, None
    images = sum(n for topic, n in counts.items() if "image" in topic)
    clouds = sum(n for topic, n in counts.items() if "points" in topic)
    return images, clouds, line.get("end_unix_s")


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
        images, clouds, end_unix_s = published(os.path.join(work, run + ".play.json"))
        last = last_answer_utime(os.path.join(work, run, "session.lcmlog"))
        row = {
            "run": run,
            "images_published": images, "images_received": int(c.get("image_received", 0)),
            "clouds_published": clouds, "clouds_received": int(c.get("cloud_received", 0)),
            "image_latency_mean_ms": 1000 * c.get("image_latency_mean_s", float("nan")),
            "image_latency_max_ms": 1000 * c.get("image_latency_max_s", float("nan")),
            "cloud_latency_mean_ms": 1000 * c.get("cloud_latency_mean_s", float("nan")),
            "cloud_latency_max_ms": 1000 * c.get("cloud_latency_max_s", float("nan")),
            "judged_lost": int(c.get("image_lost", 0) + c.get("cloud_lost", 0)),
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


if __name__ == "__main__":
    main()
