"""Reading YAML with errors that name the file and the problem in one line."""

from __future__ import annotations

import functools
import math
from collections.abc import Mapping
from pathlib import Path
from typing import Annotated, Any, Union

import yaml
from pydantic import ConfigDict, Field, TypeAdapter, ValidationError

from scone_bt.config.schema import read_text
from scone_bt.errors import ConfigError
from scone_bt.resources import cache_switched_off, default_cache_dir

__all__ = ["read_yaml", "require", "Fields"]


_UNPARSED = object()


def _fast_parse(text: str) -> Any:
    """The document through libyaml's parser when present (7x faster: the grocery catalogue in 0.15 s instead of
    1.1 s), else _UNPARSED: the pure-Python parser then parses it, or words its one-line error.

    A document of `CACHED_MIN_CHARS` or more is also kept, parsed, on disk (`_parsed_path`): a fresh process reads
    the catalogue's family files back in a few milliseconds instead of a quarter of a second.
    """
    loader = getattr(yaml, "CSafeLoader", None)
    if loader is None:
        return _UNPARSED
    path = _parsed_path(text) if len(text) >= CACHED_MIN_CHARS else None
    if path is not None:
        data = _read_parsed(path)
        if data is not _UNPARSED:
            return data
    try:
        data = yaml.load(text, Loader=loader)  # noqa: S506 - a safe loader
    except (yaml.YAMLError, RecursionError, ValueError, TypeError, OverflowError):
        return _UNPARSED
    if path is not None:
        _write_parsed(path, data)
    return data


CACHED_MIN_CHARS = 2048
"""Documents shorter than this are parsed every time (a robot file: a few milliseconds)."""
YAML_CACHE_ENV = "SCONE_BT_YAML_CACHE"
"""Set to 0 to parse every file anew (nothing read or written)."""


def _parsed_path(text: str) -> Path | None:
    """Where the parse of exactly this text is kept: named by a digest of the text, the parser and the Python
    version (marshal's format is Python's own); None when switched off."""
    import hashlib
    import sys

    if cache_switched_off(YAML_CACHE_ENV):
        return None
    key = f"{sys.version_info[:2]} {yaml.__version__} CSafeLoader\n{text}"
    return default_cache_dir() / "yaml" / f"{hashlib.sha256(key.encode()).hexdigest()}.marshal"


def _read_parsed(path: Path) -> Any:
    """The kept parse, or _UNPARSED (none kept, unreadable, damaged, or not a document's data).

    A kept file is the sha256 of its marshal data, then the data: marshal is not meant for damaged input, so only
    data whose digest matches is loaded.
    """
    import hashlib
    import marshal

    try:
        blob = path.read_bytes()
    except OSError:
        return _UNPARSED
    digest, body = blob[:32], blob[32:]
    if len(digest) < 32 or hashlib.sha256(body).digest() != digest:
        return _UNPARSED
    try:
        data = marshal.loads(body)
    except (EOFError, ValueError, TypeError):
        return _UNPARSED
    return data if isinstance(data, dict) else _UNPARSED


def _write_parsed(path: Path, data: Any) -> None:
    """Keep a parse (`files.write_atomic`: a reader never sees half a file); nothing when it cannot be (a type
    marshal does not hold, such as a date, or an unwritable folder)."""
    import hashlib
    import marshal

    from scone_bt.files import write_atomic

    if not isinstance(data, dict):
        return
    try:
        body = marshal.dumps(data)
        path.parent.mkdir(parents=True, exist_ok=True)
        write_atomic(path, hashlib.sha256(body).digest() + body)
    except (OSError, ValueError):
        return


