"""Group a py-spy profile by stage: where the wall time of an episode or an SC generation goes.

Usage:
    py-spy record -r 100 -f raw -o episode.folded -- .venv/bin/python -m scone_bt.cli.run --seed 0 --quiet
    .venv/bin/python tools/profile_stages.py episode.folded [more.folded ...]

Each sample (a stack, root first) is put in the stage of the frame nearest the leaf that matches a rule below, so
physics stepped while a motion executes counts as physics, and a render inside `perceive` as rendering. A sample
with an import frame anywhere counts as imports (a lazy import in the middle of an episode is start-up cost paid
late). Prints a Markdown table: stage, samples, share of all samples.
"""

from __future__ import annotations

import argparse
import re
import sys
from collections import Counter
from pathlib import Path

# (stage, pattern on one frame "function (file:line)"); the first rule that matches a frame wins for that frame.
RULES: tuple[tuple[str, re.Pattern[str]], ...] = (
    ("physics stepping", re.compile(r"scone_bt/world/kitchen\.py|stepSimulation|scone_bt/world/physics")),
    ("rendering (camera images)", re.compile(r"scone_bt/(perception|world)/camera\.py|getCameraImage")),
    ("perception (markers, observe)", re.compile(r"scone_bt/perception/")),
    ("planning (OMPL, IK, grasps, ruckig)", re.compile(r"scone_bt/motion/|scone_bt/grasp|ompl|ruckig")),
    ("embedding", re.compile(r"scone_bt/embedding/|sentence_transformers|torch/")),
    ("self-confidence fit", re.compile(r"scone_bt/confidence/")),
    (
        "scene set-up (shelf, robot load)",
        re.compile(r"scone_bt/stocking/shelf\.py|scone_bt/robot/sim\.py|setup \("),
    ),
    ("recording (rerun)", re.compile(r"scone_bt/viz/|rerun/")),
    (
        "behaviour tree, gate, human",
        re.compile(r"py_trees/|scone_bt/behaviours/|scone_bt/gate/|scone_bt/human/"),
    ),
)
_IMPORT = re.compile(r"_find_and_load|_call_with_frames_removed \(<frozen importlib")
# A thread pool worker blocked on its queue is idle, but py-spy sees a Python frame there and counts it.
_IDLE_LEAF = re.compile(r"^_worker \(concurrent/futures/thread\.py:81\)|^Condition\.wait \(threading\.py")
# The episode loop's main thread caught between two timed parts: after a long PyBullet call it hands the GIL to the
# planner thread and waits to get it back, so py-spy samples it in WallClock.__exit__/__enter__.
_GIL_WAIT_LEAF = re.compile(r"^WallClock\.__(exit|enter)__ ")
IDLE = "idle (not counted)"


def stage_of(frames: list[str]) -> str:
    """The stage of one sample (frames root first)."""
    if _IDLE_LEAF.search(frames[-1]):
        return IDLE
    if _GIL_WAIT_LEAF.search(frames[-1]):
        return "main thread waiting for the GIL (planner thread runs)"
    if any(_IMPORT.search(f) for f in frames):
        return "start-up / imports"
    for frame in reversed(frames):
        for stage, pattern in RULES:
            if pattern.search(frame):
                return stage
    return "other (argument parsing, store, reporting)"


def count(paths: list[Path], thread: str | None = None) -> Counter[str]:
    """Samples per stage over py-spy raw (collapsed) files: one 'frame;frame;... N' line per distinct stack.

    ``thread``: "main" keeps only the main thread's stacks, "other" only the others' (None: all).
    """
    stages: Counter[str] = Counter()
    for path in paths:
        for line in path.read_text().splitlines():
            stack, _, n = line.rpartition(" ")
            if not stack.strip() or not n.isdigit():
                continue  # py-spy writes a line with an empty stack for samples it could not unwind
            frames = stack.split(";")
            if frames[0].startswith("process "):
                frames = frames[1:]  # py-spy --subprocesses names the process first
                if not frames:
                    continue
            is_other = frames[0].startswith("Thread._bootstrap")
            if thread == "main" and is_other or thread == "other" and not is_other:
                continue
            stages[stage_of(frames)] += int(n)
    return stages


def table(stages: Counter[str]) -> str:
    """Markdown table, largest stage first."""
    stages = Counter({s: n for s, n in stages.items() if s != IDLE})
    total = sum(stages.values()) or 1
    rows = ["| stage | samples | share |", "|---|---:|---:|"]
    rows += [f"| {s} | {n} | {100 * n / total:.1f} % |" for s, n in stages.most_common()]
    rows.append(f"| total | {total} | 100 % |")
    return "\n".join(rows)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("folded", nargs="+", type=Path, help="py-spy record -f raw output files")
    parser.add_argument(
        "--thread", choices=("main", "other"), help="only the main thread's or the others' stacks"
    )
    args = parser.parse_args(argv)
    print(table(count(args.folded, args.thread)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
