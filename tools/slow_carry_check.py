"""Would a slower arm keep what slips? Re-run a profile's slips with its kinematic limits scaled down.

The products that slip in the development streams (`tools/data/sc_probe`: "slipped out of the gripper while
lifting", "dropped out of the gripper while carrying it") are most of what the weak, slippery and old robots fail.
If the carry's accelerations caused them, a slower carry after a doubtful heft would turn them into successes.
This re-runs those executions (same profile, index and seed) with velocity × s, acceleration × s², jerk × s³ for
the whole motion, an upper bound on what slowing only the carry could do, and counts the outcomes
(docs/results/probe.md, "A slower carry").

    PYTHONPATH=$PWD python tools/slow_carry_check.py --profiles p01_weak_gripper,p02_slippery_fingers --scales 1,0.5,0.25
"""

from __future__ import annotations

import argparse
import csv
import dataclasses
import json
from collections import Counter
from pathlib import Path

SLIPS = ("grasp", "transit")
"""Failure stages of a product that left the fingers after they closed on it."""


def slipped_rows(dataset: Path, opening_m: float) -> list[dict[str, str]]:
    """Rows of a dataset CSV whose product fits the opening and which failed at a slip stage."""
    with dataset.open(newline="") as f:
        rows = list(csv.DictReader(line for line in f if not line.startswith("#")))
    fits = [r for r in rows if min(float(r["width_m"]), float(r["depth_m"] or r["width_m"])) <= opening_m]
    return [r for r in fits if r["outcome"] != "success" and r["failure_stage"] in SLIPS]


def slower(profile, robot_limits, scale: float):
    """The profile with its (or the robot's) velocity, acceleration and jerk scales multiplied by s, s², s³."""

    def times(own: float | None, base: float, factor: float) -> float:
        return (base if own is None else own) * factor

    return dataclasses.replace(
        profile,
        velocity_scale=times(profile.velocity_scale, robot_limits.velocity_scale, scale),
        acceleration_scale=times(profile.acceleration_scale, robot_limits.acceleration_scale, scale**2),
        jerk_scale=times(profile.jerk_scale, robot_limits.jerk_scale, scale**3),
    )


def main(argv: list[str] | None = None) -> None:
    from scone_bt.benchmarks.self_confidence.generate import drawable_products, run_execution
    from scone_bt.benchmarks.self_confidence.profiles import load_profiles
    from scone_bt.confidence.physical import DEFAULT_OPENING_M
    from scone_bt.config import load_kitchen, load_robot

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--datasets", default="tools/data/sc_probe")
    ap.add_argument(
        "--profiles", default="p01_weak_gripper,p02_slippery_fingers,p05_miscalibrated_xy,p09_old_robot"
    )
    ap.add_argument("--scales", default="1,0.5,0.25", help="comma-separated factors s of the velocity limits")
    ap.add_argument("--limit", type=int, default=0, help="at most this many rows per profile (0: all)")
    a = ap.parse_args(argv)
    kitchen, robot = load_kitchen("kitchen"), load_robot("panda")
    pool = drawable_products(kitchen)
    for profile in load_profiles("tools/profiles", a.profiles.split(",")):
        rows = slipped_rows(Path(a.datasets) / f"{profile.name}.csv", DEFAULT_OPENING_M)
        rows = rows[: a.limit] if a.limit else rows
        for scale in (float(s) for s in a.scales.split(",")):
            outcomes: Counter[str] = Counter()
            for row in rows:
                record, _ = run_execution(
                    slower(profile, robot.limits, scale), int(row["index"]), kitchen, robot, pool=pool
                )
                outcomes["success" if record.success else str(record.failure_stage)] += 1
            print(
                json.dumps(
                    {"profile": profile.name, "scale": scale, "slips": len(rows), "outcomes": dict(outcomes)}
                )
            )


if __name__ == "__main__":
    main()
