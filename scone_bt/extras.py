"""The lab bench's optional installs: the robot cooks without them, and a command that needs one says which.

``pip install scone-bt`` is the robot (`scone-run`, the tree, the stages, the SQLite store). The extras add the
trust-study toolkit (``[study]``), the benchmarks (``[bench]``) and the fleet (``[fleet]``: Ray, PostgreSQL);
``make run`` and ``make test`` install all of them.
"""

from __future__ import annotations

import importlib.util

from scone_bt.errors import SconeError

__all__ = ["EXTRAS", "MissingExtraError", "missing", "require"]

EXTRAS: dict[str, tuple[str, ...]] = {
    "study": ("fastapi", "uvicorn", "pymc", "arviz", "pandas", "matplotlib"),
    "bench": ("matplotlib", "pandas", "unified_planning"),
    "fleet": ("ray", "psycopg"),
}
"""Extra → the modules it installs (pyproject.toml's ``[project.optional-dependencies]``)."""


class MissingExtraError(SconeError):
    """A command needs an extra that is not installed."""


def missing(extra: str, modules: tuple[str, ...] | None = None) -> list[str]:
    """The extra's modules (or the given ones of it) that cannot be imported here."""
    return [m for m in (modules or EXTRAS[extra]) if importlib.util.find_spec(m) is None]


def require(extra: str, what: str, modules: tuple[str, ...] | None = None) -> None:
    """Raise MissingExtraError (one line, naming the install command) unless the extra's modules are here."""
    if extra not in EXTRAS:
        raise SconeError(f"unknown extra {extra!r}; valid: {', '.join(EXTRAS)}")
    gone = missing(extra, modules)
    if gone:
        raise MissingExtraError(
            f"{what} needs the '{extra}' extra ({', '.join(gone)} not installed): pip install 'scone-bt[{extra}]'"
        )
