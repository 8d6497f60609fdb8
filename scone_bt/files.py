"""Writing a file so that a reader never sees half of it."""

from __future__ import annotations

import os
import stat
import tempfile
from collections.abc import Callable
from pathlib import Path

__all__ = ["temporary_beside", "replace_with", "write_atomic", "write_via"]


def write_atomic(path: Path | str, data: str | bytes) -> None:
    """Write `data` to `path` through a temporary file in the same folder, renamed over it when complete.

    A write that fails (disk full, an interrupt) leaves the old file whole and no temporary file behind.
    """
    raw = data.encode() if isinstance(data, str) else data

    def write(tmp: Path) -> None:
        with tmp.open("wb") as f:
            f.write(raw)
            f.flush()
            os.fsync(f.fileno())

    write_via(path, write, suffix=".tmp")


def write_via(path: Path | str, write: Callable[[Path], None], suffix: str | None = None) -> None:
    """Let `write` fill a temporary file beside `path` (named with `suffix`, default `path`'s, for writers that
    pick the format by it), then rename it over `path`; if `write` fails, the old file stays whole."""
    path = Path(path)
    tmp = temporary_beside(path, path.suffix if suffix is None else suffix)
    try:
        write(tmp)
        replace_with(path, tmp)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


def temporary_beside(path: Path | str, suffix: str = ".tmp") -> Path:
    """A new empty file in `path`'s folder, hidden, named after it (a rename over `path` is then atomic)."""
    path = Path(path)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=suffix, dir=path.parent)
    os.close(fd)
    return Path(tmp)


def replace_with(path: Path | str, tmp: Path | str) -> None:
    """Rename the finished `tmp` over `path`, with `path`'s permissions if it exists (else the umask's)."""
    if os.path.exists(path):  # keep the old file's permissions (mkstemp makes 0600)
        os.chmod(tmp, stat.S_IMODE(os.stat(path).st_mode))
    else:
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
    os.replace(tmp, path)
