"""Spawned process pools that Ctrl-C stops at once, in one place for every command that runs workers.

A terminal's Ctrl-C reaches the whole process group: workers included. A worker that takes it raises
KeyboardInterrupt inside whatever task it runs (a kitchen half restocked, a scenario half ticked), reports that as
the task's result and goes on to the next queued task in the broken state, while the parent, leaving its ``with``
block, waits for every submitted task: ``scone-scenario run --jobs 2`` went on for a minute after Ctrl-C, and
``sc generate`` printed PyBullet's ``restoreState failed`` from a worker. So workers ignore SIGINT (the parent
handles it once) and, on any exception in the parent, ``abort_pool`` drops the queued tasks and terminates the
workers instead of waiting for them.
"""

from __future__ import annotations

import concurrent.futures as cf
import multiprocessing as mp
import signal
import time
from collections.abc import Callable
from multiprocessing.process import BaseProcess
from typing import Any

__all__ = ["abort_pool", "spawn_pool"]

_TERMINATE_WAIT_S = 5.0
"""Seconds a worker has to exit after SIGTERM before it is killed (a busy machine may be slow to schedule it)."""


def _start_worker(initializer: Callable[..., None] | None, initargs: tuple[Any, ...]) -> None:
    """Worker initialiser: SIGINT is the parent's to handle, then the caller's own initialiser."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    if initializer is not None:
        initializer(*initargs)


def spawn_pool(
    workers: int, initializer: Callable[..., None] | None = None, initargs: tuple[Any, ...] = ()
) -> cf.ProcessPoolExecutor:
    """A pool of ``workers`` spawned processes that ignore SIGINT (``initializer`` must be module-level).

    Spawn, not fork: the parent may hold PyBullet clients, torch thread pools and SQLite handles that a forked
    child must not inherit.
    """
    return cf.ProcessPoolExecutor(
        workers,
        mp_context=mp.get_context("spawn"),
        initializer=_start_worker,
        initargs=(initializer, initargs),
    )


def abort_pool(pool: cf.ProcessPoolExecutor) -> None:
    """Drop queued tasks and terminate the workers now (a running task is not waited for)."""
    processes = list((getattr(pool, "_processes", None) or {}).values())
    pool.shutdown(wait=False, cancel_futures=True)
    for process in processes:
        if process.is_alive():
            process.terminate()
    for process in processes:
        if not _reaped(process, _TERMINATE_WAIT_S):  # SIGTERM not handled in time: no second chance
            process.kill()
            _reaped(process, _TERMINATE_WAIT_S)


def _reaped(process: BaseProcess, timeout_s: float) -> bool:
    """Whether ``process`` exited and its exit status is known, waiting up to ``timeout_s`` seconds.

    The pool's own management thread joins its workers too. When it reaps one first, this thread's ``waitpid``
    gets ECHILD and multiprocessing reports the worker alive until that thread has recorded the status: CI once saw
    a terminated worker "alive" right after ``abort_pool`` returned. So wait for the status, not only the exit.
    """
    deadline = time.monotonic() + timeout_s
    process.join(timeout=timeout_s)
    while process.exitcode is None and time.monotonic() < deadline:
        time.sleep(0.01)
    return process.exitcode is not None
