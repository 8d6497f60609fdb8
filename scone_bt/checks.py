"""Checks of command-line values that argparse's types cannot express, done before any long work starts.

Each check raises SconeError with one line naming the flag, the value and what is allowed.
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import stat
import tempfile
from collections.abc import Callable, Iterable, Mapping
from pathlib import Path
from typing import Literal

from scone_bt.errors import SconeError
from scone_bt.files import write_atomic

__all__ = [
    "MAX_SEED",
    "OUTPUT_KINDS",
    "OutputKind",
    "REPORT_KEYS",
    "RRD_MAGIC",
    "check_seed",
    "check_port",
    "check_at_least",
    "comma_list",
    "check_range",
    "check_output_file",
    "check_output_dir",
    "check_not_yaml",
    "check_positive_int",
    "internal_error_line",
    "is_output_kind",
    "is_report",
    "same_file",
    "sqlite_files",
    "write_atomic",
]

OutputKind = Literal["rrd", "json", "report", "csv", "sqlite", "text", "image"]
REPORT_KEYS = ("benchmark", "wall_s", "seconds", "timing_s", "machine", "meets_targets")
"""A benchmark report is a JSON object with one of these keys at its top level (every report scone-bench writes
has one; docs/results/*.json do): a recipe, a scenario schema or a data file there is not a report."""
OUTPUT_KINDS: dict[str, str] = {
    "rrd": "a rerun recording (.rrd)",
    "json": "a JSON file",
    "report": f"a benchmark report (a JSON object with a {', '.join(REPORT_KEYS[:-1])} or {REPORT_KEYS[-1]} key)",
    "csv": "a CSV file",
    "sqlite": "an SQLite file",
    "text": "a text file",
    "image": "an image (PNG, SVG or PDF)",
}
"""What each kind of output is called in messages."""

RRD_MAGIC = (b"RRF0", b"RRF1", b"RRF2", b"RRIS")
"""The first four bytes of a rerun recording (file format versions of rerun-sdk 0.x)."""

_SQLITE_MAGIC = b"SQLite format 3\x00"
_IMAGE_MAGIC = (b"\x89PNG\r\n\x1a\n", b"%PDF-")
_SNIFF_BYTES = 1 << 20  # a JSON/CSV/text file is judged on its first MiB: an output of ours is small
_REPORT_BYTES = 16 << 20  # a report is parsed whole; none of ours is this large (docs/results: < 1 MiB)
_YAML_SUFFIXES = (".yaml", ".yml")
_SQLITE_SIDECARS = ("-wal", "-shm", "-journal")

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


def comma_list(text: str, flag: str, example: str) -> tuple[str, ...]:
    """The items of a comma list given to ``flag``, stripped; an empty list or an empty item ("10,,20", "") is one
    line naming the flag and an ``example`` (a typo must not silently drop an item or select everything)."""
    items = tuple(x.strip() for x in text.split(","))
    if not text.strip() or any(not x for x in items):
        raise SconeError(f"{flag} {text!r}: a comma list with no empty item, e.g. {example}")
    return items


def check_at_least(value: int, flag: str, least: int) -> int:
    """``value`` of ``flag`` if it is ``least`` or more, else one line naming both ("--chains 0: must be 1 or more")."""
    if value < least:
        raise SconeError(f"{flag} {value}: must be {least} or more")
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


def same_file(a: Path | str, b: Path | str) -> bool:
    """True when `a` and `b` name one file: the same inode (hard links, symlinks followed) or resolved path."""
    try:
        if os.path.samefile(a, b):
            return True
    except OSError:  # one of them does not exist (yet): compare where they would be
        pass
    return os.path.realpath(a) == os.path.realpath(b)


def check_not_yaml(
    path: Path, flag: str, output: str, suffix: str, *, ours: Callable[[Path], bool] | None = None
) -> Path:
    """Refuse an existing YAML file (.yaml/.yml, as named or where a link leads) as the target of an output that
    is not YAML, even with --force: the project's inputs (scenarios, robots, kitchens, profiles) are YAML files, and
    no output of ours is one.

    An empty file, and one that `ours` says already holds this output, may be replaced.

    Args:
        path: The file the output would be written to.
        flag: The option's name, for the message (e.g. "--junit").
        output: What is written, for the message (e.g. "a JUnit report").
        suffix: The output's usual suffix, for the path the message suggests (e.g. ".xml").
        ours: Whether the existing file already is this output (e.g. `is_junit_report`).
    """
    names = (path.name, os.path.basename(os.path.realpath(path)))
    if not any(Path(n).suffix.lower() in _YAML_SUFFIXES for n in names):
        return path
    try:
        st = os.stat(path)
    except OSError:
        return path  # nothing there yet (or a dangling link): nothing to lose
    if not stat.S_ISREG(st.st_mode) or st.st_size == 0 or (ours is not None and ours(path)):
        return path  # a folder or device is check_output_file's to word; empty or ours: nothing lost
    raise SconeError(
        f"{flag} {path}: is a YAML file (an input such as a scenario, robot or kitchen file, perhaps); "
        f"{output} never replaces it, even with --force: give another path (e.g. {path.with_suffix(suffix).name})"
    )


def _head(path: Path, n: int) -> bytes:
    with path.open("rb") as f:
        return f.read(n)


def is_report(data: object) -> bool:
    """Whether parsed JSON is a benchmark report: an object with one of `REPORT_KEYS` at its top level."""
    return isinstance(data, dict) and any(key in data for key in REPORT_KEYS)


def is_output_kind(path: Path, kind: OutputKind) -> bool:
    """Whether the existing regular file `path` is of `kind` (so overwriting it loses nothing of another kind).

    rrd, sqlite and image (PNG, PDF, SVG) by their first bytes; json when its text parses as JSON (a JSON Lines
    file: its first line); report when the whole file is a JSON object with one of `REPORT_KEYS` (`is_report`);
    csv and text when they are UTF-8 text without NUL bytes.
    """
    try:
        size = path.stat().st_size
        head = _head(path, _SNIFF_BYTES)
    except OSError:
        return False
    if size == 0:
        return True  # nothing to lose
    if kind == "report":
        if size > _REPORT_BYTES:
            return False  # none of our reports is this large; do not read it to find out
        try:
            return is_report(json.loads(path.read_bytes()))
        except (OSError, ValueError, RecursionError):  # unreadable, not UTF-8 or not JSON
            return False
    if kind == "rrd":
        return head[:4] in RRD_MAGIC
    if kind == "sqlite":
        return head.startswith(_SQLITE_MAGIC)
    if kind == "image":  # PNG and PDF by their magic, SVG by its root element near the start
        return head.startswith(_IMAGE_MAGIC) or b"<svg" in head[:4096]
    try:
        text = head.decode("utf-8")
    except UnicodeDecodeError as exc:
        if size <= _SNIFF_BYTES or exc.start < len(head) - 4:  # a cut through the last character is fine
            return False
        text = head[: exc.start].decode("utf-8")
    if "\x00" in text:
        return False
    if kind == "json":
        if size > _SNIFF_BYTES:
            return False  # none of our reports is this large; do not guess
        try:
            json.loads(text)
        except ValueError:
            first = text.lstrip().split("\n", 1)[0]
            try:
                json.loads(first)
            except ValueError:
                return False
        return True
    return True  # csv, text: UTF-8 text


def check_output_file(
    path: Path,
    flag: str,
    must_not_exist: bool = False,
    *,
    kind: OutputKind | None = None,
    inputs: Mapping[str, Iterable[Path | str]] | None = None,
    force: bool = False,
) -> Path:
    """A file that will be written: not an input of the run, its folder writable, and nothing else overwritten.

    Checked in order, each failure one line naming the flag: a folder, a device/FIFO/socket (refused at once:
    writing `/dev/full` fails only after the work is done), a file that is one of `inputs` (same inode or resolved
    path, symlinks followed; refused even with --force), an existing file that is not of `kind` (refused unless
    `force`), a folder that is a file or read-only, a read-only file.

    Args:
        path: The file.
        flag: The option's name, for the message.
        must_not_exist: Refuse an existing file (outputs that are never overwritten).
        kind: What the output is; an existing non-empty file of another kind is not overwritten.
        inputs: The run's inputs and stores, by flag (e.g. {"--experience": [db, db-wal]}).
        force: Overwrite an existing file of another kind.
    """
    if path.is_dir():
        raise SconeError(f"{flag} {path}: is a folder; give a file path")
    try:
        st = os.stat(path)
    except OSError:
        st = None
    if st is not None and not stat.S_ISREG(st.st_mode):
        from scone_bt.config.schema import file_kind  # pydantic: only on this error path, not at start-up

        raise SconeError(f"{flag} {path}: is {file_kind(st.st_mode)}, not a file; give a file path")
    for other_flag, files in (inputs or {}).items():
        for other in files:
            if same_file(path, other):
                raise SconeError(
                    f"{flag} {path}: is the {other_flag} {'store' if other_flag == '--experience' else 'input'} "
                    f"of this run ({other}); writing there would destroy it, give another path"
                )
    if must_not_exist and path.exists():
        raise SconeError(f"{flag} {path}: already exists; it is never overwritten, give a new path")
    if st is not None and kind is not None and not force and not is_output_kind(path, kind):
        raise SconeError(
            f"{flag} {path}: exists and is not {OUTPUT_KINDS[kind]}; it is not overwritten "
            "(give another path, or --force to replace it)"
        )
    folder, blocker = _first_existing_parent(path)
    if blocker is not None:
        raise SconeError(f"{flag} {path}: {blocker} is a file, not a folder")
    if path.exists() and not os.access(path, os.W_OK):
        raise SconeError(f"{flag} {path}: the file is read-only")
    if not os.access(folder, os.W_OK | os.X_OK) or not _can_create_in(folder):
        raise SconeError(f"{flag} {path}: cannot write in {folder} (read-only or no permission)")
    return path


def _can_create_in(folder: Path) -> bool:
    """Whether a file can be made in `folder`, by making one: os.access answers yes to root everywhere, also on
    /proc and /sys, where the write would fail only after the work is done."""
    try:
        fd, tmp = tempfile.mkstemp(prefix=".scone-write-check.", dir=folder)
    except OSError:
        return False
    os.close(fd)
    with contextlib.suppress(OSError):
        os.unlink(tmp)
    return True


def sqlite_files(path: Path | str) -> list[Path]:
    """An SQLite database and the files SQLite keeps beside it (-wal, -shm, -journal)."""
    p = Path(path)
    return [p, *(p.with_name(p.name + s) for s in _SQLITE_SIDECARS)]


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
    if not os.access(folder, os.W_OK | os.X_OK) or not _can_create_in(folder):
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
