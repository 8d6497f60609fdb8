"""The command lines' argparse pieces: a parser whose usage errors are one line, and one help formatter (each
option's default said once, where it means something)."""

from __future__ import annotations

import argparse
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import NoReturn

__all__ = [
    "DefaultsHelpFormatter",
    "OneLineArgumentParser",
    "path_arg",
    "refuse_unread",
    "store_arg",
    "subcommand_defaults",
]


def path_arg(text: str) -> Path:
    """A path option's value (``type=path_arg``): an empty one is refused, as Path('') is '.', the working folder,
    where an empty --out or --cache-dir wrote its files."""
    if not text.strip():
        raise argparse.ArgumentTypeError("an empty path; give a file or folder path")
    return Path(text)


def store_arg(text: str) -> str:
    """An experience store option's value (an SQLite file or a postgresql:// URL): an empty one is refused."""
    if not text.strip():
        raise argparse.ArgumentTypeError("an empty store; give an SQLite file or a postgresql:// URL")
    return text


def subcommand_defaults(
    register: Callable[[argparse._SubParsersAction], object], name: str, *required: str
) -> argparse.Namespace:
    """The namespace of subcommand ``name`` with nothing given (``required``: its required options' argv), from
    the ``register`` that adds it to a command: what `refuse_unread` compares with."""
    parser = argparse.ArgumentParser()
    register(parser.add_subparsers())
    return parser.parse_args([name, *required])


def refuse_unread(
    args: argparse.Namespace, defaults: argparse.Namespace, options: Mapping[str, str], why: str
) -> None:
    """One meaning per flag: refuse the first of ``options`` (dest → flag) that this run would not read, given
    with another value than its default (`defaults`: the command's namespace with nothing given), in one line:
    "FLAG: WHY". A default given explicitly is no other value."""
    from scone_bt.errors import SconeError

    for dest, flag in options.items():
        given, default = getattr(args, dest, None), getattr(defaults, dest, None)
        if isinstance(given, list | tuple) and isinstance(default, list | tuple):
            given, default = list(given), list(default)  # nargs: a list given, a tuple as the default
        if given != default:
            raise SconeError(f"{flag}: {why}")


class OneLineArgumentParser(argparse.ArgumentParser):
    """An ArgumentParser whose usage errors ("invalid int value", a missing required option) are one line, like
    every other bad input: argparse's own prints the whole usage block first (9 to 23 lines). Its subcommands'
    parsers are of this class too (argparse makes them of the parent's class).

    Parsing a command line also checks the environment variables the code reads (`environment.check_environment`):
    a bad one is the same one line, before the command does any work.
    """

    # Untyped: argparse's parse_args is overloaded, and this override keeps its signature.
    def parse_args(self, args=None, namespace=None):
        parsed = super().parse_args(args, namespace)
        from scone_bt.environment import check_environment
        from scone_bt.errors import SconeError

        try:
            check_environment()
        except SconeError as exc:
            self.exit(2, f"{self.prog}: {exc}\n")
        return parsed

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"{self.prog}: error: {message} (--help lists the options)\n")


class DefaultsHelpFormatter(argparse.HelpFormatter):
    """argparse's ArgumentDefaultsHelpFormatter without its noise: no "(default: None)" on a required option or on
    one whose default is "not given", no "(default: False)" on a switch, and nothing added where the help already
    says its default in words ("default: a temporary file")."""

    def _get_help_string(self, action: argparse.Action) -> str | None:
        text = action.help or ""
        if (
            "default" in text
            or action.required
            or not action.option_strings
            or action.default is None
            or action.default is False
            or action.default is argparse.SUPPRESS
        ):
            return text
        return f"{text} (default: %(default)s)"
