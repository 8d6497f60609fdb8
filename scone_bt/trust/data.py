"""Real human trust ratings: the household and driving data of Soh, Pan, Chen and Hsu ("Multi-Task Trust Transfer
for Human-Robot Interaction", IJRR 2020; RSS 2018), vendored under tools/data/trust/ (provenance in its README).

Each participant rated their trust (1-7) that the robot can do three tasks (C, D, E), then watched it do two other
tasks (A, B), both succeeding or both failing (``B_SF``), then rated C, D and E again.

    data = load_trust_data("household")
    data.records[0].after      # (7, 5, 4): the ratings after watching
    data.tasks[1].text         # "Pick and Place glass"
"""

from __future__ import annotations

import csv
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from scone_bt.errors import SconeError, UnknownNameError

__all__ = [
    "DOMAINS",
    "RATING_COLUMNS",
    "TASK_COLUMNS",
    "TrustDataError",
    "TrustDataset",
    "TrustRecord",
    "TrustTask",
    "data_dir",
    "load_tasks",
    "load_trust_data",
    "rating_to_trust",
]

DOMAINS: tuple[str, ...] = ("household", "driving")
RATING_COLUMNS: tuple[str, ...] = (
    "C1_rating",
    "D1_rating",
    "E1_rating",
    "A_rating",
    "B_rating",
    "C2_rating",
    "D2_rating",
    "E2_rating",
)
TASK_COLUMNS: tuple[str, ...] = ("A_ID", "B_ID", "C_ID", "D_ID", "E_ID")
OUTCOME_COLUMN = "B_SF"
RATING_RANGE = (1, 7)


class TrustDataError(SconeError):
    """A ratings or task file that cannot be used; the message names the file, row and column."""


def rating_to_trust(rating: float) -> float:
    """A 1-7 rating on the paper's (0, 1) trust scale, sigmoid(rating - 3.5) (runExperiment.loadData)."""
    return 1.0 / (1.0 + math.exp(-(rating - 3.5)))


def data_dir() -> Path:
    """tools/data/trust in the source tree (the vendored data)."""
    return Path(__file__).resolve().parents[2] / "tools" / "data" / "trust"


@dataclass(frozen=True)
class TrustTask:
    """One task participants rated or watched.

    Attributes:
        id: Task id in the ratings file (1-12).
        label: The paper's label (category letter and difficulty rank, e.g. "A-5").
        text: The task description whose embedding (ζ) carries trust between tasks.
    """

    id: int
    label: str
    text: str


@dataclass(frozen=True)
class TrustRecord:
    """One participant's row.

    Attributes:
        participant: 0-based row index in the file (the paper's participant index).
        observed: Task ids the robot was seen doing (A, B), in order.
        success: True when the robot succeeded at both observed tasks, False when it failed at both.
        predicted: Task ids rated before and after (C, D, E).
        before: Trust ratings (1-7) for ``predicted`` before watching.
        after: Trust ratings (1-7) for ``predicted`` after watching.
        observed_ratings: Trust ratings (1-7) of the observed tasks A and B, given after watching each.
    """

    participant: int
    observed: tuple[int, int]
    success: bool
    predicted: tuple[int, int, int]
    before: tuple[int, int, int]
    after: tuple[int, int, int]
    observed_ratings: tuple[int, int]


@dataclass(frozen=True)
class TrustDataset:
    """A domain's ratings and its tasks.

    Attributes:
        domain: "household", "driving", or the file's stem for another file.
        tasks: Task id -> task.
        records: One per participant, in file order.
        source: The ratings file read.
    """

    domain: str
    tasks: dict[int, TrustTask]
    records: tuple[TrustRecord, ...]
    source: Path

    @property
    def participants(self) -> int:
        return len(self.records)


