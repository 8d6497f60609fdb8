"""``scone-bench perception``: detection accuracy of the shelf and table cameras on seeded scenes (JSON).

``--robot`` picks the engine that renders (``sim``: PyBullet's TinyRenderer, ``mujoco``: MuJoCo's renderer, with
MuJoCo's rays for the ground truth, through the kitchen's `ray_bodies`); the scenes, the detector and the
scoring are the same.

Each scene stocks the shelving with a random draw of the catalogue (21 products by default, drawn again if they
do not fit side by side; random slots, heaviest lowest, random yaws, settled by physics, the arm at home) and puts
three more on the table by the simulated human's hand. Every
shelf camera renders once (TinyRenderer) at the kitchen file's resolution, at 320x240 and 640x480, and with extra
pixel noise; the detections of all shelf cameras are merged (most confident per product) and scored against the
simulator's ground truth: precision, recall on objects whose marker some shelf camera sees unoccluded (and on all),
3D error of the top-face centre (median, p95), and milliseconds per frame. The table camera is scored the same way
on the table's products.

    scone-bench perception                      # 20 scenes of 21 + 3 products
    scone-bench perception --scenes 3 --json out.json
"""

from __future__ import annotations

import argparse
import copy
import time
from dataclasses import asdict, replace
from pathlib import Path
from typing import Any

from scone_bt.reporting import emit_report

__all__ = ["register", "run", "TARGETS"]

DEFAULT_OBJECTS = 21
"""Products on the shelving per scene by default: a long recipe's ingredients and four distractors."""
TARGETS = {"recall_unoccluded": 0.95, "precision": 0.99, "position_error_median_m": 0.01}
RESOLUTIONS = ((320, 240), (640, 480))


def _merge_truth(per_camera: list[list[Any]]) -> list[Any]:
    """One truth per object over several cameras: unoccluded if any camera sees the whole marker."""
    best: dict[str, Any] = {}
    for truths in per_camera:
        for t in truths:
            if t.name not in best or (t.unoccluded and not best[t.name].unoccluded):
                best[t.name] = t
    return list(best.values())


