"""Finds the declarative inputs (robots/, perception/, trees/) in a checkout or in an installed wheel."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Literal

from scone_bt.environment import folder_variable, switch_on
from scone_bt.errors import ConfigError, UnknownNameError

__all__ = [
    "DataKind",
    "cache_switched_off",
    "data_dir",
    "default_cache_dir",
    "resolve_file",
    "repo_root",
    "shared_dir",
]

DataKind = Literal["robots", "perception", "trees"]
_PACKAGE = Path(__file__).resolve().parent


def repo_root() -> Path | None:
    """The checkout root when running from a source tree, else None."""
    root = _PACKAGE.parent
    return root if (root / "pyproject.toml").is_file() and (root / "robots").is_dir() else None


def default_cache_dir() -> Path:
    """Where caches live (embeddings, models, rendered backgrounds): $SCONE_BT_CACHE, else
    $XDG_CACHE_HOME/scone_bt, else ~/.cache/scone_bt."""
    # Not checked here: a cache that cannot be written is skipped, never a failure. A command refuses a bad
    # $SCONE_BT_CACHE as it starts (`environment.check_environment`).
    if env := os.environ.get("SCONE_BT_CACHE", "").strip():
        return Path(env).expanduser()
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "scone_bt"


def cache_switched_off(variable: str) -> bool:
    """True when the environment variable that governs one disk cache says 0 (or false, no, off; any other value
    but the ``on`` ones is a ConfigError: `environment.switch_on`)."""
    return not switch_on(variable)


def data_dir(kind: DataKind) -> Path:
    """Directory holding the user-editable files of one kind.

    Order: $SCONE_BT_DATA/<kind>, the checkout's top-level folder, the copy inside the wheel.
    """
    candidates = []
    if (env := folder_variable("SCONE_BT_DATA")) is not None:
        candidates.append(env / kind)
    if (root := repo_root()) is not None:
        candidates.append(root / kind)
    candidates.append(_PACKAGE / "_data" / kind)
    for path in candidates:
        if path.is_dir():
            return path
    raise ConfigError(f"cannot find the {kind}/ folder; looked in: {', '.join(map(str, candidates))}")


_WHAT: dict[str, str] = {"robots": "robot", "perception": "kitchen", "trees": "tree"}
"""What a file of each kind is called in messages."""


def resolve_file(
    kind: DataKind, name_or_path: str | os.PathLike[str], suffixes: tuple[str, ...], flag: str | None = None
) -> Path:
    """A file given by path, or by bare name inside data_dir(kind) (e.g. 'panda' → robots/panda.yaml).

    Raises:
        ConfigError: a path (it has a folder or one of `suffixes`, or exists) that is not a file, naming `flag`.
        UnknownNameError: a bare name that is not one of the files in data_dir(kind) (naming `flag`, if given).
    """
    path = Path(name_or_path)
    if path.is_file():
        return path
    folder = data_dir(kind)
    for suffix in ("", *suffixes):
        candidate = folder / f"{name_or_path}{suffix}"
        if candidate.is_file():
            return candidate
    names = sorted({p.stem for p in folder.iterdir() if p.suffix in suffixes})
    what = _WHAT.get(kind, kind.rstrip("s"))
    text = str(name_or_path)
    looks_like_path = (
        os.sep in text or (os.altsep is not None and os.altsep in text) or path.suffix in suffixes
    )
    if looks_like_path or path.exists():
        reason = (
            "is a folder, not a file"
            if path.is_dir()
            else "is not a file"
            if path.exists()
            else "no such file"
        )
        raise ConfigError(
            f"{flag + ' ' if flag else ''}{text}: {reason}; give a {what} name (valid: {', '.join(names) or '(none)'}) "
            f"or a path to a {what} YAML file"
        )
    error = UnknownNameError(what, text, names)
    if flag:
        error.args = (f"{flag} {text}: unknown {what}; valid: {', '.join(error.valid) or '(none)'}",)
    raise error


def shared_dir() -> Path | None:
    """The workplace's shared/ folder beside the checkout (holds the recipe corpus), if present."""
    for candidate in (
        folder_variable("SCONE_BT_SHARED"),  # set, it must be a folder: no silent fall-back to ../shared
        (repo_root() or Path.cwd()).parent / "shared",
        Path.cwd().parent / "shared",
    ):
        if candidate is not None and candidate.is_dir():
            return candidate
    return None
