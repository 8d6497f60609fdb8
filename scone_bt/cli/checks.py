"""Checks of command-line values that argparse's types cannot express, done before any long work starts.

Each check raises SconeError with one line naming the flag, the value and what is allowed.
"""

from __future__ import annotations

import math
import os
from pathlib import Path

from scone_bt.errors import SconeError

__all__ = [
    "MAX_SEED",
    "check_seed",
    "check_port",
    "check_range",
    "check_output_file",
    "check_output_dir",
    "check_positive_int",
    "internal_error_line",
]

MAX_SEED = 2**32 - 1
"""Seeds are unsigned 32-bit integers (numpy, OMPL and PyBullet all accept this range)."""


def check_seed(value: int, flag: str = "--seed") -> int:
    if not 0 <= value <= MAX_SEED:
        raise SconeError(f"{flag} {value}: must be an integer in 0..{MAX_SEED}")
    return value


def check_port(value: int, flag: str = "--port") -> int:
    if not 0 <= value <= 65535:
        raise SconeError(f"{flag} {value}: must be a TCP port in 0..65535 (0: any free port)")
    return value


def check_positive_int(value: int, flag: str, maximum: int = 10**9) -> int:
    if not 1 <= value <= maximum:
        raise SconeError(f"{flag} {value}: must be an integer in 1..{maximum}")
    return value


def check_range(value: float, flag: str, low: float, high: float) -> float:
    if not (math.isfinite(value) and low <= value <= high):
        raise SconeError(f"{flag} {value}: must be a number in [{low:g}, {high:g}]")
    return value


def _first_existing_parent(path: Path) -> tuple[Path, Path | None]:
    """The nearest existing ancestor folder, and the ancestor that exists but is not a folder (if any)."""
    for parent in path.absolute().parents:
        if parent.exists():
            return parent, (None if parent.is_dir() else parent)
    return Path("/"), None


def check_output_file(path: Path, flag: str, must_not_exist: bool = False) -> Path:
    """A file that will be written: its folder exists or can be made, and it is writable.

    Args:
        path: The file.
        flag: The option's name, for the message.
        must_not_exist: Refuse an existing file (outputs that are never overwritten).
    """
    if path.is_dir():
        raise SconeError(f"{flag} {path}: is a folder; give a file path")
    if must_not_exist and path.exists():
        raise SconeError(f"{flag} {path}: already exists; it is never overwritten, give a new path")
    folder, blocker = _first_existing_parent(path)
    if blocker is not None:
        raise SconeError(f"{flag} {path}: {blocker} is a file, not a folder")
    if path.exists() and not os.access(path, os.W_OK):
        raise SconeError(f"{flag} {path}: the file is read-only")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise SconeError(f"{flag} {path}: cannot write in {folder} (read-only or no permission)")
    return path


def check_output_dir(path: Path, flag: str, must_be_new: bool = False) -> Path:
    """A folder that will be written into: it is a folder (or can be made) and writable.

    Args:
        path: The folder.
        flag: The option's name, for the message.
        must_be_new: Refuse a folder that exists and is not empty (outputs that are never overwritten).
    """
    if path.exists() and not path.is_dir():
        raise SconeError(f"{flag} {path}: is a file, not a folder; it is never overwritten")
    if must_be_new and path.is_dir() and any(path.iterdir()):
        raise SconeError(
            f"{flag} {path}: exists and is not empty; its files are never overwritten, give a new folder"
        )
    folder, blocker = _first_existing_parent(path / "x")
    if blocker is not None:
        raise SconeError(f"{flag} {path}: {blocker} is a file, not a folder")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise SconeError(f"{flag} {path}: cannot write in {folder} (read-only or no permission)")
    return path


def internal_error_line(exc: BaseException) -> str:
    """One line for an unexpected exception: a program error stops the run and is never stored as an outcome."""
    text = " ".join(str(exc).split())
    text = text if len(text) <= 300 else text[:297] + "..."
    return (
        f"{type(exc).__name__}: {text or '(no message)'} (a program error, not an outcome of the robot: "
        "the run stopped; nothing was stored for it; SCONE_BT_DEBUG=1 shows the traceback)"
    )
