"""The tree's decision settings as command-line options, derived from `TreeParameters` (their one declaration).

Each field of `scone_bt.config.tree_parameters.TreeParameters` becomes ``--<field-name>`` (underscores as
dashes) with its description as help text and its default shown as the tree default; a ``Literal`` is a choice, a
bool a ``--x/--no-x`` pair. A nested section (``probe:``, a model of its own) gives one option per field of it,
``--probe-below`` for ``probe.below``. An option left out is None, and the tree file's value applies
(`BehaviourOptions.resolve`; for a nested section, key by key). A setting added to the model is an option of every
command that calls `add_tree_options`, with nothing to map by hand.
"""

from __future__ import annotations

import argparse
import typing
from collections.abc import Callable
from typing import TYPE_CHECKING, Any, cast

from scone_bt.errors import SconeError

if TYPE_CHECKING:
    from pydantic.fields import FieldInfo

__all__ = [
    "add_tree_options",
    "check_flags_take_effect",
    "tree_overrides",
    "flag_of",
    "dest_of",
    "option_fields",
]

_BUDGET_ONLY = ("target_failure_rate", "exploration_credit", "probe")
"""Tree parameters only the budget gate reads (``probe``: every key of the section)."""
_PAPER_ONLY = ("confidence_threshold",)
"""Tree parameters only the paper's fixed-threshold gate reads."""


def flag_of(name: str | tuple[str, ...]) -> str:
    """The command-line option of a tree parameter: ``--target-failure-rate`` for ``target_failure_rate``,
    ``--probe-lift-m`` for ``("probe", "lift_m")`` (a field of a nested section)."""
    path = (name,) if isinstance(name, str) else name
    return "--" + "-".join(path).replace("_", "-")


def dest_of(path: tuple[str, ...]) -> str:
    """The option's attribute on the parsed arguments: ``probe_lift_m`` for ``("probe", "lift_m")``."""
    return "_".join(path)


def _is_section(kind: object) -> bool:
    from pydantic import BaseModel

    return isinstance(kind, type) and issubclass(kind, BaseModel)


def option_fields() -> tuple[tuple[tuple[str, ...], FieldInfo], ...]:
    """Every tree parameter that is an option, by its path in the tree file: a nested section's fields, each
    (``("probe", "below")``), in place of the section."""
    from scone_bt.config.tree_parameters import TreeParameters

    out: list[tuple[tuple[str, ...], FieldInfo]] = []
    for name, field in TreeParameters.model_fields.items():
        if _is_section(field.annotation):
            section: Any = field.annotation
            out.extend(((name, sub), f) for sub, f in section.model_fields.items())
        else:
            out.append(((name,), field))
    return tuple(out)


def add_tree_options(parser: argparse.ArgumentParser | argparse._ArgumentGroup) -> None:
    """Add one option per tree parameter (default None: the tree file's value)."""
    for path, field in option_fields():
        kind: Any = field.annotation
        default = "true" if field.default is True else "false" if field.default is False else field.default
        text = f"{field.description} (tree default: {default})"
        flag, dest = flag_of(path), dest_of(path)
        if kind is bool:
            parser.add_argument(
                flag, dest=dest, action=argparse.BooleanOptionalAction, default=None, help=text
            )
        elif typing.get_origin(kind) is typing.Literal:
            parser.add_argument(flag, dest=dest, choices=typing.get_args(kind), default=None, help=text)
        else:
            convert = cast(Callable[[str], Any], kind)  # float, int or str: each parses its own text
            metavar = "NUMBER" if kind is float else "N" if kind is int else "NAME"
            parser.add_argument(flag, dest=dest, type=convert, default=None, metavar=metavar, help=text)


def _field(path: tuple[str, ...]) -> FieldInfo | None:
    return dict(option_fields()).get(path)


