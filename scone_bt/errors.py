"""One exception hierarchy for everything a user can get wrong.

Every message is one line and, where there is a finite set of valid choices, names them.
"""

from __future__ import annotations

from collections.abc import Iterable

__all__ = [
    "SconeError",
    "ConfigError",
    "UnknownNameError",
    "RecipeError",
    "ExperienceStoreError",
    "ModelUnavailableError",
    "DistributedError",
]


class SconeError(Exception):
    """Base class: the CLI prints these as one line and exits with status 2."""


class ConfigError(SconeError):
    """A declarative file (robot, kitchen, tree) is missing or malformed."""


class UnknownNameError(SconeError, KeyError):
    """A name (object, robot, embedder, estimator, ...) that is not one of the valid ones."""

    def __init__(self, kind: str, name: str, valid: Iterable[str]) -> None:
        self.kind = kind
        self.name = name
        self.valid = sorted(valid)
        super().__init__(f"unknown {kind} {name!r}; valid: {', '.join(self.valid) or '(none)'}")

    def __str__(self) -> str:  # KeyError would otherwise quote the message
        return self.args[0]


class RecipeError(SconeError):
    """A recipe id, file or record that cannot be used."""


class ExperienceStoreError(SconeError):
    """An experience database that is corrupt, foreign or unwritable. It is never overwritten."""


class ModelUnavailableError(SconeError):
    """An embedding model that is not installed locally (no downloads happen at run time)."""


class DistributedError(SconeError):
    """A Ray cluster that cannot be reached, a bad --ray address, or a task that failed on every retry."""
