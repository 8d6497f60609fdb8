"""Worker pools stop at once on Ctrl-C: workers ignore SIGINT, and the parent terminates them instead of waiting
for their tasks (``scone-scenario run --jobs 2`` went on for a minute after Ctrl-C; ``sc generate`` workers ran
their next task in a half-restocked kitchen)."""

from __future__ import annotations

import time
from pathlib import Path

import engine_tasks
import pytest

from scone_bt.distributed import EngineOptions
from scone_bt.distributed.local import imap_local
from scone_bt.distributed.pool import abort_pool, spawn_pool


def test_spawned_workers_ignore_sigint() -> None:
    pool = spawn_pool(2)
    try:
        assert list(pool.map(engine_tasks.sigint_ignored, range(4))) == [True] * 4
    finally:
        pool.shutdown(wait=True)


def test_abort_terminates_running_workers() -> None:
    pool = spawn_pool(2)
    pool.submit(engine_tasks.sigint_ignored, 0).result()  # the workers are up
    processes = list(pool._processes.values())
    pool.submit(time.sleep, 30)
    abort_pool(pool)
    # A worker left running would sleep on for 30 s: given 10 s, a terminated one has surely been reaped (its
    # status is recorded by whichever thread reaps it first, the pool's own or this one).
    for process in processes:
        process.join(timeout=10.0)
    assert processes and not any(p.is_alive() for p in processes)


@pytest.mark.parametrize("stop", [KeyboardInterrupt, GeneratorExit])
def test_an_interrupted_local_batch_does_not_wait_for_its_running_tasks(tmp_path: Path, stop: type) -> None:
    items = [(n, str(tmp_path)) for n in range(4)]
    source = imap_local(engine_tasks.slow_then_mark, items, EngineOptions(workers=2))
    assert next(source) == (0, 0)
    with pytest.raises(stop):
        source.throw(stop)  # Ctrl-C in the consumer, or a consumer that stops reading
    # the running tasks were terminated: none of them ever finishes, even given the time to
    time.sleep(4.0)
    assert not list(tmp_path.glob("finished-*"))
