"""Start-up cost of the command lines (issue 29): building a parser imports none of the heavy stacks.

Each check runs in a fresh interpreter, since this test session has imported most of them already.
"""

from __future__ import annotations

import importlib
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
# scone-run's parser also keeps clear of the study toolkit: its --ui flags come from the light
# scone_bt.study.ui_args, and the study package loads its names lazily.
RUN_PARSER_FREE_OF = (
    *HEAVY,
    "scone_bt.study.ui",
    "scone_bt.study.trust",
    "scone_bt.study.log",
    "scone_bt.study.design",
    "scone_bt.study.questionnaires",
    "scone_bt.episode",
)

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
        ("scone_bt.cli.bench", "_parser", ["gate", "--episodes", "0"]),
    ],
)
def test_other_parsers_import_no_heavy_stack(module: str, function: str, argv: list[str]) -> None:
    # scipy too: scone-bench --help took 1.5 s while the SC report imported scipy.stats at module level.
    assert _loaded_after_parsing(module, function, argv, (*HEAVY, "scipy")) == []


def test_scone_run_and_the_study_ui_share_one_definition_of_the_ui_flags() -> None:
    from scone_bt.cli import run
    from scone_bt.study import ui, ui_args

    assert run.add_ui_arguments is ui_args.add_ui_arguments is ui.add_ui_arguments
    parser = run.build_parser()
    group = next(g for g in parser._action_groups if g.title and g.title.startswith("tablet UI"))
    assert [a.dest for a in group._group_actions] == ["ui", "ui_host", "ui_port", "ui_token"]


def test_the_study_package_still_exports_its_names() -> None:
    import scone_bt.study as study
    from scone_bt.study.trust import TrustParameters

    assert study.TrustParameters is TrustParameters
    assert sorted(study.__all__) == sorted(study._HOMES)
    for name in study.__all__:
        assert getattr(importlib.import_module(f"scone_bt.study.{study._HOMES[name]}"), name) is getattr(
            study, name
        )
    with pytest.raises(AttributeError, match="no attribute 'nope'"):
        _ = study.nope
