"""What the self-confidence evaluation reads of a dataset: outcomes plus each row's product family and context.

`load_eval_datasets` reads a folder through `dataset.load_datasets` (which validates every column) and keeps, per
row, the packaging `family` and the six execution-context values a grounded κ̂ sees
(`scone_bt.confidence.CONTEXT_FIELDS`; the catalogue's own width, height and mass are properties of the product,
not of the execution, and stay out). A missing context column or cell is NaN; a file without a `family` column
takes each object's family from the kitchen catalogue, "unknown" where the object is not in it.

The context is what the robot knows when it decides (`decision_time_context`, the one place that turns a dataset
row into a κ̂ context; the gate benchmark's replay reads it too): the recorded perceived columns as they are. The
generator records them with the episode's own function (`scone_bt.perception.context.execution_contexts`, see
generate.perceived_context), so training, evaluation and the tree's decisions share one definition. A target the
cameras missed is `detected = 0` with every other value unknown (NaN): the robot knows it did not see it, and
nothing more (in the episode it asks for it instead of acting). No value is filled in from the catalogue.

What that costs a grounded κ̂'s figures: every undetected row is a perception failure (about 5 % of the rows), and
`detected = 0` (or its missing sizes) says so, so a grounded estimator scores those rows right. This is knowledge
the robot has when it decides, but the episode's κ̂ never meets such a row (an unseen item is asked for, not
scored); an earlier version hid it by setting `detected` to 1 and filling in the product's true size, which no
robot perceives. Measured on Algorithm 1 (docs/results/self_confidence_grounded.json against
self_confidence.json): grounded AUCs rose by 0.01-0.06; with the undetected rows encoded the old way and every
other cell perceived, they move by at most 0.003, so the rise is these rows, not the perceived tier, clearance,
neighbours and sizes.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from scone_bt.benchmarks.self_confidence.dataset import Dataset, load_datasets
from scone_bt.confidence.grounded import CONTEXT_FIELDS
from scone_bt.errors import ConfigError

__all__ = ["EvalDataset", "UNKNOWN_FAMILY", "decision_time_context", "load_eval_datasets"]

UNKNOWN_FAMILY = "unknown"


@dataclass(frozen=True, eq=False)
class EvalDataset:
    """One robot's outcomes in observed order, with product families and execution contexts.

    Attributes:
        name: Dataset name.
        actions: Action text per row.
        objects: Product name per row.
        families: Packaging family per row (UNKNOWN_FAMILY if not known).
        success: (n,) bool outcomes.
        context: (n, len(CONTEXT_FIELDS)) float64, NaN where a value is missing; booleans as 0/1.
    """

    name: str
    actions: tuple[str, ...]
    objects: tuple[str, ...]
    families: tuple[str, ...]
    success: np.ndarray
    context: np.ndarray

    def __len__(self) -> int:
        return len(self.actions)

    @classmethod
    def from_dataset(
        cls,
        data: Dataset,
        families: Sequence[str] | None = None,
        context: np.ndarray | None = None,
    ) -> EvalDataset:
        """Wrap a `Dataset`; families default to UNKNOWN_FAMILY, context to all missing."""
        n = len(data)
        fam = tuple(families) if families is not None else (UNKNOWN_FAMILY,) * n
        ctx = context if context is not None else np.full((n, len(CONTEXT_FIELDS)), np.nan)
        if len(fam) != n or ctx.shape != (n, len(CONTEXT_FIELDS)):
            raise ConfigError(f"dataset {data.name}: families/context do not match its {n} rows")
        return cls(data.name, data.actions, data.objects, fam, data.success, ctx)


def decision_time_context(data: Dataset) -> np.ndarray:
    """(n, len(CONTEXT_FIELDS)) context as the robot had it when it decided: the recorded perceived columns.

    NaN where a column is missing or a row leaves it empty (an undetected target's size, tier, clearance and
    neighbours); nothing is taken from the product's catalogue values.
    """
    nan = np.full(len(data), np.nan)
    return np.column_stack(
        [np.asarray(data.context.get(c, nan), dtype=np.float64) for c in CONTEXT_FIELDS]
    ).reshape(len(data), len(CONTEXT_FIELDS))


def _catalogue_families(kitchen: str) -> dict[str, str]:
    from scone_bt.config import load_kitchen

    return {o.name: o.family or UNKNOWN_FAMILY for o in load_kitchen(kitchen).catalogue.objects}


def load_eval_datasets(
    directory: Path | str,
    min_rows: int = 0,
    names: Sequence[str] | None = None,
    kitchen: str = "kitchen",
) -> list[EvalDataset]:
    """Every dataset of `directory` (see dataset.load_datasets), with families and contexts.

    Args:
        directory: Folder of dataset files.
        min_rows: Fewer rows in a dataset is an error.
        names: Only these dataset names (file stems).
        kitchen: Kitchen whose catalogue names the family of objects when a file has no family column.
    """
    directory = Path(directory)
    datasets = load_datasets(directory, min_rows=min_rows, names=names)
    lookup: dict[str, str] | None = None
    out = []
    for d in datasets:
        families: list[str] | None = None
        if len(d.families) == len(d) and any(d.families):
            families = [f or UNKNOWN_FAMILY for f in d.families]
        else:
            if lookup is None:
                lookup = _catalogue_families(kitchen)
            families = [lookup.get(o, UNKNOWN_FAMILY) for o in d.objects]
        out.append(EvalDataset.from_dataset(d, families, decision_time_context(d)))
    return out
