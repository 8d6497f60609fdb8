"""The environment variables a user may set, each read and checked here.

Every command checks them once, as it parses its command line (`argparsing.OneLineArgumentParser`), so a typo is
one line before any work instead of a traceback where the value is first used, or a value silently read as
another. The readers below are what the rest of the code calls; they raise the same one-line error.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Mapping
from pathlib import Path

from scone_bt.errors import ConfigError

__all__ = [
    "SWITCHES",
    "VARIABLES",
    "check_environment",
    "embed_runtime",
    "folder_variable",
    "switch_on",
    "torch_threads",
]

_ON = ("1", "true", "yes", "on")
_OFF = ("0", "false", "no", "off")
SWITCHES = (*_ON, *_OFF)
"""What an on/off variable accepts (case and surrounding spaces ignored)."""

VARIABLES: dict[str, str] = {
    "SCONE_BT_CACHE": "folder of the caches (embeddings, models, rendered backgrounds, parsed YAML)",
    "SCONE_BT_DATA": "folder holding robots/, perception/ and trees/ to use instead of the checkout's",
    "SCONE_BT_SHARED": "the shared/ folder that holds data/recipes/, the recipe corpus",
    "SCONE_BT_MPNET": "folder of an assembled all-mpnet-base-v2 model",
    "SCONE_BT_TORCH_THREADS": "threads of an embedding forward pass: a whole number from 1 to 1024",
    "SCONE_BT_EMBED_RUNTIME": "torch: run MiniLM in sentence-transformers instead of numpy (valid: numpy, torch)",
    "SCONE_BT_RENDER_CACHE": "0 switches off the disk cache of rendered backgrounds (valid: "
    + ", ".join(SWITCHES)
    + ")",
    "SCONE_BT_YAML_CACHE": "0 switches off the disk cache of parsed YAML files (valid: "
    + ", ".join(SWITCHES)
    + ")",
    "SCONE_BT_DEBUG": "any value: an internal error prints its traceback",
}
"""Every variable the code reads, with what it means (the reference lists them)."""

_RUNTIMES = ("numpy", "torch")
_MAX_THREADS = 1024
"""Most threads an embedding forward pass may be given (more is a typo: torch refuses it only when it encodes)."""


def _value(name: str, environ: Mapping[str, str] | None) -> str | None:
    value = (os.environ if environ is None else environ).get(name)
    return None if value is None else value.strip()


def switch_on(name: str, environ: Mapping[str, str] | None = None) -> bool:
    """An on/off variable (`SWITCHES`); unset or empty is on.

    Raises:
        ConfigError: any other value.
    """
    value = _value(name, environ)
    if not value:
        return True
    if value.lower() in SWITCHES:
        return value.lower() in _ON
    raise ConfigError(f"{name}={value!r}: must be one of {', '.join(SWITCHES)}")


def torch_threads(environ: Mapping[str, str] | None = None) -> int | None:
    """$SCONE_BT_TORCH_THREADS as a number ≥ 1, or None when unset or empty.

    Raises:
        ConfigError: not a whole number from 1 to `_MAX_THREADS`.
    """
    value = _value("SCONE_BT_TORCH_THREADS", environ)
    if not value:
        return None
    if not (value.isascii() and value.isdecimal()) or not 1 <= int(value) <= _MAX_THREADS:
        raise ConfigError(
            f"SCONE_BT_TORCH_THREADS={value!r}: must be a whole number from 1 to {_MAX_THREADS}"
        )
    return int(value)


def embed_runtime(environ: Mapping[str, str] | None = None) -> str:
    """$SCONE_BT_EMBED_RUNTIME: ``numpy`` (the default, where the model allows it) or ``torch``.

    Raises:
        ConfigError: another value.
    """
    value = (_value("SCONE_BT_EMBED_RUNTIME", environ) or "numpy").lower()
    if value not in _RUNTIMES:
        raise ConfigError(f"SCONE_BT_EMBED_RUNTIME={value!r}: must be one of {', '.join(_RUNTIMES)}")
    return value


def folder_variable(
    name: str, environ: Mapping[str, str] | None = None, *, may_create: bool = False
) -> Path | None:
    """A variable naming a folder, or None when unset or empty.

    Raises:
        ConfigError: the path is a file, or (unless ``may_create``) no folder is there; with ``may_create`` a
            path under a file.
    """
    value = _value(name, environ)
    if not value:
        return None
    path = Path(value).expanduser()
    if path.is_dir():
        return path
    if path.exists():
        raise ConfigError(f"{name}={value}: is a file, not a folder ({VARIABLES[name]})")
    if not may_create:
        raise ConfigError(f"{name}={value}: no such folder ({VARIABLES[name]})")
    for parent in path.parents:
        if parent.exists():
            if not parent.is_dir():
                raise ConfigError(f"{name}={value}: {parent} is a file, so the folder cannot be made")
            break
    return path


_CHECKS: dict[str, Callable[[Mapping[str, str] | None], object]] = {
    "SCONE_BT_CACHE": lambda env: folder_variable("SCONE_BT_CACHE", env, may_create=True),
    "SCONE_BT_DATA": lambda env: folder_variable("SCONE_BT_DATA", env),
    "SCONE_BT_SHARED": lambda env: folder_variable("SCONE_BT_SHARED", env),
    "SCONE_BT_MPNET": lambda env: folder_variable("SCONE_BT_MPNET", env),
    "SCONE_BT_TORCH_THREADS": torch_threads,
    "SCONE_BT_EMBED_RUNTIME": embed_runtime,
    "SCONE_BT_RENDER_CACHE": lambda env: switch_on("SCONE_BT_RENDER_CACHE", env),
    "SCONE_BT_YAML_CACHE": lambda env: switch_on("SCONE_BT_YAML_CACHE", env),
}
"""How each variable of `VARIABLES` is read (SCONE_BT_DEBUG takes any value); a test keeps the two in step."""


def check_environment(environ: Mapping[str, str] | None = None) -> None:
    """Check every variable of `VARIABLES` that is set.

    Raises:
        ConfigError: the first bad one, in one line naming it and what it accepts.
    """
    for check in _CHECKS.values():
        check(environ)
