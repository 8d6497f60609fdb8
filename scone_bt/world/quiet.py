"""PyBullet prints its build banner and argv from C on import and connect; users should not see that."""

from __future__ import annotations

import contextlib
import os
import sys
from collections.abc import Iterator

__all__ = ["c_stdout_silenced"]


@contextlib.contextmanager
def c_stdout_silenced() -> Iterator[None]:
    """Redirect the process's file descriptor 1 to /dev/null (C-level printf included)."""
    try:
        fd = sys.stdout.fileno()
    except (AttributeError, OSError, ValueError):  # pytest capture or a replaced stdout: nothing to silence
        yield
        return
    sys.stdout.flush()
    saved = os.dup(fd)
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, fd)
        yield
    finally:
        sys.stdout.flush()
        os.dup2(saved, fd)
        os.close(saved)
        os.close(devnull)
