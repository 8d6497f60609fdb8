"""``--robot`` and ``--arm``, one meaning in every command: the backend, and the robot file.

``--robot`` names the backend an episode runs on (`scone_bt.robot.registry.BACKENDS`: ``sim`` is PyBullet); a
backend added to the registry is accepted by every command that uses these options, with no change here.
``--arm`` names the robot file (``robots/<name>.yaml`` or a YAML path). A robot file given to ``--robot`` is
refused in one line that says to use ``--arm``.
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path

from scone_bt.defaults import EPISODE
from scone_bt.errors import SconeError

__all__ = ["add_backend_option", "add_robot_options", "check_backend", "require_pybullet", "robot_file_names"]

DEFAULT_ARM = EPISODE.arm
"""The robot file every command uses when ``--arm`` is not given."""


def robot_file_names() -> list[str]:
    """The robot files ``--arm`` accepts by name (robots/*.yaml); empty where the folder cannot be found."""
    from scone_bt.resources import data_dir

    try:
        folder = data_dir("robots")
    except SconeError:
        return []
    return sorted({p.stem for p in folder.iterdir() if p.suffix in (".yaml", ".yml")})


def _backend_names() -> list[str]:
    from scone_bt.robot.registry import BACKENDS

    return sorted(BACKENDS)


def add_backend_option(
    parser: argparse.ArgumentParser | argparse._ArgumentGroup, arm_flag: str = "--arm"
) -> None:
    """Add ``--robot BACKEND`` alone (checked by `check_backend` when the command runs); ``arm_flag`` is the flag
    that names the robot file (``--arms`` where a benchmark takes several)."""
    from scone_bt.robot.registry import DEFAULT_BACKEND

    parser.add_argument(
        "--robot",
        default=DEFAULT_BACKEND,
        metavar="BACKEND",
        help=f"robot backend; valid: {', '.join(_backend_names())} (default: %(default)s); the robot file is {arm_flag}",
    )


def add_robot_options(
    parser: argparse.ArgumentParser | argparse._ArgumentGroup,
    arm_default: str = DEFAULT_ARM,
    arm_help: str | None = None,
) -> None:
    """Add ``--robot BACKEND`` and ``--arm FILE`` (checked by `check_backend` when the command runs)."""
    add_backend_option(parser)
    names = ", ".join(robot_file_names()) or "none found"
    parser.add_argument(
        "--arm",
        default=arm_default,
        metavar="FILE",
        help=arm_help or f"robot file: a name in robots/ ({names}) or a YAML path (default: %(default)s)",
    )


def _is_robot_file(name: str) -> bool:
    """Whether ``name`` reads as a robot file rather than a backend: a YAML path, a path, or a robots/ name."""
    if Path(name).suffix in (".yaml", ".yml") or os.sep in name or "/" in name:
        return True
    return name in robot_file_names()


def check_backend(name: str) -> str:
    """``--robot`` against the backend registry: the name, or one line naming the valid backends (and ``--arm``
    for a robot file)."""
    valid = _backend_names()
    if name in valid:
        return name
    if _is_robot_file(name):
        raise SconeError(
            f"--robot {name!r}: --robot names the robot backend ({', '.join(valid)}); "
            f"give the robot file with --arm {name}"
        )
    raise SconeError(
        f"--robot {name!r}: unknown robot backend; valid: {', '.join(valid)} (the robot file is --arm)"
    )


def require_pybullet(name: str, command: str) -> None:
    """Refuse a backend other than ``sim`` where a benchmark builds its PyBullet kitchen directly (not through
    the backend an episode runs on), rather than silently measuring PyBullet."""
    check_backend(name)
    if name != "sim":
        raise SconeError(
            f"{command} --robot {name}: this benchmark builds its PyBullet kitchen directly, not through a "
            "backend; only --robot sim is supported"
        )
