"""Per-task seeding: a task's random draws depend on its index, never on the worker that runs it."""

from __future__ import annotations

import random
from collections.abc import Callable
from typing import Any

import numpy as np

__all__ = ["task_seed", "run_seeded"]

_NO_SHARED = object()


def task_seed(rng_seed: int, index: int) -> int:
    """A 63-bit seed for task `index` of a batch seeded with `rng_seed` (independent streams per index)."""
    return int(np.random.SeedSequence([rng_seed, index]).generate_state(2, np.uint32).view(np.uint64)[0] >> 1)


def run_seeded(fn: Callable[..., Any], index: int, item: Any, rng_seed: int, shared: Any = _NO_SHARED) -> Any:
    """Call fn(item) (or fn(item, shared)) with the global generators seeded for this task.

    Well-written tasks carry their seed in the item; seeding the globals too means a library that draws from
    `random` or NumPy's legacy generator cannot make the result depend on which worker ran the task before.
    """
    seed = task_seed(rng_seed, index)
    random.seed(seed)
    np.random.seed(seed % 2**32)
    return fn(item) if shared is _NO_SHARED else fn(item, shared)
