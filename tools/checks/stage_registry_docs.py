#!/usr/bin/env python3
"""The docs against the stage registry (stages/stages.def): a stage the docs name must be in it, and what
they say of the stages must be what it says.

- Wherever README.md or docs/*.md say "the stages, in start order:" (docs/architecture.md must), the
  list that follows is exactly the registry's names, in its order.
- Every executable `fusecal-<name>` in README.md and docs/*.md is a registry stage's (fusecal-<stage with
  dashes>) or one of the project's other executables (OTHER_EXECUTABLES), or a name the docs give to
  something else (NOT_EXECUTABLES).
- The channel table of docs/design.md (section 3): in the "published by" and "subscribed by" columns,
  each item (comma separated, its parentheses aside) is a registry stage or starts with one of the words
  of NOT_STAGES; the stages named for a channel are exactly those whose registry entry publishes or
  subscribes to it, and every channel the registry names has its row.

Usage: stage_registry_docs.py [SOURCE_DIR]   (default: this checkout). Prints each disagreement; exit 1
if there is any."""
import glob
import os
import re
import sys

OTHER_EXECUTABLES = {"fusecal-bus-bridge", "fusecal-bench-transport"}
NOT_EXECUTABLES = {"fusecal-a", "fusecal-b"}  # docs/transport.md: network namespaces
NOT_STAGES = ("sensor", "log", "or", "every", "the", "never", "simulator", "importers", "coordinator")


def registry(source_dir):
    """[(name, channels_in, channels_out)] in start order."""
    stages = []
    with open(os.path.join(source_dir, "stages", "stages.def")) as f:
        for line in f:
            if line.startswith("FUSECAL_STAGE("):
                name = line[len("FUSECAL_STAGE("):].split(",")[0].strip()
                quoted = re.findall(r'"([^"]*)"', line)
                stages.append((name, set(quoted[1].split()), set(quoted[2].split())))
    return stages


def doc_paths(source_dir):
    return [os.path.join(source_dir, "README.md")] + sorted(glob.glob(os.path.join(source_dir, "docs", "*.md")))


def stage_list_problems(source_dir, names):
    problems = []
    architecture = os.path.join(source_dir, "docs/architecture.md")
    for path in doc_paths(source_dir):
        if not os.path.exists(path):
            continue
        lists = re.findall(r"the stages, in start order[^:]*:(.*?)\.(?:\s|$)", open(path).read(), re.S | re.I)
        if path == architecture and not lists:
            problems.append(f"{path}: no 'The stages, in start order:' listing the stages")
        for text in lists:
            listed = re.findall(r"`([a-z0-9_]+)`", text)
            if listed != names:
                problems.append(f"{path}: lists the stages {listed}; the registry (stages/stages.def) has {names}")
    return problems


def executable_problems(source_dir, names):
    known = {"fusecal-" + n.replace("_", "-") for n in names} | OTHER_EXECUTABLES | NOT_EXECUTABLES
    problems = []
    for path in doc_paths(source_dir):
        if not os.path.exists(path):
            continue
        for number, line in enumerate(open(path), 1):
            for executable in re.findall(r"\bfusecal-[a-z0-9]+(?:-[a-z0-9]+)*", line):
                if executable not in known:
                    problems.append(f"{path}:{number}: names {executable}, which is no stage of the registry "
                                    "(stages/stages.def) and no other executable of the project")
    return problems


def items(column):
    """The items of a table cell: comma separated, parentheses and backticks aside, lower case."""
    column = re.sub(r"\([^)]*\)", "", column).replace("`", "")
    return [item.strip() for part in column.split(";") for item in part.split(",") if item.strip()]


def channel_table_problems(source_dir, stages):
    path = os.path.join(source_dir, "docs/design.md")
    names = {name for name, _, _ in stages}
    problems, rows = [], set()
    for number, line in enumerate(open(path), 1):
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) != 5 or not re.fullmatch(r"[A-Z_]+", cells[0]):
            continue
        channel = cells[0]
        rows.add(channel)
        for column, side, label in ((cells[3], 2, "published by"), (cells[4], 1, "subscribed by")):
            named = set()
            for item in items(column):
                word = item.split()[0]
                if word in names:
                    named.add(word)
                elif not word.startswith(NOT_STAGES):
                    problems.append(f"{path}:{number}: {channel} {label} '{item}': no stage of the registry")
            expected = {name for name, *channels in stages if channel in channels[side - 1]}
            if named != expected:
                problems.append(f"{path}:{number}: {channel} {label} names the stages {sorted(named)}; the registry "
                                f"(stages/stages.def) has {sorted(expected)}")
    for channel in sorted(set().union(*(i | o for _, i, o in stages)) - rows):
        problems.append(f"{path}: the channel table has no row for {channel}, which the registry's stages use")
    return problems


def main():
    source_dir = os.path.normpath(sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", ".."))
    stages = registry(source_dir)
    names = [name for name, _, _ in stages]
    problems = (stage_list_problems(source_dir, names) + executable_problems(source_dir, names) +
                channel_table_problems(source_dir, stages))
    for problem in problems:
        print(problem)
    if problems:
        print(f"stage registry: {len(problems)} disagreement(s) between the docs and stages/stages.def")
        return 1
    print(f"stage registry: the docs name the {len(names)} stages of stages/stages.def and their channels")
    return 0


if __name__ == "__main__":
    sys.exit(main())
