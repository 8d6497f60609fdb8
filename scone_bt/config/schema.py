"""Validating declarative files with pydantic: one model per file type, one line per error.

Every loader reads its file with `read_text` (strict UTF-8: a UTF-16 byte-order mark or random bytes is a one-line
error, not a UnicodeDecodeError), parses it, then checks the result with `validate(Model, data, where)`. pydantic's
ValidationError becomes ONE line naming the file, the key path and what is allowed, raised as the loader's own
`SconeError` subclass.
"""

from __future__ import annotations

import codecs
import os
import stat
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Annotated, Any, TypeVar

from pydantic import BaseModel, ConfigDict, Field, ValidationError

from scone_bt.errors import ConfigError, SconeError

__all__ = [
    "StrictModel",
    "FiniteFloat",
    "PositiveFloat",
    "NonNegativeFloat",
    "UnitFloat",
    "read_text",
    "read_bytes",
    "check_input_file",
    "file_kind",
    "validate",
    "format_validation_error",
    "ErrorWords",
    "MAX_FILE_BYTES",
    "MAX_DATA_FILE_BYTES",
]

MAX_FILE_BYTES = 16 * 1024 * 1024
"""YAML/JSON files larger than this (16 MiB) are refused before they are read (a recipe or robot file is a few kB,
the whole bundled catalogue under 100 kB)."""

MAX_DATA_FILE_BYTES = 256 * 1024 * 1024
"""Data files (the recipe corpus, dataset and ratings CSVs) larger than this (256 MiB) are refused before they are
read (the corpus of 1,227 recipes is 2.2 MB)."""

FiniteFloat = Annotated[float, Field(allow_inf_nan=False)]
PositiveFloat = Annotated[float, Field(gt=0, allow_inf_nan=False)]
NonNegativeFloat = Annotated[float, Field(ge=0, allow_inf_nan=False)]
UnitFloat = Annotated[float, Field(ge=0, le=1, allow_inf_nan=False)]

M = TypeVar("M", bound=BaseModel)

_BOMS = (
    (codecs.BOM_UTF32_LE, "UTF-32"),
    (codecs.BOM_UTF32_BE, "UTF-32"),
    (codecs.BOM_UTF16_LE, "UTF-16"),
    (codecs.BOM_UTF16_BE, "UTF-16"),
)


class StrictModel(BaseModel):
    """Base of the file models: unknown keys, wrong types (no "3" for 3, no true for 1) and NaN are rejected."""

    model_config = ConfigDict(extra="forbid", strict=True, frozen=True)


def _size(n: int) -> str:
    """Bytes as the unit a limit is stated in ("16 MiB")."""
    for unit, scale in (("GiB", 1 << 30), ("MiB", 1 << 20), ("KiB", 1 << 10)):
        if n >= scale and n % scale == 0:
            return f"{n // scale} {unit}"
    return f"{n} bytes"


def file_kind(mode: int) -> str:
    """What a path that is not a regular file is, in words ("a device", "a FIFO (named pipe)", ...)."""
    if stat.S_ISDIR(mode):
        return "a directory"
    if stat.S_ISCHR(mode) or stat.S_ISBLK(mode):
        return "a device"
    if stat.S_ISFIFO(mode):
        return "a FIFO (named pipe)"
    if stat.S_ISSOCK(mode):
        return "a socket"
    return "not a regular file"


def _check_stat(path: Path, st: os.stat_result, error: type[SconeError], limit: int) -> None:
    if not stat.S_ISREG(st.st_mode):
        raise error(f"{path}: is {file_kind(st.st_mode)}, not a regular file; give a file")
    if st.st_size > limit:
        raise error(
            f"{path}: {st.st_size:,} bytes is too large for this kind of file (at most {_size(limit)})"
        )


