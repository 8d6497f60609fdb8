"""The same pick-and-places on PyBullet and on MuJoCo: which products' outcomes flip between the engines (JSON).

    .venv/bin/python tools/engine_grasps.py --scenes 6 --per-scene 8 > docs/results/engine_grasps.json

Each scene stocks the shelving with a seeded draw of catalogue products (as `scone-bench perception` draws them),
then picks every product of the scene in turn from a fresh kitchen, on each engine. Detections are the simulator's
ground truth (top centre and yaw) and the planner's seed is the scene's, so both engines execute the same plan
wherever their settled scenes agree. What differs is the body: contacts, friction, grasp physics.
"""

from __future__ import annotations

import argparse
import copy
import json
import sys
import time


def _pick(engine: str, kitchen_cfg, robot_cfg, specs, places, target: str, seed: int) -> dict[str, object]:
    from scone_bt.motion import MotionSystem
    from scone_bt.perception.types import Detection
    from scone_bt.quiet import c_stdout_silenced
    from scone_bt.robot.sim import shared_arm

    with c_stdout_silenced():
        if engine == "mujoco":
            from scone_bt.world.mj_kitchen import MjKitchen

            kitchen = MjKitchen(kitchen_cfg, robot_cfg)
        else:
            from scone_bt.world import Kitchen

            kitchen = Kitchen(kitchen_cfg, robot_cfg)
    with kitchen:
        kitchen.spawn_planned(specs, places)

        def detect(name: str) -> Detection:
            x, y, z = kitchen.object_state(name).position
            top = (x, y, z + kitchen.specs[name].height / 2)
            return Detection(name, 0, top, kitchen.object_yaw(name), 1.0, (0, 0, 1, 1))

        others = [(detect(n), kitchen.specs[n]) for n in kitchen.objects if n != target]
        with MotionSystem.build(kitchen, robot_cfg, arm=shared_arm(robot_cfg)) as system:
            task = system.pick_and_place(detect(target), kitchen.specs[target], others, rng_seed=seed)
            task.start()
            while not task.done():
                kitchen.advance(0.1)
            outcome = task.outcome()
    return {"success": outcome.success, "stage": None if outcome.stage is None else str(outcome.stage.value)}


def main(argv: list[str]) -> int:
    import numpy as np

    from scone_bt.config import load_kitchen, load_robot
    from scone_bt.errors import ConfigError
    from scone_bt.stocking import plan_stocking

    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--scenes", type=int, default=6)
    p.add_argument("--per-scene", type=int, default=8)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--arm", default="panda")
    args = p.parse_args(argv)
    kitchen_cfg, robot_cfg = load_kitchen(), load_robot(args.arm)
    catalogue = kitchen_cfg.catalogue
    rows = []
    started = time.perf_counter()
    for scene in range(args.scenes):
        rng = np.random.default_rng(args.seed + scene)
        for _ in range(100):
            chosen = rng.choice(len(catalogue), size=args.per_scene, replace=False)
            specs = [catalogue.objects[int(i)] for i in chosen]
            trial = copy.deepcopy(rng)
            try:
                places = plan_stocking(kitchen_cfg.scene, specs, trial)
            except ConfigError:
                continue
            break
        else:
            raise ConfigError("no draw fits the shelving")
        for spec in specs:
            row = {"scene": scene, "product": spec.name, "mass_kg": spec.mass, "friction": spec.friction}
            for engine in ("sim", "mujoco"):
                row[engine] = _pick(
                    engine, kitchen_cfg, robot_cfg, specs, places, spec.name, args.seed + scene
                )
            rows.append(row)
            print(json.dumps(row), file=sys.stderr, flush=True)
    n = len(rows)
    flips = [r for r in rows if r["sim"]["success"] != r["mujoco"]["success"]]
    report = {
        "picks": n,
        "success_rate": {e: round(sum(r[e]["success"] for r in rows) / n, 3) for e in ("sim", "mujoco")},
        "flips": [
            {"product": r["product"], "scene": r["scene"], "sim": r["sim"], "mujoco": r["mujoco"]}
            for r in flips
        ],
        "wall_s": round(time.perf_counter() - started, 1),
        "rows": rows,
    }
    print(json.dumps(report, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
