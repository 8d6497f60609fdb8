"""ρ, filtering: a similarity threshold learnt from labelled data, and instruction progress.

An instruction is *irrelevant* to the robot ("Preheat the oven") when no action's similarity reaches the
threshold, and *completed* when every action that reaches it has been done.
"""

from __future__ import annotations

import json
import math
from collections.abc import Collection, Sequence
from dataclasses import dataclass
from enum import StrEnum
from pathlib import Path

import numpy as np

from scone_bt.errors import ConfigError, SconeError
from scone_bt.relevance.types import RankedAction

__all__ = ["InstructionProgress", "InstructionStatus", "RelevanceFilter", "instruction_progress"]

_FORMAT = "scone-bt-relevance-filter"


@dataclass(frozen=True)
class RelevanceFilter:
    """A cosine-similarity threshold: a score counts as relevant when score ≥ threshold.

    Attributes:
        threshold: Cosine similarity, in [-1, 1].
        embedder: Name of the embedder the threshold was learnt with ("" if unknown); thresholds do not
            transfer between embedders.
        balanced_accuracy: Mean of the true-positive and true-negative rates on the fitting data (nan if
            unknown).
    """

    threshold: float
    embedder: str = ""
    balanced_accuracy: float = float("nan")

    def __post_init__(self) -> None:
        if not -1.0 <= self.threshold <= 1.0:
            raise SconeError(
                f"relevance threshold must be a cosine similarity in [-1, 1], got {self.threshold}"
            )

    @classmethod
    def fit(
        cls, scores: Sequence[float] | np.ndarray, labels: Sequence[bool] | np.ndarray, embedder: str = ""
    ) -> RelevanceFilter:
        """Threshold that best separates relevant from irrelevant scores (maximum balanced accuracy).

        Use per-(instruction, action) similarities labelled "this action serves this instruction", or per-
        instruction best similarities labelled "the robot can help with this instruction". Among equally good
        thresholds the middle of the widest gap between scores is taken, for the largest margin.

        Raises:
            SconeError: lengths differ or one of the classes is missing.
        """
        s = np.asarray(scores, dtype=np.float64)
        y = np.asarray(labels, dtype=bool)
        if s.shape != y.shape or s.ndim != 1:
            raise SconeError(f"fit needs one label per score; got {s.shape} scores and {y.shape} labels")
        n_pos, n_neg = int(y.sum()), int((~y).sum())
        if n_pos == 0 or n_neg == 0:
            raise SconeError(
                f"fit needs relevant and irrelevant examples; got {n_pos} relevant, {n_neg} irrelevant"
            )
        values = np.unique(s)
        # candidate i sits in the gap below values[i]; the two ends lie just outside the data
        cands = np.concatenate([[values[0] - 1e-3], (values[:-1] + values[1:]) / 2, [values[-1] + 1e-3]])
        widths = np.concatenate([[0.0], np.diff(values), [0.0]])
        # O(n log n) for the tens of thousands of (instruction, action) pairs of a benchmark
        pos_below = np.searchsorted(np.sort(s[y]), cands, side="left")
        neg_below = np.searchsorted(np.sort(s[~y]), cands, side="left")
        tpr = 1.0 - pos_below / n_pos
        tnr = neg_below / n_neg
        bacc = (tpr + tnr) / 2
        best = np.flatnonzero(np.isclose(bacc, bacc.max()))
        threshold = float(np.clip(cands[best[np.argmax(widths[best])]], -1.0, 1.0))
        return cls(threshold, embedder, float(bacc.max()))

    def is_relevant(self, score: float) -> bool:
        """Whether one similarity passes the threshold."""
        return score >= self.threshold

    def relevant(self, ranked: Sequence[RankedAction]) -> list[RankedAction]:
        """The actions that pass, in the given order."""
        return [r for r in ranked if r.relevance >= self.threshold]

    def save(self, path: Path | str) -> Path:
        """Write as JSON; returns the path."""
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        acc = None if math.isnan(self.balanced_accuracy) else self.balanced_accuracy
        record = {
            "format": _FORMAT,
            "threshold": self.threshold,
            "embedder": self.embedder,
            "balanced_accuracy": acc,
        }
        path.write_text(json.dumps(record, indent=2) + "\n")
        return path

    @classmethod
    def load(cls, path: Path | str) -> RelevanceFilter:
        """Read a file written by `save`.

        Raises:
            ConfigError: missing, not JSON, or not a relevance filter.
        """
        path = Path(path)
        try:
            record = json.loads(path.read_text())
        except OSError as exc:
            raise ConfigError(f"cannot read relevance filter {path}: {exc.strerror}") from None
        except json.JSONDecodeError as exc:
            raise ConfigError(
                f"relevance filter {path} is not JSON: {exc.msg} at line {exc.lineno}"
            ) from None
        if not isinstance(record, dict) or record.get("format") != _FORMAT or "threshold" not in record:
            raise ConfigError(
                f"{path} is not a relevance filter (expected format {_FORMAT!r} and a threshold)"
            )
        acc = record.get("balanced_accuracy")
        return cls(
            float(record["threshold"]), str(record.get("embedder", "")), float("nan") if acc is None else acc
        )


class InstructionStatus(StrEnum):
    IRRELEVANT = "irrelevant"  # no action reaches the threshold: the robot cannot help with it
    PENDING = "pending"  # some relevant action is not done yet
    COMPLETED = "completed"  # every relevant action is done


@dataclass(frozen=True)
class InstructionProgress:
    """Where one instruction stands.

    Attributes:
        status: irrelevant, pending or completed.
        relevant: Texts of the actions that pass the threshold, best first.
        pending: Those of them not done yet, best first.
    """

    status: InstructionStatus
    relevant: tuple[str, ...]
    pending: tuple[str, ...]


def instruction_progress(
    ranked: Sequence[RankedAction], done: Collection[str], relevance: RelevanceFilter
) -> InstructionProgress:
    """Status of an instruction given every action ranked against it and the action texts already done.

    `ranked` must include the done actions as well as the available ones (rank all actions the robot has known
    this episode), so that an instruction whose relevant objects were all moved reads as completed rather than
    irrelevant.
    """
    relevant = tuple(r.text for r in sorted(relevance.relevant(ranked), key=lambda r: -r.relevance))
    pending = tuple(t for t in relevant if t not in done)
    if not relevant:
        status = InstructionStatus.IRRELEVANT
    elif pending:
        status = InstructionStatus.PENDING
    else:
        status = InstructionStatus.COMPLETED
    return InstructionProgress(status, relevant, pending)