def run(args: argparse.Namespace) -> int:
    """Render and score the scenes; print the JSON report (and write it to --json)."""
    import numpy as np

    from scone_bt.benchmarks.detection_scoring import ground_truth, score_frame, summarise
    from scone_bt.checks import check_range
    from scone_bt.config import load_kitchen, load_robot
    from scone_bt.errors import ConfigError
    from scone_bt.perception import Camera, Detector
    from scone_bt.perception.observe import merge_detections
    from scone_bt.quiet import c_stdout_silenced
    from scone_bt.robot.flags import check_backend
    from scone_bt.stocking import plan_stocking

    for noise in args.noise:  # the scale of a camera's noise_std in a kitchen file
        check_range(noise, "--noise", 0.0, 255.0)
    kitchen_cfg = load_kitchen(args.kitchen, args.catalogue or ())
    engine = check_backend(args.robot)
    kitchen_type: Any  # the engine's kitchen class
    if engine not in ("sim", "mujoco"):
        raise ConfigError(f"scone-bench perception --robot {engine}: it renders on sim (PyBullet) or mujoco")
    if engine == "mujoco":  # the extra and headless rendering, one line each, before any scene is built
        from scone_bt.world.mj_camera import check_rendering
        from scone_bt.world.mj_model import import_mujoco

        check_rendering(import_mujoco())
        from scone_bt.world.mj_kitchen import MjKitchen

        kitchen_type = MjKitchen
    else:
        from scone_bt.world import Kitchen

        kitchen_type = Kitchen
    robot_cfg = load_robot(args.arm)
    slots = len(kitchen_cfg.scene.shelf_slots())
    catalogue = kitchen_cfg.catalogue
    if args.scenes < 1 or args.table_objects < 0:
        raise ConfigError("--scenes must be >= 1 and --table-objects >= 0")
    most = min(slots, len(catalogue)) - args.table_objects
    objects = min(DEFAULT_OBJECTS, most) if args.objects is None else args.objects
    if not 1 <= objects <= most:
        raise ConfigError(
            f"--objects {objects}: must be in 1-{most} ({slots} shelf slots, {len(catalogue)} products, "
            f"--table-objects {args.table_objects})"
        )
    table_spec = kitchen_cfg.table_camera

    variants: dict[str, list[Camera]] = {}
    for w, h in RESOLUTIONS:
        variants[f"{w}x{h}"] = [Camera(replace(c, width=w, height=h)) for c in kitchen_cfg.shelf_cameras]
    base = kitchen_cfg.camera
    default_key = f"{base.width}x{base.height}"
    variants.setdefault(default_key, [Camera(c) for c in kitchen_cfg.shelf_cameras])
    noisy = {
        f"noise_{n:g}": [Camera(replace(c, noise_std=n)) for c in kitchen_cfg.shelf_cameras]
        for n in args.noise
        if n != base.noise_std
    }
    table_camera = Camera(table_spec) if table_spec is not None else None
    detector = Detector(catalogue)

    keys = [*variants, *noisy]
    scores: dict[str, list[Any]] = {key: [] for key in [*keys, "table"]}
    # Wall and CPU time: TinyRenderer and OpenCV run in this process, so CPU time stays meaningful on a shared
    # machine.
    times: dict[str, dict[str, list[float]]] = {
        key: {"render_ms": [], "render_cpu_ms": [], "detect_ms": [], "detect_cpu_ms": []} for key in scores
    }

    def shoot(key: str, camera: Camera, kitchen: Any, rng: np.random.Generator) -> list[Any]:
        w0, c0 = time.perf_counter(), time.process_time()
        with c_stdout_silenced():
            frame = camera.capture(kitchen, rng)
        w1, c1 = time.perf_counter(), time.process_time()
        detections = detector.detect(frame)
        w2, c2 = time.perf_counter(), time.process_time()
        for name, value in (
            ("render_ms", w1 - w0),
            ("render_cpu_ms", c1 - c0),
            ("detect_ms", w2 - w1),
            ("detect_cpu_ms", c2 - c1),
        ):
            times[key][name].append(1000 * value)
        return detections

    for scene in range(args.scenes):
        rng = np.random.default_rng(args.seed + scene)
        for _ in range(100):  # a draw of products too wide to stand side by side is drawn again
            chosen = rng.choice(len(catalogue), size=objects + args.table_objects, replace=False)
            specs = [catalogue.objects[int(i)] for i in chosen]
            # The stocking is planned once, here, and the kitchen is stocked with that plan; a draw that does
            # not fit is planned on a copy of the generator, so `rng` stays where it was for the next choice.
            trial = copy.deepcopy(rng)
            try:
                places = plan_stocking(kitchen_cfg.scene, specs, trial)
            except ConfigError:
                continue
            rng = trial
            break
        else:
            raise ConfigError(f"--objects {objects}: no draw of that many products fits the shelving")
        with c_stdout_silenced():
            kitchen = kitchen_type(kitchen_cfg, robot_cfg)
        with kitchen:
            kitchen.spawn_planned(specs, places)
            for spec in specs[objects:]:
                kitchen.human_place_on_table(spec.name)
            kitchen.advance(0.5)
            shelf_names = {s.name for s in specs[:objects]}
            for key in keys:
                cameras = variants.get(key) or noisy[key]
                per_camera = [shoot(key, cam, kitchen, rng) for cam in cameras]
                # Shelf cameras are scored on the shelf's products (the table is the table camera's).
                merged = [d for d in merge_detections(per_camera) if kitchen_cfg.scene.on_shelf(d.position)]
                truth = _merge_truth([ground_truth(kitchen, cam) for cam in cameras])
                scores[key].append(score_frame(merged, [t for t in truth if t.name in shelf_names]))
            if table_camera is not None:
                detections = [
                    d
                    for d in shoot("table", table_camera, kitchen, rng)
                    if kitchen_cfg.scene.on_table(d.position)
                ]
                truth = [t for t in ground_truth(kitchen, table_camera) if kitchen.is_on_table(t.name)]
                scores["table"].append(score_frame(detections, truth))

    def report(key: str) -> dict[str, float | int]:
        out = summarise(scores[key])
        out.update(
            {
                f"{name}_per_frame": float(np.median(v)) if v else float("nan")
                for name, v in times[key].items()
            }
        )
        return out

    headline = report(default_key)
    result: dict[str, Any] = {
        "scenes": args.scenes,
        "objects_per_scene": objects,
        "table_objects_per_scene": args.table_objects,
        "shelf_slots": slots,
        "shelf_units": len(kitchen_cfg.scene.shelves),
        "products": len(catalogue),
        "robot": engine,
        "seed": args.seed,
        "shelf_cameras": [asdict(c) for c in kitchen_cfg.shelf_cameras],
        "table_camera": asdict(table_spec) if table_spec is not None else None,
        "default_resolution": default_key,
        "recall_unoccluded": headline["recall_unoccluded"],
        "precision": headline["precision"],
        "position_error_median_m": headline["position_error_median_m"],
        "default": headline,
        "table": report("table") if table_camera is not None else None,
        "resolutions": {key: report(key) for key in variants},
        "noise": {key: report(key) for key in noisy},
        "targets": TARGETS,
    }
    result["meets_targets"] = bool(
        headline["recall_unoccluded"] >= TARGETS["recall_unoccluded"]
        and headline["precision"] >= TARGETS["precision"]
        and headline["position_error_median_m"] <= TARGETS["position_error_median_m"]
    )
    emit_report(result, args.json)
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``perception`` to ``scone-bench``."""
    p = sub.add_parser("perception", help="marker detection accuracy of the shelf and table cameras (JSON)")
    p.add_argument("--scenes", type=int, default=20, help="seeded scenes to render (default 20)")
    p.add_argument(
        "--objects",
        type=int,
        default=None,
        help=f"products on the shelf per scene (default {DEFAULT_OBJECTS})",
    )
    p.add_argument("--table-objects", type=int, default=3, help="products on the table per scene (default 3)")
    p.add_argument("--seed", type=int, default=0, help="seed of the first scene (default 0)")
    p.add_argument(
        "--noise",
        type=float,
        nargs="*",
        default=[8.0, 16.0],
        help="extra pixel noise levels (0-255) to score",
    )
    p.add_argument("--kitchen", default="kitchen", help="kitchen file name or path (default kitchen)")
    p.add_argument("--catalogue", action="append", help="extra product file (repeatable)")
    from scone_bt.robot.flags import add_robot_options

    add_robot_options(p)
    p.add_argument("--json", type=Path, help="also write the JSON report to this file")
    p.set_defaults(func=run)
