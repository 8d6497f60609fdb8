"""The tablet UI's command-line flags (--ui, --ui-host, --ui-port, --ui-token): one definition for scone-run and
the study UI, in a module that imports nothing heavy, so building scone-run's parser never loads the study's
server or its trust model (docs/performance.md)."""

from __future__ import annotations

import argparse

__all__ = ["MIN_TOKEN_LENGTH", "add_ui_arguments"]

MIN_TOKEN_LENGTH = 8
"""Fewest characters of a session token (--ui-token)."""


def add_ui_arguments(parser: argparse.ArgumentParser) -> None:
    """The --ui flags of scone-run (argparse): --ui, --ui-host, --ui-port, --ui-token."""
    g = parser.add_argument_group("tablet UI (a person takes part; the episode runs in real time)")
    g.add_argument(
        "--ui", action="store_true", help="serve the tablet page and let a person help and take over"
    )
    g.add_argument(
        "--ui-host", default="127.0.0.1", help="address to bind; anything but localhost needs --ui-token"
    )
    g.add_argument("--ui-port", type=int, default=8765, help="port of the tablet page (0: any free port)")
    g.add_argument(
        "--ui-token", help=f"session token (at least {MIN_TOKEN_LENGTH} characters) the tablet must present"
    )
