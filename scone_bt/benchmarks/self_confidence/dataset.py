"""Self-confidence datasets: one file per robot, one row per attempted action and its outcome.

Schema (CSV or Parquet, extra columns allowed):
    action         the action text ("Put salt on table")
    object         catalogue name of the object
    outcome        "success" or "failure" (also accepted: 1/0, true/false)
    failure_stage  empty on success, else where it failed (perception, planning, grasp, ...)
    seed           the seed of that execution

An experience store export (`ExperienceStore.export_csv`) is read too: its `object_name` and `success` columns
stand for `object` and `outcome`; when its `context` JSON names several robots (or profiles), each becomes its
own dataset.
"""

from __future__ import annotations

import csv
import io
import json
import os
import tempfile
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from scone_bt.errors import ConfigError

__all__ = [
    "COLUMNS",
    "Dataset",
    "ExecutionRecord",
    "load_datasets",
    "read_dataset",
    "read_records",
    "write_records",
]

COLUMNS = ("index", "action", "object", "outcome", "failure_stage", "seed", "detail")
"""Columns the generator writes; `index` and `detail` are informative, the evaluator needs the others."""

_TRUE = {"success", "1", "true", "yes", "ok"}
_FALSE = {"failure", "0", "false", "no", "fail"}
_SPLIT_KEYS = ("profile", "robot")


@dataclass(frozen=True)
class ExecutionRecord:
    """One simulated pick-and-place.

    Attributes:
        index: Position of the execution in its profile (0-based).
        action: Action text.
        object: Catalogue name of the target.
        success: Whether the target ended upright on the table.
        failure_stage: None on success, else the FailureStage value.
        seed: Seed of the execution.
        detail: Human-readable detail of the outcome.
    """

    index: int
    action: str
    object: str
    success: bool
    failure_stage: str | None
    seed: int
    detail: str = ""

    def row(self) -> list[str]:
        return [
            str(self.index),
            self.action,
            self.object,
            "success" if self.success else "failure",
            self.failure_stage or "",
            str(self.seed),
            self.detail,
        ]


@dataclass(frozen=True, eq=False)
class Dataset:
    """One robot's outcomes in the order they were observed.

    Attributes:
        name: Dataset name (file stem, plus the robot/profile when one file held several).
        actions: Action texts, one per row.
        objects: Object names, one per row.
        success: (n,) bool outcomes.
        failure_stages: Failure stage per row ("" on success).
    """

    name: str
    actions: tuple[str, ...]
    objects: tuple[str, ...]
    success: np.ndarray
    failure_stages: tuple[str, ...]

    def __len__(self) -> int:
        return len(self.actions)

    @property
    def success_rate(self) -> float:
        return float(self.success.mean()) if len(self) else float("nan")


