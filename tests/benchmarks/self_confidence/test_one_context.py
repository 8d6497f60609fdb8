"""One context function for training and deciding (issue 26): the generator records, for each execution's target,
what the episode's `scone_bt.perception.context.execution_contexts` makes of the detections and frames the robot
acts on; the tree's ContextExtractor goes through the same function; an undetected target records nothing
perceived; and the evaluation and the gate replay read the recorded columns through one reader."""

from __future__ import annotations

import argparse
import csv
from collections.abc import Callable
from dataclasses import astuple
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import scone_bt.benchmarks.self_confidence.evaldata as evaldata
import scone_bt.perception.context as pc
from scone_bt.benchmarks.self_confidence import load_profile
from scone_bt.benchmarks.self_confidence.dataset import COLUMNS, load_datasets
from scone_bt.benchmarks.self_confidence.generate import drawable_products
from scone_bt.confidence.grounded import CONTEXT_FIELDS
from scone_bt.experience.types import FELT_FIELDS

PROFILES = Path(__file__).resolve().parents[3] / "tools" / "profiles"


def _spy(monkeypatch: pytest.MonkeyPatch) -> list[dict[str, Any]]:
    """Count and record every call of the episode's context function (whoever calls it)."""
    calls: list[dict[str, Any]] = []
    real = pc.execution_contexts

    def spy(targets, detections, frames, scene, catalogue, measure=pc.size_from_frames):  # type: ignore[no-untyped-def]
        out = real(targets, detections, frames, scene, catalogue, measure)
        calls.append({"targets": list(targets), "detections": list(detections), "frames": frames, "out": out})
        return out

    monkeypatch.setattr(pc, "execution_contexts", spy)
    return calls


def _record_context(record: Any) -> tuple[object, ...]:
    return (
        record.shelf_tier,
        record.clearance_m,
        record.neighbours,
        record.detected,
        record.detected_width_m,
        record.detected_height_m,
        record.detected_depth_m,
        record.detected_fill,
    )


@pytest.fixture
def fresh_worker():  # type: ignore[no-untyped-def]
    import scone_bt.benchmarks.self_confidence.generate as gen

    saved = gen._WORKER
    gen._WORKER = gen._Worker()
    try:
        yield gen
    finally:
        gen._WORKER.kitchen is not None and gen._WORKER.kitchen.close()
        gen._WORKER = saved


@pytest.mark.slow
def test_one_context_function_for_training_and_deciding(
    kitchen_cfg, robot_cfg, monkeypatch, fresh_worker
) -> None:
    calls = _spy(monkeypatch)
    # A camera-to-robot error in z: the recorded height is the robot's (true + 2.5 cm), measured in frames that
    # moved with the detections.
    prof = load_profile(PROFILES / "p06_miscalibrated_z.yaml")
    pool = tuple(o for o in drawable_products(kitchen_cfg) if o.family in ("cans", "boxes", "bags"))
    record, _ = fresh_worker.run_execution(prof, 0, kitchen_cfg, robot_cfg, pool=pool)
    assert record.detected
    # The generator's path: one call, for its target, on every frame it rendered and every shelf detection.
    assert len(calls) == 1
    call = calls[0]
    assert [t.name for t in call["targets"]] == [record.object]
    assert len(call["frames"]) >= 1 and len(call["detections"]) >= 1
    context = call["out"][record.object]
    # the record holds exactly what the function returned; perception feels nothing (that is the probe's)
    assert _record_context(record) + (None,) * len(FELT_FIELDS) == astuple(context)
    assert record.detected_height_m == pytest.approx(record.height_m + prof.calibration_offset[2], abs=0.01)
    assert record.detected_width_m == pytest.approx(record.width_m, abs=0.01)
    # The tree's path (ConfidenceGate's ContextExtractor) on the same perception: the same function, same context.
    again = pc.ContextExtractor(kitchen_cfg.scene, kitchen_cfg.catalogue)(
        call["targets"], call["detections"], call["frames"]
    )
    assert len(calls) == 2 and again[record.object] == context


@pytest.mark.slow
def test_an_undetected_target_records_nothing_perceived(
    kitchen_cfg, robot_cfg, monkeypatch, fresh_worker
) -> None:
    calls = _spy(monkeypatch)
    prof = load_profile(PROFILES / "p08_transparent_blind.yaml")  # execution 0: glass, detection dropped
    record, _ = fresh_worker.run_execution(prof, 0, kitchen_cfg, robot_cfg)
    assert record.failure_stage == "perception" and not record.detected
    assert _record_context(record) == (None, None, None, False, None, None, None, None)
    assert record.shelf_unit == "" and record.slot is None
    assert not any(record.object in [t.name for t in c["targets"]] for c in calls)
    row = dict(zip(COLUMNS, record.row(), strict=True))
    perceived = [c for c in CONTEXT_FIELDS if c not in FELT_FIELDS]  # a dataset records no felt_ columns
    assert [row[c] for c in perceived] == ["", "", "", "0", "", "", "", ""]  # empty cells in the CSV


def test_the_evaluation_and_the_gate_replay_read_the_recorded_context(
    sc_data: Callable[..., Path], monkeypatch: pytest.MonkeyPatch
) -> None:
    from scone_bt.benchmarks import replay_streams

    folder = sc_data(n_datasets=2, rows=30)
    rows = list(csv.DictReader(next(iter(sorted(folder.glob("*.csv")))).open()))
    (first, _) = load_datasets(folder)
    got = evaldata.decision_time_context(first)
    recorded = np.array(
        [[float(r[c]) if r.get(c) else np.nan for c in CONTEXT_FIELDS] for r in rows], dtype=np.float64
    )
    np.testing.assert_array_equal(got, recorded)  # as recorded: NaN stays NaN, detected 0 stays 0
    undetected = recorded[:, CONTEXT_FIELDS.index("detected")] == 0
    assert undetected.any() and np.isnan(got[undetected, CONTEXT_FIELDS.index("detected_width_m")]).all()
    # Both readers go through decision_time_context.
    seen: list[str] = []
    real = evaldata.decision_time_context

    def counting(data):  # type: ignore[no-untyped-def]
        seen.append(data.name)
        return real(data)

    monkeypatch.setattr(evaldata, "decision_time_context", counting)
    (data, _) = evaldata.load_eval_datasets(folder)
    np.testing.assert_array_equal(data.context, recorded)
    streams = replay_streams.load_streams(argparse.Namespace(datasets=str(folder)), oracle=True)
    assert seen == [first.name, "p01_robot", first.name, "p01_robot"]
    # The oracle replaces only the size by the product's own, and counts every row as detected.
    oracle = streams.context[0]
    keep = [CONTEXT_FIELDS.index(c) for c in ("shelf_tier", "clearance_m", "neighbours")]
    np.testing.assert_array_equal(oracle[:, keep], recorded[:, keep])
    assert (oracle[:, CONTEXT_FIELDS.index("detected")] == 1).all()
