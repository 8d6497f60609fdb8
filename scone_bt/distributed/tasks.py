"""One API for a batch of independent tasks, on the local process pool or on Ray.

    results = map_tasks(run_execution, items, engine=EngineOptions(workers=2))
    for i, record in imap_tasks(run_execution, items, engine=EngineOptions(EngineKind.RAY, address="auto")):
        save(record)                       # as each task finishes, in any order

Tasks must be deterministic functions of their item (carry the seed in the item): the engine adds per-index
seeding of the global generators, so the results are identical on any engine and for any number of workers.
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Generator, Sequence
from typing import Any, TypeVar

from scone_bt.distributed.options import EngineKind, EngineOptions
from scone_bt.distributed.seeding import _NO_SHARED

__all__ = ["imap_tasks", "map_tasks", "start_engine"]

R = TypeVar("R")


def start_engine(engine: EngineOptions | None) -> str:
    """Connect to (or start) the engine's Ray cluster now, so a bad address fails before any output is created.

    A no-op for the local engine; imap_tasks would otherwise connect on first use.
    """
    if engine is None or engine.kind is not EngineKind.RAY:
        return "local"
    from scone_bt.distributed.ray_engine import connect_ray

    return connect_ray(engine.address, engine.workers)


def imap_tasks(
    fn: Callable[..., R],
    items: Sequence[Any],
    *,
    engine: EngineOptions | None = None,
    shared: Any = _NO_SHARED,
) -> Generator[tuple[int, R], None, None]:
    """Yield (index, fn(items[index])) as tasks finish (any order), each index exactly once.

    Args:
        fn: A picklable (module-level) function of one item, or of (item, shared) when `shared` is given.
        items: The work items (picklable); each should carry its own seed.
        engine: Where to run (default: the local pool on every CPU).
        shared: An object every task reads (datasets, features): sent to each worker once, not per task.

    Raises:
        DistributedError: a worker died more than `max_retries` times, or Ray cannot be reached.
        Exception: whatever a task raised (program errors are not retried).
    """
    opts = engine or EngineOptions()
    items = list(items)
    if opts.kind is EngineKind.RAY:
        from scone_bt.distributed.ray_engine import imap_ray

        source = imap_ray(fn, items, opts, shared)
    else:
        from scone_bt.distributed.local import imap_local

        source = imap_local(fn, items, opts, shared)
    if opts.progress is None:
        yield from source
        return
    from tqdm import tqdm

    with tqdm(total=len(items), desc=opts.progress, unit="task", file=sys.stderr) as bar:
        for pair in source:
            bar.update(1)
            yield pair


def map_tasks(
    fn: Callable[..., R],
    items: Sequence[Any],
    *,
    engine: EngineOptions | None = None,
    shared: Any = _NO_SHARED,
) -> list[R]:
    """fn over items, results in item order (see imap_tasks)."""
    items = list(items)
    out: dict[int, R] = dict(imap_tasks(fn, items, engine=engine, shared=shared))
    return [out[i] for i in range(len(items))]
