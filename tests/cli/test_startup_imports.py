"""Start-up cost of the command lines (issue 29): building a parser imports none of the heavy stacks.

Each check runs in a fresh interpreter, since this test session has imported most of them already.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]

# Stacks no parser may pull in: each costs from a tenth of a second (psycopg) to seconds (torch, PyMC, Ray).
HEAVY = (
    "ray",
    "pymc",
    "pytensor",
    "fastapi",
    "uvicorn",
    "starlette",
    "psycopg",
    "torch",
    "sentence_transformers",
    "transformers",
    "sklearn",
    "rerun",
    "pybullet",
)
# scone-run's parser also keeps clear of the study toolkit (the --ui flags are defined in scone_bt.cli.run).
RUN_PARSER_FREE_OF = (*HEAVY, "scone_bt.study", "scone_bt.study.ui", "scone_bt.episode")

_LOADED = textwrap.dedent(
    """
    import importlib, json, sys
    module, function, argv, watched = sys.argv[1], sys.argv[2], json.loads(sys.argv[3]), sys.argv[4:]
    parser = getattr(importlib.import_module(module), function)()
    parser.parse_args(argv)
    print(json.dumps(sorted(m for m in watched if m in sys.modules)))
    """
)


def _loaded_after_parsing(module: str, function: str, argv: list[str], watched: tuple[str, ...]) -> list[str]:
    done = subprocess.run(
        [sys.executable, "-c", _LOADED, module, function, json.dumps(argv), *watched],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert done.returncode == 0, done.stderr[-3000:]
    return json.loads(done.stdout.strip().splitlines()[-1])


def test_scone_run_parser_imports_no_heavy_stack() -> None:
    argv = ["--robot", "sim", "--headless", "--seed", "0", "--ui-port", "8765"]
    assert _loaded_after_parsing("scone_bt.cli.run", "build_parser", argv, RUN_PARSER_FREE_OF) == []


@pytest.mark.parametrize(
    ("module", "function", "argv"),
    [
        ("scone_bt.cli.models", "_parser", ["list"]),
        ("scone_bt.study.cli", "build_parser", ["simulate", "--db", "study.db"]),
    ],
)
def test_other_parsers_import_no_heavy_stack(module: str, function: str, argv: list[str]) -> None:
    assert _loaded_after_parsing(module, function, argv, HEAVY) == []


def _ui_options(parser: argparse.ArgumentParser) -> list[tuple[object, ...]]:
    group = next(g for g in parser._action_groups if g.title and g.title.startswith("tablet UI"))
    return [(a.option_strings, a.dest, a.default, a.type, a.help, a.nargs) for a in group._group_actions]


def test_scone_run_ui_flags_match_the_study_ui() -> None:
    from scone_bt.cli.run import build_parser
    from scone_bt.study.ui import add_ui_arguments

    reference = argparse.ArgumentParser()
    add_ui_arguments(reference)
    ours = _ui_options(build_parser())
    assert ours == _ui_options(reference)
    assert [o[1] for o in ours] == ["ui", "ui_host", "ui_port", "ui_token"]
