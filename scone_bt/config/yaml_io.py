"""Reading YAML with errors that name the file and the problem in one line.

Two departures from PyYAML's safe loader, both for the person who edits the file: a key given twice in one mapping
is an error naming both lines (PyYAML keeps the last silently: a ``gate: paper`` added above an existing
``gate: budget`` did nothing), and ``1e-5`` is a number (YAML 1.2; PyYAML's YAML 1.1 reads a float without a dot
as the string "1e-5", which then failed as "not a valid number").
"""

from __future__ import annotations

import re
from functools import cache
from pathlib import Path
from typing import Any

import yaml

from scone_bt.config.schema import read_text
from scone_bt.errors import ConfigError
from scone_bt.resources import cache_switched_off, default_cache_dir

__all__ = ["read_yaml", "require", "safe_load", "yaml_syntax_error"]


_UNPARSED = object()
_LOADER_VERSION = "scone-loader 1"
"""Names the loader's rules in the parse cache's key: a parse kept under other rules is not reused."""
_FLOAT_WITHOUT_DOT = re.compile(r"^[-+]?[0-9][0-9_]*[eE][-+]?[0-9]+$")
"""1e-5, 18e-2, -3E4: floats in YAML 1.2, strings to PyYAML's YAML 1.1 resolver."""


def _strict(base: type) -> type:
    """``base`` (PyYAML's SafeLoader or its libyaml twin) refusing a repeated key and reading 1e-5 as a float."""

    class Loader(base):
        def __init__(self, stream: Any) -> None:
            super().__init__(stream)
            self._checked: set[int] = set()  # the mappings whose keys were checked, by node id

        def flatten_mapping(self, node: Any) -> None:
            # Checked once per mapping, before its merge keys (<<) are folded into it: a merged anchor's keys may
            # repeat its own, and PyYAML folds a mapping in place, perhaps before it is constructed.
            if id(node) not in self._checked:
                self._checked.add(id(node))
                first: dict[Any, int] = {}
                for key_node, _ in node.value:
                    if not isinstance(key_node, yaml.ScalarNode) or key_node.tag == "tag:yaml.org,2002:merge":
                        continue
                    key = self.construct_object(key_node)  # 1 and '1' differ; ~ and null do not
                    if key in first:
                        raise yaml.constructor.ConstructorError(
                            problem=f"the key {key!r} is given twice, first on line {first[key] + 1}",
                            problem_mark=key_node.start_mark,
                        )
                    first[key] = key_node.start_mark.line
            super().flatten_mapping(node)

    Loader.add_implicit_resolver("tag:yaml.org,2002:float", _FLOAT_WITHOUT_DOT, list("-+0123456789"))
    return Loader


@cache
def _loaders() -> tuple[type | None, type]:
    """(the libyaml loader, or None where PyYAML was built without it; the pure-Python loader)."""
    fast = getattr(yaml, "CSafeLoader", None)
    return (_strict(fast) if fast is not None else None), _strict(yaml.SafeLoader)


def safe_load(text: str) -> Any:
    """`yaml.safe_load` with this module's two rules (the module docstring); raises yaml.YAMLError."""
    return yaml.load(text, Loader=_loaders()[1])  # noqa: S506 - a safe loader


def _fast_parse(text: str) -> Any:
    """The document through libyaml's parser when present (7x faster: the grocery catalogue in 0.15 s instead of
    1.1 s), else _UNPARSED: the pure-Python parser then parses it, or words its one-line error.

    A document of `CACHED_MIN_CHARS` or more is also kept, parsed, on disk (`_parsed_path`): a fresh process reads
    the catalogue's family files back in a few milliseconds instead of a quarter of a second.
    """
    loader = _loaders()[0]
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
    key = f"{sys.version_info[:2]} {yaml.__version__} CSafeLoader {_LOADER_VERSION}\n{text}"
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


def yaml_syntax_error(path: Path | str, exc: yaml.YAMLError) -> str:
    """A YAML syntax error as one line naming the file and the line ("f.yaml: line 3 is not valid YAML (...)")."""
    mark = getattr(exc, "problem_mark", None)
    where = f" line {mark.line + 1}" if mark is not None else ""
    problem = getattr(exc, "problem", None) or (str(exc).splitlines() or ["syntax error"])[0]
    return f"{path}:{where} is not valid YAML ({problem})"


def read_yaml(path: Path) -> dict[str, Any]:
    """Parse a UTF-8 YAML mapping or raise ConfigError naming the file (and the line, for syntax errors)."""
    text = read_text(path)
    data = _fast_parse(text)
    try:
        if data is _UNPARSED:
            data = safe_load(text)
    except RecursionError:
        raise ConfigError(f"{path}: nested too deeply to be a configuration file") from None
    except yaml.YAMLError as exc:
        raise ConfigError(yaml_syntax_error(path, exc)) from None
    except (ValueError, TypeError, OverflowError) as exc:  # e.g. a date like 2020-13-45
        raise ConfigError(f"{path}: is not valid YAML ({exc})") from None
    if data is None:
        raise ConfigError(f"{path}: is empty; expected a mapping of keys to values")
    if not isinstance(data, dict):
        raise ConfigError(f"{path}: expected a mapping at the top level, got {type(data).__name__}")
    return data


def require(cond: bool, message: str) -> None:
    if not cond:
        raise ConfigError(message)
