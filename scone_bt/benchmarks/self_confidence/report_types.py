"""The shape of the self-confidence evaluation report (`sc evaluate`'s JSON), as typed dictionaries.

TypedDicts, not dataclasses: the report *is* its JSON (NaN written as null), so the committed files keep their
exact text and older reports (fewer keys: ``NotRequired``) still render. evaluate.py builds an
`EvaluationReport`, report.py renders one; `report_from_json` / `load_report` check a report read back and name
the file and the key of the first thing that is wrong, on one line.
"""

# No `from __future__ import annotations`: TypedDict sees NotRequired only in evaluated annotations (3.11).
import json
import types
import typing
from pathlib import Path
from typing import Any, NotRequired, TypedDict, Union, cast

from scone_bt.errors import ConfigError
from scone_bt.strict_json import clean_json

__all__ = [
    "AccuracyCurve",
    "AucSummary",
    "DatasetSummary",
    "EvaluationReport",
    "MeanStd",
    "NoiseFloor",
    "ProtocolEntry",
    "ReliabilityBin",
    "ReportOptions",
    "RobotCounts",
    "RobotSummary",
    "TargetCheck",
    "Timing",
    "clean_report",
    "load_report",
    "report_from_json",
]


class MeanStd(TypedDict):
    """A metric over datasets: mean and standard deviation (null when no dataset had one)."""

    mean: float | None
    std: float | None


class AucSummary(MeanStd):
    """The normalised AUC of the accuracy curve, with each dataset's own (older reports: none)."""

    per_dataset: NotRequired[list[float | None]]
    dataset_index: NotRequired[list[int]]


class NoiseFloor(TypedDict):
    """The ECE a perfectly calibrated predictor would score on the same predictions."""

    mean: float | None
    p95: float | None


class AccuracyCurve(TypedDict):
    """Test accuracy per training-set size, mean and std over datasets."""

    n_train: list[int]
    mean: list[float | None]
    std: list[float | None]


class ReliabilityBin(TypedDict):
    """One bin of the reliability diagram."""

    lower: float
    upper: float
    count: int
    mean_predicted: float | None
    observed_rate: float | None


class RobotCounts(TypedDict):
    """What one online robot did along the training streams, summed over datasets."""

    rows: int
    attempts: int
    successes: int
    failures: int
    help_requests: int
    missed_successes: int
    explorations: int
    regret: int


class RobotSummary(TypedDict):
    """An eps-X pair's ε-greedy robot, the greedy one (ε = 0) beside it, and the greedy belief's AUC."""

    epsilon: RobotCounts
    greedy: RobotCounts
    greedy_auc: MeanStd
    epsilon0: float
    half_life: float
    refit_every: int


class ProtocolEntry(TypedDict):
    """One embedder × estimator pair (or the prior) under one protocol."""

    embedder: str
    estimator: str
    auc: AucSummary
    auroc: float | None
    brier: float | None
    ece: float | None
    ece_noise_floor: NotRequired[NoiseFloor]
    final_accuracy: MeanStd
    accuracy_curve: AccuracyCurve
    n_test: int
    n_datasets: int
    reliability: list[ReliabilityBin]
    robot: NotRequired[RobotSummary]
    pair_wall_s: NotRequired[float]


class ReportOptions(TypedDict):
    """The EvalOptions the report was computed with."""

    n_test: int
    n_train: list[int]
    lofo_n_train: list[int]
    shuffles: int
    seed: int
    threshold: float
    ece_bins: int
    epsilon0: float
    half_life: float
    refit_every: int


class DatasetSummary(TypedDict):
    """One evaluated dataset (report.dataset_summary)."""

    name: str
    rows: int
    success_rate: float | None
    distinct_products: int
    families: int
    context_coverage: float
    product_oracle: float | None
    family_oracle: float | None
    novel_test_rows: NotRequired[int]


class Timing(TypedDict):
    """Wall times, seconds, and the run's workers and cells."""

    embedding: float
    embedding_per_embedder: NotRequired[dict[str, float]]
    total: float
    workers: int
    engine: NotRequired[str]
    cells: NotRequired[int]
    cells_wall_s_sum: NotRequired[float]


