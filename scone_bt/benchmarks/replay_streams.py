"""The recorded streams the replay walks (`Streams`, `load_streams`): per dataset the actions' embeddings, the
context the robot perceived, the outcomes, the heft test's readings and what the robot knew before moving."""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from scone_bt.benchmarks.self_confidence.dataset import PROBE_COLUMNS, PROBE_READING_COLUMNS
from scone_bt.experience.types import CONTEXT_FIELDS

__all__ = [
    "FORESEEN_STAGES",
    "PROBE_DATASETS",
    "Streams",
    "check_probe_readings",
    "datasets_folder",
    "foreseen",
    "load_streams",
    "missed_in_place",
    "probe_readings",
    "reading_of",
    "rotated",
    "stream_rows",
]


@dataclass(frozen=True)
class Streams:
    """The datasets as the replay walks them, one entry per stream (dataset), rows in execution order.

    Attributes:
        names: The datasets' names (the proficiency profiles, e.g. "p00_nominal").
        vectors: Per stream, ζ of each row's action (the oracle: its true mass and glass instead).
        context: Per stream, the context the robot perceived (`CONTEXT_FIELDS` columns; the oracle: true sizes).
        success: Per stream, whether each execution succeeded.
        products: Per stream, each row's product name.
        readings: Per stream, the heft test's readings (`PROBE_READING_COLUMNS`), or None where it was not recorded.
        foreseen: Per stream, what the robot knew before its arm moved (`foreseen`: "", "missing", "infeasible").
        slide_pinch: Per stream, whether its arm slid and pinched flat packs on a lowest tier (its folder's
            generation.json; `benchmarks.self_confidence.batch.SETTINGS`): its gate leaves those to κ̂.
    """

    names: list[str]
    vectors: list[np.ndarray]
    context: list[np.ndarray]
    success: list[np.ndarray]
    products: list[tuple[str, ...]]
    readings: list[np.ndarray | None] = field(default_factory=list)
    foreseen: list[np.ndarray] = field(default_factory=list)
    slide_pinch: list[bool] = field(default_factory=list)


def slides_flat_packs(folder: Path, names: Sequence[str]) -> list[bool]:
    """Per dataset name, whether generation.json in ``folder`` records an arm that slid and pinched flat packs
    (False where the folder has no log or the log does not name it: recorded before the skill)."""
    from scone_bt.benchmarks.self_confidence.batch import LOG_NAME, read_log

    generations = read_log(folder / LOG_NAME).get("generations", {})
    return [bool(generations.get(n, {}).get("slide_pinch", False)) for n in names]


def datasets_folder(args: argparse.Namespace) -> Path:
    """``--datasets``, or the committed development streams when it is not given: those with the heft test's
    readings, recorded by the shipped arm, which slides and pinches flat packs (tools/data/sc_slide), where the
    replay probes (``args.probe_on``: the tree's ``probe.enabled``, or ``--probe``), else tools/data/sc."""
    from scone_bt.resources import repo_root

    if args.datasets:
        return Path(args.datasets)
    return (
        (repo_root() or Path("."))
        / "tools"
        / "data"
        / ("sc_slide" if getattr(args, "probe_on", False) else "sc")
    )


def load_streams(args: argparse.Namespace, oracle: bool, folder: Path | None = None) -> Streams:
    """Every dataset of ``folder`` (default `datasets_folder`) with ζ from ``args.embedder`` and the context from the
    one context function the robot decides with; ``oracle``: the true mass, glass and size instead."""
    from scone_bt.benchmarks.self_confidence.dataset import load_datasets
    from scone_bt.benchmarks.self_confidence.evaldata import decision_time_context
    from scone_bt.embedding import load_embedder

    if folder is None:
        folder = datasets_folder(args)
    datasets = load_datasets(folder)

    def column(d: Any, name: str) -> np.ndarray:
        return d.context.get(name, np.full(len(d), np.nan))

    # The context the robot perceived, as the self-confidence evaluation reads it (one function for both).
    context = [decision_time_context(d) for d in datasets]
    if (
        oracle
    ):  # the true size where the robot has a perceived one, always "detected"; mass and glass stand for ζ
        vectors = [np.column_stack([column(d, "mass_kg"), _glass(d)]) for d in datasets]
        for d, c in zip(datasets, context, strict=True):
            c[:, CONTEXT_FIELDS.index("detected")] = 1.0
            c[:, CONTEXT_FIELDS.index("detected_width_m")] = column(d, "width_m")
            c[:, CONTEXT_FIELDS.index("detected_height_m")] = column(d, "height_m")
    else:
        emb = load_embedder(args.embedder)
        actions = sorted({a for d in datasets for a in d.actions})
        table = dict(zip(actions, np.asarray(emb.embed(actions), dtype=np.float32), strict=True))
        vectors = [np.stack([table[a] for a in d.actions]) for d in datasets]
    return Streams(
        [d.name for d in datasets],
        vectors,
        context,
        [np.asarray(d.success) for d in datasets],
        [tuple(d.objects) for d in datasets],
        [probe_readings(d) for d in datasets],
        [foreseen(d) for d in datasets],
        slides_flat_packs(folder, [d.name for d in datasets]),
    )


FORESEEN_STAGES: tuple[str, ...] = ("ik", "planning")
"""Failure stages at which no plan was made (motion.pick_place.Diagnosis.stage)."""