def load_tasks(domain: str, path: Path | None = None) -> dict[int, TrustTask]:
    """The tasks of `domain` from tasks.csv (columns domain, task_id, label, text)."""
    path = path or data_dir() / "tasks.csv"
    if not path.is_file():
        raise TrustDataError(f"{path}: task file not found")
    tasks: dict[int, TrustTask] = {}
    with path.open(newline="", encoding="utf-8") as fh:
        reader = csv.DictReader(fh)
        _check_columns(path, reader.fieldnames, ("domain", "task_id", "label", "text"))
        for n, row in enumerate(reader, 1):
            if row["domain"] != domain:
                continue
            tid = _int(path, n, "task_id", row["task_id"])
            tasks[tid] = TrustTask(tid, row["label"], row["text"])
    if not tasks:
        raise UnknownNameError("trust data domain", domain, _domains_in(path))
    return tasks


def load_trust_data(
    domain: str = "household", path: Path | None = None, tasks: dict[int, TrustTask] | None = None
) -> TrustDataset:
    """Read a ratings file in the paper's format (the vendored one for `domain` unless `path` is given).

    Raises:
        TrustDataError: missing file or columns, a non-integer cell, a rating outside 1-7, an outcome not 0/1, or a
            task id not in the domain's tasks; one line naming the file, row (1 = first data row) and column.
        UnknownNameError: a domain without tasks.
    """
    if path is None and domain not in DOMAINS:
        raise UnknownNameError("trust data domain", domain, DOMAINS)
    path = path or data_dir() / f"trust_transfer_{domain}_cleaned.csv"
    tasks = tasks if tasks is not None else load_tasks(domain)
    if not path.is_file():
        raise TrustDataError(f"{path}: ratings file not found")
    records: list[TrustRecord] = []
    with path.open(newline="", encoding="utf-8") as fh:
        reader = csv.DictReader(fh)
        _check_columns(path, reader.fieldnames, (*RATING_COLUMNS, *TASK_COLUMNS, OUTCOME_COLUMN))
        for n, row in enumerate(reader, 1):
            records.append(_record(path, n, row, tasks))
    if not records:
        raise TrustDataError(f"{path}: no data rows")
    return TrustDataset(domain, tasks, tuple(records), path)


def _record(path: Path, n: int, row: dict[str, str], tasks: dict[int, TrustTask]) -> TrustRecord:
    ratings = {}
    for col in RATING_COLUMNS:
        v = _int(path, n, col, row[col])
        lo, hi = RATING_RANGE
        if not lo <= v <= hi:
            raise TrustDataError(f"{path}: row {n}, column {col}: rating {v} is outside {lo}-{hi}")
        ratings[col] = v
    ids = {}
    for col in TASK_COLUMNS:
        v = _int(path, n, col, row[col])
        if v not in tasks:
            valid = ", ".join(str(t) for t in sorted(tasks))
            raise TrustDataError(f"{path}: row {n}, column {col}: unknown task id {v}; valid: {valid}")
        ids[col] = v
    outcome = _int(path, n, OUTCOME_COLUMN, row[OUTCOME_COLUMN])
    if outcome not in (0, 1):
        raise TrustDataError(
            f"{path}: row {n}, column {OUTCOME_COLUMN}: {outcome} is not 0 (both failed) or 1 (both succeeded)"
        )
    return TrustRecord(
        participant=n - 1,
        observed=(ids["A_ID"], ids["B_ID"]),
        success=outcome == 1,
        predicted=(ids["C_ID"], ids["D_ID"], ids["E_ID"]),
        before=(ratings["C1_rating"], ratings["D1_rating"], ratings["E1_rating"]),
        after=(ratings["C2_rating"], ratings["D2_rating"], ratings["E2_rating"]),
        observed_ratings=(ratings["A_rating"], ratings["B_rating"]),
    )


def _check_columns(path: Path, header: Sequence[str] | None, needed: tuple[str, ...]) -> None:
    missing = [c for c in needed if c not in (header or [])]
    if missing:
        raise TrustDataError(
            f"{path}: row 0 (header), missing column(s) {', '.join(missing)}; needed: {', '.join(needed)}"
        )


def _int(path: Path, n: int, col: str, text: str | None) -> int:
    try:
        return int((text or "").strip())
    except ValueError:
        raise TrustDataError(f"{path}: row {n}, column {col}: {text!r} is not an integer") from None


def _domains_in(path: Path) -> list[str]:
    with path.open(newline="", encoding="utf-8") as fh:
        return sorted({row.get("domain", "") for row in csv.DictReader(fh)})
