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

``--replay-margins 3,4`` adds ``replay``: the first dataset folder replayed with the shipped gate (cold, the probe,
the strict promise; first start and ``default.over_starts``' ten) as recorded and as if the skill existed, for
each start τ₀ = 1 − kα given. "As if": each held row (above) becomes a success, perceived narrow enough for the
gripper (its width 2 mm under the opening, so the too-wide rule lets the robot try it and κ̂ sees a product that
fits) and hefted held fast under its own weight (``EMULATED_HOLD``). An optimistic what-if, not a measurement of a
skill: it says how far the gate could then get.
"""

from __future__ import annotations

import argparse
import csv
import json
import tempfile
from pathlib import Path

EMULATED_HOLD = {"probe_held": "1", "probe_s": "0.8917", "probe_pressed": "0", "probe_drift_mm": "0.1"}
"""The heft readings an emulated pinch gets (besides its weight as load and the grip's force): held, steady, not
pressed, its contacts put; a recorded probe's 0.89 simulated seconds."""


def main() -> None:
    from scone_bt.config.robot import load_robot

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--datasets", nargs="+", default=["tools/data/sc_probe"])
    ap.add_argument(
        "--results", nargs="+", required=True, help="slide_and_pinch_check.py outputs (JSON lines)"
    )
    ap.add_argument("--engine", default="pybullet")
    ap.add_argument("--warmup", type=int, default=20)
    ap.add_argument(
        "--replay-margins",
        default="",
        help="comma-separated k: replay the what-if at τ₀ = 1 − kα (docstring)",
    )
    a = ap.parse_args()
    held = held_in_check(a.results, a.engine)
    robot = load_robot("panda").gripper
    splits = [_gain(d, held, robot, a) for d in a.datasets]
    report = {"benchmark": "wide_pack_gain", "engine": a.engine, "results": a.results, "splits": splits}
    if a.replay_margins:
        margins = [float(k) for k in a.replay_margins.split(",")]
        report["replay"] = _replay(a.datasets[0], held, robot, a, margins)
    print(json.dumps(report, indent=1))


def held_in_check(results: list[str], engine: str) -> dict[tuple[float, float, str], bool]:
    """Whether each product held in `slide_and_pinch_check.py`'s runs on ``engine``, by (newtons per finger, the
    pads' friction, product)."""
    held: dict[tuple[float, float, str], bool] = {}
    for path in results:
        for text in Path(path).read_text(encoding="utf-8").splitlines():
            line = json.loads(text)
            if line.get("engine") == engine and "product" in line:
                force, friction = line["gripper"]
                held[(float(force), float(friction), line["product"])] = bool(line["held"])
    return held


def _gain(datasets: str, held: dict[tuple[float, float, str], bool], robot, a: argparse.Namespace) -> dict:
    """One dataset folder's figures (module docstring)."""
    from scone_bt.config.grasp import DEFAULT_OPENING_M

    streams, scored, rows, kept, unknown = [], 0, 0, 0, []
    for csv_path in sorted(Path(datasets).glob("*.csv")):
        force, friction = _gripper(csv_path.stem, robot)
        mine = {"stream": csv_path.stem, "gripper": [force, friction], "rows": 0, "held": 0}
        with csv_path.open(encoding="utf-8") as f:
            for row in csv.DictReader(f):
                if int(row["index"]) < a.warmup:
                    continue
                scored += 1
                if not _lowest_tier_flat_wide(row, DEFAULT_OPENING_M):
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


def _lowest_tier_flat_wide(row: dict[str, str], opening_m: float) -> bool:
    """A box wider than the gripper both ways, at most 7 cm tall, on a lowest tier (a dataset row's catalogue
    columns: `config.grasp.flat_pack`, where the pinch is reachable)."""
    from scone_bt.config.grasp import flat_pack

    width = min(float(row["width_m"]), float(row["depth_m"]))
    return (
        row["shape"] == "box"
        and flat_pack(width, float(row["height_m"]), opening_m)
        and row["shelf_tier"] == "0"
    )


def _gripper(profile_name: str, robot) -> tuple[float, float]:
    """(newtons per finger, the pads' friction) of a proficiency profile: its own, else the robot file's."""
    from scone_bt.benchmarks.self_confidence.profiles import load_profile

    profile = load_profile(Path("tools/profiles") / f"{profile_name}.yaml")
    force = profile.gripper_max_force if profile.gripper_max_force is not None else robot.max_force
    friction = profile.finger_friction if profile.finger_friction is not None else robot.finger_friction
    return force, friction


def _emulate(source: Path, into: Path, held: dict[tuple[float, float, str], bool], robot) -> int:
    """Copy ``source``'s streams into ``into`` with every held lowest-tier flat pack a success (module docstring);
    how many rows changed."""
    from scone_bt.config.grasp import DEFAULT_OPENING_M

    changed = 0
    for csv_path in sorted(source.glob("*.csv")):
        force, friction = _gripper(csv_path.stem, robot)
        with csv_path.open(encoding="utf-8") as f:
            reader = csv.DictReader(f)
            fields, rows = list(reader.fieldnames or ()), list(reader)
        for row in rows:
            if row["detected"] != "1" or not _lowest_tier_flat_wide(row, DEFAULT_OPENING_M):
                continue
            if not held.get((float(force), float(friction), row["object"]), False):
                continue
            weight = f"{float(row['mass_kg']) * 9.81:.4f}"
            row.update(EMULATED_HOLD, outcome="success", failure_stage="", detail="")
            row.update(detected_width_m=f"{DEFAULT_OPENING_M - 0.002:.4f}", probe_grip_n=str(force))
            for column in (
                "probe_load_n",
                "probe_load_first_n",
                "probe_wrist_load_n",
                "probe_wrist_load_first_n",
            ):
                row[column] = weight
            row["probe_drift_both_mm"], row["probe_in_place"] = "0.1", ""
            changed += 1
        with (into / csv_path.name).open("w", newline="", encoding="utf-8") as f:
            writer = csv.DictWriter(f, fieldnames=fields)
            writer.writeheader()
            writer.writerows(rows)
    return changed


def _replay(
    datasets: str, held: dict[tuple[float, float, str], bool], robot, a, margins: list[float]
) -> dict:
    """The shipped gate on ``datasets`` as recorded and as if the skill existed, per start margin (docstring)."""
    import numpy as np

    from scone_bt.benchmarks.gate import OVER_STARTS_STEP, replay_args, results_over_starts
    from scone_bt.benchmarks.replay_rates import pooled_rates
    from scone_bt.benchmarks.replay_streams import load_streams
    from scone_bt.gate.budget import BudgetOptions
    from scone_bt.gate.probe import ProbeOptions

    args = replay_args(datasets)
    out: dict = {"datasets": datasets, "alpha": 0.15, "over_starts_step": OVER_STARTS_STEP, "margins": {}}
    with tempfile.TemporaryDirectory() as tmp:
        out["rows_emulated"] = _emulate(Path(datasets), Path(tmp), held, robot)
        views = {
            "recorded": load_streams(args, oracle=False),
            "with_skill": load_streams(args, False, Path(tmp)),
        }
        for k in margins:
            args.budget = BudgetOptions(start_margin=k)
            line = {}
            for view, streams in views.items():
                starts = [
                    pooled_rates(r)
                    for _, r in results_over_starts(
                        streams, OVER_STARTS_STEP, "physical", 0.15, args, probe=ProbeOptions()
                    )
                ]
                first = starts[0]  # the start at row 0: each stream from its first row, as `stream_results`
                line[view] = {
                    "attempt_failure_rate": first["attempt_failure_rate"],
                    "help_rate": first["help_rate"],
                    "help_rate_over_starts_mean": round(float(np.mean([r["help_rate"] for r in starts])), 4),
                    "attempt_failure_rate_over_starts_mean": round(
                        float(np.mean([r["attempt_failure_rate"] for r in starts])), 4
                    ),
                    "max_excess_failures_over_starts": round(
                        max(r["max_excess_failures"] for r in starts), 2
                    ),
                }
            out["margins"][f"{k:g}"] = line
    return out


if __name__ == "__main__":
    main()
