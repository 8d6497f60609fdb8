"""What a slide-and-pinch skill could take off the help rate, per recorded stream, from `slide_and_pinch_check.py`'s
results (JSON).

For each scored decision (row index ≥ ``--warmup``) of a dataset whose target is a flat pack wider than the gripper
on a lowest tier (the only tier where the pinch is reachable: `edge_pinch_reach.py`), it looks up whether that
product was slid, pinched and lifted with that profile's gripper (its force and pads' friction,
tools/profiles/<profile>.yaml, the robot file's where the profile keeps them) on ``--engine``. The rows held are
decisions that could end without the person fetching the product, so ``help_rate_drop_at_most`` is their share of
the scored decisions: an upper bound, as if the robot attempted each such pack and the slide, the pinch and the
carry to the table all went as in the check (which places the pack alone and moves in straight joint-space lines).

    PYTHONPATH=$PWD python tools/wide_pack_gain.py \\
        --datasets tools/data/sc_probe tools/data/sc_heldout_probe tools/data/sc_heldout2_probe \\
        --results docs/results/slide_and_pinch.jsonl docs/results/slide_and_pinch_profiles.jsonl
"""

from __future__ import annotations

import argparse
import csv
import json
from pathlib import Path


def main() -> None:
    from scone_bt.config.robot import load_robot

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--datasets", nargs="+", default=["tools/data/sc_probe"])
    ap.add_argument(
        "--results", nargs="+", required=True, help="slide_and_pinch_check.py outputs (JSON lines)"
    )
    ap.add_argument("--engine", default="pybullet")
    ap.add_argument("--warmup", type=int, default=20)
    a = ap.parse_args()
    held: dict[tuple[float, float, str], bool] = {}
    for path in a.results:
        for text in Path(path).read_text(encoding="utf-8").splitlines():
            line = json.loads(text)
            if line.get("engine") == a.engine and "product" in line:
                force, friction = line["gripper"]
                held[(float(force), float(friction), line["product"])] = bool(line["held"])
    robot = load_robot("panda").gripper
    splits = [_gain(d, held, robot, a) for d in a.datasets]
    report = {"benchmark": "wide_pack_gain", "engine": a.engine, "results": a.results, "splits": splits}
    print(json.dumps(report, indent=1))


def _gain(datasets: str, held: dict[tuple[float, float, str], bool], robot, a: argparse.Namespace) -> dict:
    """One dataset folder's figures (module docstring)."""
    from scone_bt.benchmarks.self_confidence.profiles import load_profile
    from scone_bt.config.grasp import DEFAULT_OPENING_M

    streams, scored, rows, kept, unknown = [], 0, 0, 0, []
    for csv_path in sorted(Path(datasets).glob("*.csv")):
        profile = load_profile(Path("tools/profiles") / f"{csv_path.stem}.yaml")
        force = profile.gripper_max_force if profile.gripper_max_force is not None else robot.max_force
        friction = profile.finger_friction if profile.finger_friction is not None else robot.finger_friction
        mine = {"stream": csv_path.stem, "gripper": [force, friction], "rows": 0, "held": 0}
        with csv_path.open(encoding="utf-8") as f:
            for row in csv.DictReader(f):
                if int(row["index"]) < a.warmup:
                    continue
                scored += 1
                sides = (float(row["width_m"]), float(row["depth_m"]))
                flat = row["shape"] == "box" and float(row["height_m"]) <= 0.07
                if not (flat and min(sides) > DEFAULT_OPENING_M and row["shelf_tier"] == "0"):
                    continue
                key = (float(force), float(friction), row["object"])
                if key not in held:
                    unknown.append(f"{csv_path.stem}: {row['object']}")
                    continue
                mine["rows"] += 1
                mine["held"] += held[key]
        rows += mine["rows"]
        kept += mine["held"]
        streams.append(mine)
    return {
        "datasets": datasets,
        "scored_decisions": scored,
        "lowest_tier_flat_wide": rows,
        "held": kept,
        "help_rate_drop_at_most": round(kept / scored, 4) if scored else None,
        "not_in_results": unknown,
        "streams": streams,
    }


if __name__ == "__main__":
    main()