def check_input_file(
    path: Path | str, error: type[SconeError] = ConfigError, limit: int = MAX_DATA_FILE_BYTES
) -> Path:
    """`path` if it is an existing regular file of at most `limit` bytes (symlinks followed), else one-line `error`.

    For inputs that a library reads itself (e.g. Parquet); `read_bytes` does the same check and reads.
    """
    path = Path(path)
    try:
        st = os.stat(path)
    except FileNotFoundError:
        raise error(f"{path}: file not found") from None
    except OSError as exc:
        raise error(f"{path}: cannot read ({exc.strerror or exc})") from None
    _check_stat(path, st, error, limit)
    return path


def read_bytes(path: Path | str, error: type[SconeError] = ConfigError, limit: int = MAX_FILE_BYTES) -> bytes:
    """The bytes of a regular file of at most `limit` bytes; anything else is one-line `error`, raised unread.

    The one reader of user files: a device (`/dev/zero` never ends), a FIFO (blocks until a writer comes) or a
    file over `limit` is refused from its metadata, before a byte is read; a file that grows past `limit` while
    it is read is refused after `limit + 1` bytes, never held whole.
    """
    path = Path(path)
    check_input_file(path, error, limit)  # before open: opening a FIFO for reading would wait for a writer
    try:
        # O_NONBLOCK: a path swapped for a FIFO after the check above still cannot block the open
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    except FileNotFoundError:
        raise error(f"{path}: file not found") from None
    except OSError as exc:
        raise error(f"{path}: cannot read ({exc.strerror or exc})") from None
    try:
        _check_stat(path, os.fstat(fd), error, limit)  # what was opened, not what the name pointed to before
        chunks: list[bytes] = []
        total = 0
        while total <= limit:
            chunk = os.read(fd, min(1 << 20, limit + 1 - total))
            if not chunk:
                break
            chunks.append(chunk)
            total += len(chunk)
    except OSError as exc:
        raise error(f"{path}: cannot read ({exc.strerror or exc})") from None
    finally:
        os.close(fd)
    if total > limit:
        raise error(f"{path}: grew past {_size(limit)} while being read; at most {_size(limit)}")
    return b"".join(chunks)


def read_text(path: Path | str, error: type[SconeError] = ConfigError, limit: int = MAX_FILE_BYTES) -> str:
    """A file's text as strict UTF-8 (a UTF-8 byte-order mark is dropped); anything else is one-line `error`.

    The file is read by `read_bytes`: a device, FIFO or file over `limit` bytes is refused before it is read.
    """
    path = Path(path)
    data = read_bytes(path, error, limit)
    for bom, name in _BOMS:  # UTF-32-LE starts like UTF-16-LE: test the longer marks first
        if data.startswith(bom):
            raise error(f"{path}: is {name} text; save it as UTF-8")
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data[: exc.start].count(b"\n") + 1
        raise error(
            f"{path}: line {line} is not UTF-8 text (byte 0x{data[exc.start]:02x}); save it as UTF-8"
        ) from None
    if "\x00" in text:
        raise error(f"{path}: contains NUL characters; it is not a text file")
    return text.removeprefix("\ufeff")


def _loc(loc: tuple[Any, ...]) -> str:
    out = ""
    for part in loc:
        if isinstance(part, int):
            out += f"[{part}]"
        else:
            out += ("." if out else "") + str(part)
    return out