def write_records(path: Path | str, records: Iterable[ExecutionRecord]) -> Path:
    """Write records sorted by index to a CSV file atomically (a reader never sees a half-written file)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    with os.fdopen(fd, "w", newline="") as f:
        writer = csv.writer(f, lineterminator="\n")
        writer.writerow(COLUMNS)
        for rec in sorted(records, key=lambda r: r.index):
            writer.writerow(rec.row())
    os.replace(tmp, path)
    return path


def read_records(path: Path | str) -> list[ExecutionRecord]:
    """Records of a generator CSV (used to resume a half-finished profile); a missing file gives none."""
    path = Path(path)
    if not path.is_file():
        return []
    with path.open(newline="") as f:
        rows = list(csv.DictReader(f))
    missing = [c for c in COLUMNS if rows and c not in rows[0]]
    if missing:
        raise ConfigError(
            f"{path}: not a generator file (missing column {missing[0]!r}); delete it to regenerate"
        )
    return [
        ExecutionRecord(
            index=int(r["index"]),
            action=r["action"],
            object=r["object"],
            success=_outcome(r["outcome"], path, i),
            failure_stage=r["failure_stage"] or None,
            seed=int(r["seed"]),
            detail=r["detail"],
        )
        for i, r in enumerate(rows)
    ]


def _outcome(value: object, path: Path, row: int) -> bool:
    text = str(value).strip().lower()
    if text in _TRUE:
        return True
    if text in _FALSE:
        return False
    raise ConfigError(
        f"{path} row {row + 2}: outcome {value!r} is not one of success, failure, 1, 0, true, false"
    )


def _table(path: Path) -> list[dict[str, object]]:
    if path.suffix == ".parquet":
        import pyarrow.parquet as pq

        return pq.read_table(path).to_pylist()
    from scone_bt.config.schema import read_text

    try:  # strict UTF-8, and csv's own complaints (NUL bytes, a field too large) as one line
        return list(csv.DictReader(io.StringIO(read_text(path), newline="")))
    except csv.Error as exc:
        raise ConfigError(f"{path}: not a readable CSV file ({exc})") from None


def read_dataset(path: Path | str) -> list[Dataset]:
    """Read one CSV/Parquet file; usually one dataset, several if an experience export mixes robots."""
    path = Path(path)
    rows = _table(path)
    if not rows:
        raise ConfigError(f"{path}: no rows")
    cols = set(rows[0])
    obj_col = "object" if "object" in cols else "object_name" if "object_name" in cols else None
    out_col = "outcome" if "outcome" in cols else "success" if "success" in cols else None
    needed = [
        ("action", "action" in cols),
        ("object (or object_name)", obj_col),
        ("outcome (or success)", out_col),
    ]
    missing = [name for name, ok in needed if not ok]
    if missing:
        raise ConfigError(
            f"{path}: missing column {missing[0]}; a dataset needs action, object, outcome, failure_stage, seed"
        )
    groups: dict[str, list[int]] = {}
    for i, r in enumerate(rows):
        groups.setdefault(_group(r, path, i), []).append(i)
    datasets = []
    for key, idx in groups.items():
        name = path.stem if len(groups) == 1 else f"{path.stem}:{key}"
        datasets.append(
            Dataset(
                name=name,
                actions=tuple(str(rows[i]["action"]) for i in idx),
                objects=tuple(str(rows[i][obj_col]) for i in idx),  # type: ignore[index]
                success=np.array([_outcome(rows[i][out_col], path, i) for i in idx], dtype=bool),  # type: ignore[index]
                failure_stages=tuple(str(rows[i].get("failure_stage") or "") for i in idx),
            )
        )
    return datasets


def _group(row: dict[str, object], path: Path, index: int) -> str:
    raw = row.get("context")
    if not raw:
        return ""
    try:
        ctx = json.loads(str(raw))
    except json.JSONDecodeError:
        raise ConfigError(f"{path} row {index + 2}: context is not valid JSON") from None
    if not isinstance(ctx, dict):
        return ""
    return "/".join(str(ctx[k]) for k in _SPLIT_KEYS if k in ctx)


def load_datasets(
    directory: Path | str, min_rows: int = 0, names: Sequence[str] | None = None
) -> list[Dataset]:
    """Every *.csv / *.parquet dataset in `directory`, sorted by name.

    Args:
        directory: Folder of dataset files.
        min_rows: Datasets with fewer rows are an error (the evaluation needs them).
        names: Only these dataset names (file stems).
    """
    directory = Path(directory)
    if not directory.is_dir():
        raise ConfigError(f"dataset directory {directory} does not exist")
    files = sorted(
        p for p in directory.iterdir() if p.suffix in (".csv", ".parquet") and not p.name.startswith(".")
    )
    if names:
        stems = {p.stem for p in files}
        missing = [n for n in names if n not in stems]
        if missing:
            raise ConfigError(
                f"unknown dataset {missing[0]!r} in {directory}; valid: {', '.join(sorted(stems))}"
            )
        files = [p for p in files if p.stem in names]
    if not files:
        raise ConfigError(f"{directory}: no dataset files (*.csv or *.parquet)")
    datasets = [d for p in files for d in read_dataset(p)]
    short = [d for d in datasets if len(d) < min_rows]
    if short:
        raise ConfigError(
            f"dataset {short[0].name} has {len(short[0])} rows; the evaluation needs at least {min_rows}"
        )
    return datasets