def read_yaml(path: Path) -> dict[str, Any]:
    """Parse a UTF-8 YAML mapping or raise ConfigError naming the file (and the line, for syntax errors)."""
    text = read_text(path)
    data = _fast_parse(text)
    try:
        if data is _UNPARSED:
            data = yaml.safe_load(text)
    except RecursionError:
        raise ConfigError(f"{path}: nested too deeply to be a configuration file") from None
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" line {mark.line + 1}" if mark is not None else ""
        problem = getattr(exc, "problem", None) or (str(exc).splitlines() or ["syntax error"])[0]
        raise ConfigError(f"{path}:{where} is not valid YAML ({problem})") from None
    except (ValueError, TypeError, OverflowError) as exc:  # e.g. a date like 2020-13-45
        raise ConfigError(f"{path}: is not valid YAML ({exc})") from None
    if data is None:
        raise ConfigError(f"{path}: is empty; expected a mapping of keys to values")
    if not isinstance(data, dict):
        raise ConfigError(f"{path}: expected a mapping at the top level, got {type(data).__name__}")
    return data


_STRICT = ConfigDict(strict=True)  # no "3" for 3 and no true for 1, as in the file models (config.schema)
_Vector = TypeAdapter(list[Annotated[float, Field(allow_inf_nan=False)]], config=_STRICT)


@functools.cache
def _adapter(kind: type | tuple[type, ...]) -> TypeAdapter[Any]:
    """A pydantic validator for `kind` (a tuple of types: any one of them), made once per kind."""
    return TypeAdapter(Union[kind] if isinstance(kind, tuple) else kind, config=_STRICT)  # noqa: UP007


class Fields:
    """Typed access to one mapping of a config file, with errors that say where.

    Each value is checked by pydantic in strict mode (an int is a float, nothing else converts); a problem is
    one ConfigError naming the key path and what it takes.
    """

    def __init__(self, data: Mapping[str, Any], where: str) -> None:
        if not isinstance(data, Mapping):
            raise ConfigError(f"{where}: expected a mapping, got {type(data).__name__}")
        self.data = data
        self.where = where

    def get(self, key: str, kind: type | tuple[type, ...], default: Any = ...) -> Any:
        if key not in self.data:
            if default is ...:
                raise ConfigError(
                    f"{self.where}: missing key {key!r}; present: {', '.join(map(str, self.data)) or '(none)'}"
                )
            return default
        value = self.data[key]
        try:
            out = _adapter(kind).validate_python(value)
        except ValidationError:
            name = kind.__name__ if isinstance(kind, type) else "/".join(k.__name__ for k in kind)
            raise ConfigError(f"{self.where}.{key}: expected {name}, got {value!r}") from None
        if isinstance(out, float) and not math.isfinite(out):
            raise ConfigError(f"{self.where}.{key}: expected a finite number, got {value!r}")
        return out

    def number(self, key: str, lo: float, hi: float, default: Any = ..., *, above: bool = False) -> float:
        """A finite number in [lo, hi] (in (lo, hi] with `above`), else one ConfigError naming the key and range."""
        value = self.get(key, float, default)
        ok = (lo < value if above else lo <= value) and value <= hi
        if not ok:
            bracket = "(" if above else "["
            raise ConfigError(f"{self.where}.{key}: must be in {bracket}{lo:g}, {hi:g}], got {value!r}")
        return float(value)

    def allow(self, *keys: str) -> Fields:
        """Self if every key of the mapping is one of `keys`; else one ConfigError naming it and the valid keys."""
        for key in self.data:
            if key not in keys:
                shown = key if str(key).isprintable() else repr(key)
                raise ConfigError(f"{self.where}: unknown key {shown!r}; valid: {', '.join(keys)}")
        return self

    def vector(self, key: str, length: int | None = None, default: Any = ...) -> Any:
        # Any: a tuple of floats whose length is checked here; callers store fixed-length tuples.
        value = self.get(key, list, default)
        if value is default and default is not ...:
            return default
        try:
            out = tuple(_Vector.validate_python(value))
        except ValidationError:
            raise ConfigError(f"{self.where}.{key}: expected a list of numbers, got {value!r}") from None
        if length is not None and len(out) != length:
            raise ConfigError(f"{self.where}.{key}: expected {length} numbers, got {len(out)}")
        return out

    def sub(self, key: str) -> Fields:
        return Fields(self.get(key, dict), f"{self.where}.{key}")


def require(cond: bool, message: str) -> None:
    if not cond:
        raise ConfigError(message)
