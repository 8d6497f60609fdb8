"""Quiet third-party libraries; `c_stdout_silenced` hides what C code prints (PyBullet's build banner and argv on
import and connect, which the simulated kitchen imports and connects inside it)."""

from __future__ import annotations

import contextlib
import ctypes
import os
import sys
from collections.abc import Iterator

__all__ = ["c_stdout_silenced", "quiet_backends"]


def _flush_c_stdio() -> None:
    # C's stdio buffers would otherwise reach the terminal at exit, after the descriptors are restored.
    with contextlib.suppress(OSError, AttributeError):
        ctypes.CDLL(None).fflush(None)


@contextlib.contextmanager
def c_stdout_silenced() -> Iterator[None]:
    """Send the process's stdout and stderr descriptors to /dev/null, C-level printf included."""
    fds = []
    for stream in (sys.stdout, sys.stderr):
        # pytest's capture or a replaced stream has no descriptor: leave it alone
        with contextlib.suppress(AttributeError, OSError, ValueError):
            fds.append(stream.fileno())
    for stream in (sys.stdout, sys.stderr):
        stream.flush()
    saved = [os.dup(fd) for fd in fds]
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        for fd in fds:
            os.dup2(devnull, fd)
        yield
    finally:
        for stream in (sys.stdout, sys.stderr):
            stream.flush()
        _flush_c_stdio()
        for fd, copy in zip(fds, saved, strict=True):
            os.dup2(copy, fd)
            os.close(copy)
        os.close(devnull)


def quiet_backends(loggers: tuple[str, ...] = ()) -> None:
    """Offline, quiet third-party libraries for command-line use: no hub look-ups, no banners, no warnings."""
    import logging
    import warnings

    os.environ.setdefault("TOKENIZERS_PARALLELISM", "false")
    os.environ.setdefault("HF_HUB_OFFLINE", "1")
    os.environ.setdefault("TRANSFORMERS_OFFLINE", "1")
    warnings.filterwarnings("ignore")
    for name in ("sentence_transformers", "transformers", *loggers):
        logging.getLogger(name).setLevel(logging.ERROR)
    # PyBullet is not imported here: only the simulator backend imports it, silenced (`world.Kitchen`).
