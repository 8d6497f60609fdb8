"""Benchmark work spread over processes, with results in submission order and no hang on failure.

``process_pool(jobs)`` opens a spawn-context process pool (None for ``jobs`` = 1: the caller's own process);
``ordered_map(pool, fn, calls)`` yields ``fn(*call)`` for each call in the calls' order, whatever order the
workers finish in, so a report aggregated from it does not depend on ``jobs``.

Failures: an exception raised by ``fn`` in a worker is raised again here (a SconeError stays one, so the CLI
prints its usual one line, even where its class cannot be rebuilt from a pickle); a worker that dies (killed, out of memory, a crash in C) becomes a SconeError. On
any exception, Ctrl-C included, the pool's queued calls are dropped and its workers terminated before the
exception propagates: nothing waits for work whose result nobody will read. Workers ignore SIGINT (the
terminal sends it to the whole process group), so Ctrl-C is handled once, here.
"""

from __future__ import annotations

import concurrent.futures as cf
import contextlib
import pickle
from collections.abc import Callable, Iterator, Sequence
from typing import Any

from scone_bt.distributed.pool import abort_pool, spawn_pool
from scone_bt.errors import SconeError

__all__ = ["ordered_map", "process_pool"]


@contextlib.contextmanager
def process_pool(jobs: int) -> Iterator[cf.ProcessPoolExecutor | None]:
    """A pool of ``jobs`` spawned worker processes, or None when ``jobs`` is 1 (run in this process).

    Spawned workers that ignore SIGINT (`scone_bt.distributed.pool`).
    """
    if jobs <= 1:
        yield None
        return
    pool = spawn_pool(jobs)
    try:
        yield pool
    except BaseException:
        abort_pool(pool)
        raise
    pool.shutdown(wait=True)


def _pickles(exc: BaseException) -> bool:
    """Whether ``exc`` survives the trip back to the parent (one that does not would break the whole pool)."""
    try:
        pickle.loads(pickle.dumps(exc))
    except Exception:  # any failure, pickling or unpickling, means the same
        return False
    return True


def _call(fn: Callable[..., Any], args: tuple[Any, ...]) -> Any:
    """``fn(*args)`` in a worker; an exception that cannot be unpickled is raised as its message instead.

    Exceptions with required constructor arguments (UnknownNameError) cannot be rebuilt from their pickle, and
    the pool would report them as a dead worker: a SconeError keeps its one-line message as a SconeError.
    """
    try:
        return fn(*args)
    except Exception as exc:
        if _pickles(exc):
            raise
        if isinstance(exc, SconeError):
            raise SconeError(str(exc)) from None
        raise RuntimeError(f"{type(exc).__name__}: {exc}") from None


def _result(future: cf.Future[Any]) -> Any:
    """The future's result; a worker that died is a SconeError, not a BrokenProcessPool traceback."""
    try:
        return future.result()
    except cf.process.BrokenProcessPool as exc:
        raise SconeError(f"a worker process died ({exc}); rerun with --jobs 1 to see its error") from None


def ordered_map(
    pool: cf.ProcessPoolExecutor | None, fn: Callable[..., Any], calls: Sequence[tuple[Any, ...]]
) -> Iterator[Any]:
    """``fn(*call)`` for each call, yielded in the calls' order (in this process when ``pool`` is None).

    With a pool every call is submitted at once (``fn`` and its arguments must pickle: a module-level function).
    """
    if pool is None:
        for call in calls:
            yield fn(*call)
        return
    futures = [pool.submit(_call, fn, call) for call in calls]
    for future in futures:
        yield _result(future)
