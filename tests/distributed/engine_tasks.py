"""Task functions for the engine tests (importable by worker processes)."""

from __future__ import annotations

import os
import random
from pathlib import Path

import numpy as np

from scone_bt.errors import SconeError


def seeded_draws(item: int) -> tuple[int, float, float, int]:
    """Draws from the item's own generator and from the globals the engine seeds per task."""
    return (
        item,
        float(np.random.default_rng(item).random()),
        float(np.random.random()),
        random.randrange(10**6),
    )


def die_once(item: tuple[int, str]) -> int:
    """Kill this worker process the first time item 3 runs (a marker file remembers), else square the number."""
    n, folder = item
    with open(Path(folder) / f"attempts-{n}", "a") as f:
        f.write("x")
    marker = Path(folder) / "died"
    if n == 3 and not marker.exists():
        marker.write_text("once")
        os._exit(1)  # like SIGKILL or an out-of-memory kill: no exception, no cleanup
    return n * n


def fail_on_two(item: tuple[int, str]) -> int:
    """A program error on item 2 (must not be retried)."""
    n, folder = item
    with open(Path(folder) / f"attempts-{n}", "a") as f:
        f.write("x")
    if n == 2:
        raise SconeError("item 2 is bad input")
    return n


def sigint_ignored(_item: object) -> bool:
    """Whether this worker ignores SIGINT (Ctrl-C is the parent's to handle)."""
    import signal

    return signal.getsignal(signal.SIGINT) is signal.SIG_IGN


def slow_then_mark(item: tuple[int, str]) -> int:
    """Item 0 returns at once; any other sleeps 3 s, then leaves a marker file (proof that it ran to the end)."""
    import time

    n, folder = item
    if n:
        time.sleep(3.0)
        (Path(folder) / f"finished-{n}").write_text("x")
    return n