def _short(value: Any, limit: int = 60) -> str:
    text = repr(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def _model_at(model: type[BaseModel], loc: tuple[Any, ...]) -> type[BaseModel] | None:
    """The nested model that owns the last key of `loc` (for listing its valid keys)."""
    current: Any = model
    for part in loc[:-1]:
        if isinstance(part, int) or not (isinstance(current, type) and issubclass(current, BaseModel)):
            continue
        field = current.model_fields.get(str(part))
        if field is None:
            return None
        ann = field.annotation
        for candidate in (ann, *getattr(ann, "__args__", ())):
            for inner in (candidate, *getattr(candidate, "__args__", ())):
                if isinstance(inner, type) and issubclass(inner, BaseModel):
                    current = inner
                    break
    return current if isinstance(current, type) and issubclass(current, BaseModel) else None


ErrorWords = Callable[[Mapping[str, Any]], "str | None"]
"""A file type's own words for one pydantic error (a dict of ``ValidationError.errors()``): the line after
``where: ``, or None for the standard words."""

_UNKNOWN_KEY = ("extra_forbidden", "invalid_key")


_NOT_A_MAPPING = frozenset({"model_type", "model_attributes_type", "dict_type"})
"""pydantic's error types for a value where a mapping (a section of keys) belongs."""


def _standard_words(first: Mapping[str, Any], loc: tuple[Any, ...], model: type[BaseModel] | None) -> str:
    """`key.path: problem (got value)`, an unknown key with the valid ones, or a missing key."""
    kind = first.get("type", "")
    key = _loc(loc)
    if kind in _UNKNOWN_KEY:
        owner = _model_at(model, loc) if model is not None else None
        valid = ", ".join(owner.model_fields) if owner is not None else ""
        msg = f"unknown key {str(loc[-1])!r}" + (f"; valid: {valid}" if valid else "")
        key = _loc(loc[:-1])
    elif kind == "missing":
        msg = "missing (required)"
    elif kind in _NOT_A_MAPPING:  # pydantic's words name the model class ("instance of WorldSection")
        owner = _model_at(model, (*loc, "")) if model is not None else None
        msg = "must be a mapping of keys to values" + (f" ({', '.join(owner.model_fields)})" if owner else "")
        if "input" in first and not isinstance(first.get("input"), (dict, list)):
            msg += f" (got {_short(first.get('input'))})"
    else:
        msg = " ".join(str(first.get("msg", "invalid")).split()).removeprefix("Value error, ")
        value = first.get("input")
        if "input" in first and kind != "value_error" and not isinstance(value, (dict, list)):
            msg += f" (got {_short(value)})"
    return f"{key}: {msg}" if key and (loc or kind != "value_error") else msg


def format_validation_error(
    exc: ValidationError,
    where: str,
    model: type[BaseModel] | None = None,
    *,
    words: ErrorWords | None = None,
    unknown_key_first: bool = False,
    loc_filter: Callable[[tuple[Any, ...]], tuple[Any, ...]] | None = None,
) -> str:
    """The project's ONE line for a pydantic error: ``where: key.path: problem (got value)``, plus how many more.

    The one formatter of validation errors: a file type with words of its own passes ``words`` (e.g. the robot
    file's grasp section, a ratings CSV's row and column), never a formatter of its own.

    Args:
        exc: pydantic's error.
        where: The file (and section) the data came from.
        model: The model validated (lists the valid keys of an unknown one).
        words: The file type's own words for the problem reported (None: the standard words).
        unknown_key_first: Report an unknown key before other problems (a misspelt key explains a missing one).
        loc_filter: Rewrites a problem's key path (e.g. drops a union's discriminator tags).
    """
    errors = exc.errors(include_url=False)
    first: Mapping[str, Any] = errors[0]
    if unknown_key_first:
        first = next((e for e in errors if e.get("type") in _UNKNOWN_KEY), first)
    loc = tuple(first.get("loc", ()))
    if loc_filter is not None:
        loc = loc_filter(loc)
    text = words(first) if words is not None else None
    if text is None:
        text = _standard_words(first, loc, model)
    more = f" (and {len(errors) - 1} more problem{'s' if len(errors) > 2 else ''})" if len(errors) > 1 else ""
    return f"{where}: {text}{more}"


def validate(
    model: type[M],
    data: Any,
    where: str,
    error: type[SconeError] = ConfigError,
    context: Mapping | None = None,
) -> M:
    """`model` validated from `data`, or `error` with one line naming `where`, the key path and what is allowed."""
    try:
        return model.model_validate(data, context=dict(context) if context is not None else None)
    except ValidationError as exc:
        raise error(format_validation_error(exc, where, model)) from None