class EvaluationReport(TypedDict):
    """The whole `sc evaluate` report: what was run, on what, and every protocol's entries."""

    benchmark: str
    data: str
    options: ReportOptions
    datasets: list[DatasetSummary]
    embedders: list[str]
    embedders_skipped: dict[str, str]
    estimators: list[str]
    protocols: dict[str, list[ProtocolEntry]]
    prior: NotRequired[dict[str, ProtocolEntry]]
    timing_s: Timing


class TargetCheck(TypedDict):
    """One target of report_text/report.yaml: its label, the measured numbers, whether it is met."""

    target: str
    measured: str
    met: bool


def clean_report(report: EvaluationReport) -> EvaluationReport:
    """`report` as its JSON text holds it: NaN as None, numpy scalars as Python ones, tuples as lists."""
    return cast(EvaluationReport, clean_json(report))


# ----------------------------------------------------------------------------------------------- checking
class _Malformed(Exception):
    """A value that does not fit its declared type: the dotted key and what is wrong."""


def _kind(value: object) -> str:
    return "null" if value is None else type(value).__name__


def _check(value: object, tp: Any, key: str) -> None:
    """Raise _Malformed unless `value` (parsed JSON) fits the annotation `tp`."""
    origin = typing.get_origin(tp)
    if tp is Any or tp is object:
        return
    if tp is type(None):
        if value is not None:
            raise _Malformed(f"{key}: expected null, got {_kind(value)}")
        return
    if origin in (Union, types.UnionType):
        errors = []
        for option in typing.get_args(tp):
            try:
                _check(value, option, key)
                return
            except _Malformed as exc:
                errors.append(str(exc))
        raise _Malformed(errors[-1])
    # is_typeddict is False for anything but a TypedDict class; tp stays Any so its __required_keys__ reads
    if typing.is_typeddict(tp):
        if not isinstance(value, dict):
            raise _Malformed(f"{key}: expected an object, got {_kind(value)}")
        for name in sorted(tp.__required_keys__ - set(value)):
            raise _Malformed(f"{key}.{name}: missing")
        for name, sub in typing.get_type_hints(tp).items():
            if name in value:
                _check(value[name], sub, f"{key}.{name}")
        return
    if origin is list:
        if not isinstance(value, list):
            raise _Malformed(f"{key}: expected a list, got {_kind(value)}")
        (item,) = typing.get_args(tp)
        for i, v in enumerate(value):
            _check(v, item, f"{key}[{i}]")
        return
    if origin is dict:
        if not isinstance(value, dict):
            raise _Malformed(f"{key}: expected an object, got {_kind(value)}")
        _, item = typing.get_args(tp)
        for k, v in value.items():
            _check(v, item, f"{key}.{k}")
        return
    if tp is float:
        ok = isinstance(value, int | float) and not isinstance(value, bool)
    elif tp is int:
        ok = isinstance(value, int) and not isinstance(value, bool)
    else:
        ok = isinstance(value, tp)
    if not ok:
        raise _Malformed(f"{key}: expected {tp.__name__}, got {_kind(value)}")


def report_from_json(obj: object, source: str = "<report>") -> EvaluationReport:
    """`obj` (parsed JSON) as an EvaluationReport; a ConfigError naming `source` and the key if it is not one."""
    try:
        _check(obj, EvaluationReport, "report")
    except _Malformed as exc:
        raise ConfigError(f"{source}: malformed self-confidence report: {exc}") from None
    return cast(EvaluationReport, obj)


def load_report(path: Path) -> EvaluationReport:
    """Read and check a report JSON file (one-line ConfigError naming the file, and the key, if it is wrong)."""
    try:
        obj = json.loads(Path(path).read_text(encoding="utf-8"))
    except (OSError, json.JSONDecodeError) as exc:
        raise ConfigError(f"{path}: cannot read the self-confidence report: {exc}") from None
    return report_from_json(obj, str(path))
