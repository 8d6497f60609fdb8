"""SIGTERM ends a command as Ctrl-C does: `kill`, `timeout` and a service manager's stop are interrupts too.

Without it the default action killed the process on the spot: no "interrupted" line, a study session left with
no end time, a recording not kept. `terminate_as_interrupt` turns SIGTERM into KeyboardInterrupt for the commands
whose Ctrl-C path already unwinds cleanly.
"""

from __future__ import annotations

import contextlib
import signal
import threading
from collections.abc import Iterator
from types import FrameType

__all__ = ["terminate_as_interrupt"]


def _raise_interrupt(signum: int, frame: FrameType | None) -> None:
    raise KeyboardInterrupt


@contextlib.contextmanager
def terminate_as_interrupt() -> Iterator[None]:
    """Within the block, SIGTERM raises KeyboardInterrupt in the main thread (only where SIGTERM still has its
    default action: a caller's own handler, or an ignored SIGTERM, is left alone); restored after."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.getsignal(signal.SIGTERM)
    if previous is not signal.SIG_DFL:
        yield
        return
    signal.signal(signal.SIGTERM, _raise_interrupt)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)