_TIMED_OUT: tuple[str, ...] = ("no path", "injected: no plan")
"""How a planning failure's detail begins when the planner only ran out of time (PlanFailureReason.NO_PATH, or the
generator's injected planning failure): the tree still attempts those (robot.sim: not `infeasible`), so they
stay failed attempts."""


PROBE_DATASETS: tuple[str, ...] = (
    "tools/data/sc_slide",
    "tools/data/sc_heldout_slide",
    "tools/data/sc_probe",
    "tools/data/sc_heldout_probe",
)
"""Committed datasets that record the heft test's readings (the _slide ones by the arm that slides and pinches flat
packs; tools/data/sc and the other older folders were generated without the probe)."""


def check_probe_readings(args: argparse.Namespace, streams: Streams) -> None:
    """ConfigError (one line) when ``--probe`` asks to replay the heft test on datasets none of which recorded it:
    without readings every stream would be replayed without the probe, and the report would say so only in its
    ``default.probe`` key. The tree's own ``probe.enabled`` (no ``--probe``) is not checked: it falls back quietly."""
    from scone_bt.errors import ConfigError

    if getattr(args, "probe", None) is True and not any(r is not None for r in streams.readings):
        raise ConfigError(
            f"--probe: no dataset in {datasets_folder(args)} records the heft test's readings "
            f"({', '.join(PROBE_COLUMNS)}); datasets that do: {', '.join(PROBE_DATASETS)} (--datasets)"
        )


def foreseen(d: Any) -> np.ndarray:
    """(n,) str: for each execution of a dataset, the rule by which the robot would ask instead of attempting it:
    "missing" where its target was not detected (the tree asks for what it sees nowhere, gate.rules.ask_for_missing),
    "infeasible" where the scene's geometry left no plan (it asks before the arm moves,
    gate.rules.infeasible_decision), else "". The generator attempts every one and records these as failed
    executions; a file without a ``detail`` column cannot tell a planner that ran out of time, so none of its
    planning failures is foreseen."""
    detected = np.nan_to_num(d.context.get("detected", np.ones(len(d))), nan=1.0)
    details = d.details or ("",) * len(d)
    geometric = [
        stage in FORESEEN_STAGES and bool(detail) and not detail.startswith(_TIMED_OUT)
        for stage, detail in zip(d.failure_stages, details, strict=True)
    ]
    rules = np.full(len(d), "", dtype=object)
    rules[np.array(geometric, dtype=bool)] = "infeasible"
    rules[detected == 0] = "missing"
    return rules


def probe_readings(d: Any) -> np.ndarray | None:
    """(n, 11) probe readings in PROBE_READING_COLUMNS order (NaN where a file of an earlier schema lacks a column, or
    a row leaves it empty), or None for a dataset recorded without the probe."""
    if any(c not in d.context for c in PROBE_COLUMNS):
        return None
    unknown = np.full(len(d.context[PROBE_COLUMNS[0]]), np.nan)
    return np.column_stack([d.context.get(c, unknown) for c in PROBE_READING_COLUMNS])


def reading_of(values: np.ndarray) -> Any:
    """The motion.probe.ProbeReading a recorded row of `probe_readings` stands for, as the robot's hand makes it;
    None where the arm never held the product up. A row of PROBE_COLUMNS alone (5 values) measured nothing more."""
    from scone_bt.motion.probe import ProbeReading

    held, load, first, grip, seconds = values[:5]
    if np.isnan(held):
        return None
    sensed = [
        None if np.isnan(v) else float(v) for v in values[5:10]
    ]  # NaN: unmeasured, or an earlier schema
    pressed, drift, drift_both, wrist, wrist_first = sensed + [None] * (5 - len(sensed))
    return ProbeReading(
        bool(held),
        float(load),
        float(first),
        float(grip),
        float(seconds),
        pressed=bool(pressed),
        drift_mm=drift,
        drift_both_mm=drift_both,
        wrist_load_n=wrist,
        wrist_load_first_n=wrist_first,
    )


def missed_in_place(values: np.ndarray) -> bool:
    """A recorded row of `probe_readings` whose fingers closed on nothing beside a product that still stood where
    it stood (``probe_in_place`` 1): the robot ends that probe aborted."""
    return len(values) > 10 and bool(values[10] == 1.0)


def _glass(d: Any) -> np.ndarray:
    return np.array([m == "glass" for m in d.materials], dtype=float) if d.materials else np.zeros(len(d))


def stream_rows(streams: Streams, which: Sequence[int]) -> tuple[np.ndarray, np.ndarray]:
    """Streams' rows as κ̂ learns them (embedding then context) and their outcomes, as a store holds them
    (gate_unseen.stream_prior: no target that was not detected)."""
    from scone_bt.benchmarks.gate_unseen import stream_prior

    prior = stream_prior(streams, which)
    return prior.rows, prior.success


def rotated(streams: Streams, start: int) -> Streams:
    """Every stream of ``streams`` starting at row ``start`` (modulo its length), the rows before it after its end:
    the same executions met by a robot that started elsewhere in them (`benchmarks.gate`'s ``over_starts``,
    tools/cold_starts.py)."""
    import dataclasses

    def roll(xs: list) -> list:
        return [None if x is None else np.roll(x, -start, axis=0) for x in xs]

    return dataclasses.replace(
        streams,
        vectors=roll(streams.vectors),
        context=roll(streams.context),
        success=roll(streams.success),
        products=[tuple(np.roll(np.array(p, dtype=object), -start)) for p in streams.products],
        readings=roll(streams.readings),
        foreseen=roll(streams.foreseen),
    )
