"""The tree's decision settings as command-line options, derived from `TreeParameters` (their one declaration).

Each field of `scone_bt.config.tree_parameters.TreeParameters` becomes ``--<field-name>`` (underscores as
dashes) with its description as help text and its default shown as the tree default; a ``Literal`` is a choice, a
bool a ``--x/--no-x`` pair. An option left out is None, and the tree file's value applies
(`BehaviourOptions.resolve`). A setting added to the model is an option of every command that calls
`add_tree_options`, with nothing to map by hand.
"""

from __future__ import annotations

import argparse
import typing
from collections.abc import Callable
from typing import Any, cast

from scone_bt.errors import SconeError

__all__ = ["add_tree_options", "tree_overrides", "flag_of"]


def flag_of(name: str) -> str:
    """The command-line option of a tree parameter: ``--target-failure-rate`` for ``target_failure_rate``."""
    return "--" + name.replace("_", "-")


def add_tree_options(parser: argparse.ArgumentParser | argparse._ArgumentGroup) -> None:
    """Add one option per tree parameter (default None: the tree file's value)."""
    from scone_bt.config.tree_parameters import TreeParameters

    for name, field in TreeParameters.model_fields.items():
        kind = field.annotation
        default = "true" if field.default is True else "false" if field.default is False else field.default
        text = f"{field.description} (tree default: {default})"
        if kind is bool:
            parser.add_argument(flag_of(name), action=argparse.BooleanOptionalAction, default=None, help=text)
        elif typing.get_origin(kind) is typing.Literal:
            parser.add_argument(flag_of(name), choices=typing.get_args(kind), default=None, help=text)
        else:
            convert = cast(Callable[[str], Any], kind)  # float, int or str: each parses its own text
            metavar = "NUMBER" if kind is float else "N" if kind is int else "NAME"
            parser.add_argument(flag_of(name), type=convert, default=None, metavar=metavar, help=text)


def _bounds(name: str) -> str | None:
    """A numeric parameter's range as the user reads it ("[0, 1]", "(0, 1)"), or None."""
    from scone_bt.config.tree_parameters import TreeParameters

    lo = hi = None
    left, right = "[", "]"
    for item in TreeParameters.model_fields[name].metadata:
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
    bounds = _bounds(str(error["loc"][0])) if error.get("loc") else None
    return f"must be a number in {bounds}" if bounds is not None else None


def tree_overrides(args: argparse.Namespace) -> dict[str, Any]:
    """The tree parameters given on the command line, checked by the model: one line naming the option."""
    from pydantic import ValidationError

    from scone_bt.config.schema import format_validation_error
    from scone_bt.config.tree_parameters import PARAMETER_NAMES, TreeParameters

    given = {name: getattr(args, name) for name in PARAMETER_NAMES if getattr(args, name, None) is not None}
    try:
        TreeParameters.model_validate(given)
    except ValidationError as exc:
        name = str(exc.errors(include_url=False)[0]["loc"][0])
        raise SconeError(
            format_validation_error(exc, f"{flag_of(name)} {given[name]}", words=_words)
        ) from None
    return given