def _bounds(path: tuple[str, ...]) -> str | None:
    """A numeric parameter's range as the user reads it ("[0, 1]", "(0, 1)"), or None."""
    field = _field(path)
    if field is None:
        return None
    lo = hi = None
    left, right = "[", "]"
    for item in field.metadata:
        for attr, side in (("ge", "["), ("gt", "(")):
            if getattr(item, attr, None) is not None:
                lo, left = getattr(item, attr), side
        for attr, side in (("le", "]"), ("lt", ")")):
            if getattr(item, attr, None) is not None:
                hi, right = getattr(item, attr), side
    if lo is None or hi is None:
        return None
    return f"{left}{lo:g}, {hi:g}{right}"


def _words(error: typing.Mapping[str, Any]) -> str | None:
    """A bad option in the words of the range it must be in (None: pydantic's own words)."""
    bounds = _bounds(tuple(str(k) for k in error["loc"])) if error.get("loc") else None
    return f"must be a number in {bounds}" if bounds is not None else None


def tree_overrides(args: argparse.Namespace) -> dict[str, Any]:
    """The tree parameters given on the command line, checked by the model: one line naming the option."""
    from pydantic import ValidationError

    from scone_bt.config.schema import format_validation_error
    from scone_bt.config.tree_parameters import TreeParameters

    given: dict[str, Any] = {}
    values: dict[tuple[str, ...], Any] = {}
    for path, _ in option_fields():
        value = getattr(args, dest_of(path), None)
        if value is None:
            continue
        values[path] = value
        if len(path) == 1:
            given[path[0]] = value
        else:  # a nested section's field: only the keys given (the rest stay the tree file's)
            given.setdefault(path[0], {})[path[1]] = value
    try:
        TreeParameters.model_validate(given)
    except ValidationError as exc:
        loc = tuple(str(k) for k in exc.errors(include_url=False)[0]["loc"])
        path = loc if loc in values else loc[:1]
        raise SconeError(
            format_validation_error(exc, f"{flag_of(path)} {values.get(path)}", words=_words)
        ) from None
    return given


def check_flags_take_effect(
    given: dict[str, Any], gate: str, self_confidence: bool, probe_enabled: bool
) -> None:
    """Refuse a decision option given on the command line that this run would not read (one meaning per flag):
    the budget gate's settings with ``gate`` paper, the paper's threshold with the budget gate, every gate
    setting without self-confidence (the robot always acts), and the probe's settings while it is off. A tree file
    holds values for both gates; the gate in use reads its own (docs/one_source.md).

    Args:
        given: `tree_overrides`' result (the options given, by tree-file key).
        gate: The gate this run uses (the option, else the tree file's).
        self_confidence: False with ``--no-self-confidence``.
        probe_enabled: Whether this run probes (``--probe-enabled``, else the tree file's ``probe.enabled``).

    Raises:
        SconeError: the first such option, naming what it needs.
    """

    def flag(path: tuple[str, ...], value: object) -> str:
        """The option as given: ``--no-probe-enabled`` for a switch turned off."""
        name = flag_of(path)
        return "--no-" + name.removeprefix("--") if value is False else name

    def flags(key: str) -> list[str]:
        value = given.get(key)
        if isinstance(value, dict):
            return [flag((key, sub), v) for sub, v in value.items()]
        return [flag((key,), value)]

    for key in given:
        if not self_confidence and key in (*_BUDGET_ONLY, *_PAPER_ONLY, "gate"):
            raise SconeError(
                f"{flags(key)[0]} has no effect with --no-self-confidence (the robot always acts, no gate decides)"
            )
        if gate == "paper" and key in _BUDGET_ONLY:
            raise SconeError(
                f"{flags(key)[0]} has no effect with the paper's gate (it sets the budget gate): "
                "give --gate budget, or leave it out"
            )
        if gate == "budget" and key in _PAPER_ONLY:
            raise SconeError(
                f"{flags(key)[0]} has no effect with the budget gate (it sets the paper's gate): "
                "give --gate paper, or leave it out"
            )
    settings = [flag_of(("probe", sub)) for sub in given.get("probe", {}) if sub != "enabled"]
    if settings and not probe_enabled:
        raise SconeError(
            f"{settings[0]} has no effect while the probe is off: give --probe-enabled too, or leave it out"
        )
