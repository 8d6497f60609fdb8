"""The local engine: a process pool on this machine, or the calling process itself for one worker.

A worker process that dies (killed, out of memory, a crash in a C extension) breaks a ProcessPoolExecutor as a
whole; the pool is then rebuilt and every task that had not returned is submitted again, each counted against
`max_retries`. Results are keyed by task index, so a task is reported exactly once. Workers ignore SIGINT; Ctrl-C (or a caller
that stops reading) terminates them (`scone_bt.distributed.pool`).
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import FIRST_COMPLETED, Future, wait
from concurrent.futures.process import BrokenProcessPool
from typing import Any

from scone_bt.distributed.options import EngineOptions
from scone_bt.distributed.pool import abort_pool, spawn_pool
from scone_bt.distributed.seeding import _NO_SHARED, run_seeded
from scone_bt.errors import DistributedError

__all__ = ["imap_local"]

_SHARED: Any = _NO_SHARED  # the batch's shared object, set once per worker process by _init_worker


def _init_worker(has_shared: bool, shared: Any) -> None:
    global _SHARED
    _SHARED = shared if has_shared else _NO_SHARED  # the sentinel's identity does not survive pickling


def _call(fn: Callable[..., Any], index: int, item: Any, rng_seed: int) -> Any:
    return run_seeded(fn, index, item, rng_seed, _SHARED)


def imap_local(
    fn: Callable[..., Any], items: Sequence[Any], options: EngineOptions, shared: Any = _NO_SHARED
) -> Iterator[tuple[int, Any]]:
    """Yield (index, fn(items[index])) as tasks finish, each index exactly once."""
    workers = min(options.local_workers(), max(1, len(items)))
    if workers == 1:
        for i, item in enumerate(items):
            yield i, run_seeded(fn, i, item, options.rng_seed, shared)
        return
    todo = list(range(len(items)))[::-1]  # popped from the end: submitted in index order
    attempts = dict.fromkeys(range(len(items)), 0)
    while todo:
        pool = spawn_pool(workers, _init_worker, (shared is not _NO_SHARED, shared))
        running: dict[Future, int] = {}
        broken = False
        try:
            while todo or running:
                while todo and len(running) < 2 * workers:  # a short queue keeps the progress bar honest
                    i = todo.pop()
                    attempts[i] += 1
                    running[pool.submit(_call, fn, i, items[i], options.rng_seed)] = i
                finished, _ = wait(running, return_when=FIRST_COMPLETED)
                for future in finished:
                    i = running.pop(future)
                    try:
                        value = future.result()
                    except BrokenProcessPool:
                        broken = True
                        todo.append(i)
                        continue
                    yield i, value
                if broken:
                    break
        except BaseException:  # Ctrl-C, or the caller stopped reading: nothing waits for the running tasks
            abort_pool(pool)
            raise
        pool.shutdown(wait=not broken, cancel_futures=True)
        if broken:
            todo.extend(running.values())  # tasks that were queued or running when a worker died
            todo = sorted(set(todo), reverse=True)
            failed = [i for i in todo if attempts[i] > options.max_retries]
            if failed:
                raise DistributedError(
                    f"task {failed[0]} lost its worker process {attempts[failed[0]]} times "
                    f"(max_retries={options.max_retries}); giving up"
                )
