"""Environment variables: each checked in one place, a bad one is one line before any work, in every command."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from scone_bt.environment import VARIABLES, check_environment, folder_variable, switch_on, torch_threads
from scone_bt.errors import ConfigError

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.parametrize(
    ("name", "value", "says"),
    [
        ("SCONE_BT_TORCH_THREADS", "abc", "whole number from 1 to 1024"),
        ("SCONE_BT_TORCH_THREADS", "²", "whole number from 1 to 1024"),
        ("SCONE_BT_TORCH_THREADS", "99999999999", "whole number from 1 to 1024"),
        ("SCONE_BT_TORCH_THREADS", "0", "whole number from 1 to 1024"),
        ("SCONE_BT_EMBED_RUNTIME", "bogus", "numpy, torch"),
        ("SCONE_BT_RENDER_CACHE", "maybe", "0, false, no, off"),
        ("SCONE_BT_YAML_CACHE", "maybe", "1, true, yes, on"),
        ("SCONE_BT_SHARED", "{tmp}/nope", "no such folder"),
        ("SCONE_BT_DATA", "{tmp}/afile", "is a file, not a folder"),
        ("SCONE_BT_MPNET", "{tmp}/nope", "no such folder"),
        ("SCONE_BT_CACHE", "{tmp}/afile/cache", "is a file, so the folder cannot be made"),
    ],
)
def test_a_bad_value_is_one_line_naming_the_variable_and_what_it_accepts(tmp_path, name, value, says):
    (tmp_path / "afile").write_text("")
    value = value.format(tmp=tmp_path)
    with pytest.raises(ConfigError) as err:
        check_environment({name: value})
    message = str(err.value)
    assert message.startswith(f"{name}=") and says in message and "\n" not in message


def test_good_values_and_unset_ones_pass(tmp_path):
    check_environment({})
    check_environment(
        {
            "SCONE_BT_TORCH_THREADS": " 2 ",
            "SCONE_BT_EMBED_RUNTIME": "Torch",
            "SCONE_BT_RENDER_CACHE": "OFF",
            "SCONE_BT_YAML_CACHE": "",
            "SCONE_BT_SHARED": str(tmp_path),
            "SCONE_BT_CACHE": str(tmp_path / "not" / "yet"),  # made when first written
        }
    )
    assert torch_threads({"SCONE_BT_TORCH_THREADS": "3"}) == 3 and torch_threads({}) is None
    assert not switch_on("SCONE_BT_RENDER_CACHE", {"SCONE_BT_RENDER_CACHE": "no"})
    assert switch_on("SCONE_BT_RENDER_CACHE", {})
    assert folder_variable("SCONE_BT_SHARED", {}) is None


def test_every_variable_the_code_reads_is_listed():
    """A new SCONE_BT_ variable read anywhere must be listed (and checked) here."""
    import re

    read = set()
    for path in (ROOT / "scone_bt").rglob("*.py"):
        read |= set(re.findall(r"\bSCONE_BT_[A-Z_]+\b", path.read_text(encoding="utf-8")))
    assert read <= set(VARIABLES), sorted(read - set(VARIABLES))


@pytest.mark.parametrize(
    "command", ["scone_bt.cli.run", "scone_bt.cli.bench", "scone_bt.study.cli", "scone_bt.scenario.cli"]
)
def test_every_command_refuses_a_bad_variable_before_any_work(command):
    import os

    env = {**os.environ, "SCONE_BT_TORCH_THREADS": "abc"}
    args = {
        "scone_bt.cli.bench": ["catalogue"],
        "scone_bt.study.cli": ["power"],
        "scone_bt.scenario.cli": ["check", "scenarios"],
    }
    done = subprocess.run(
        [sys.executable, "-m", command, *args.get(command, [])],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=300,
        env=env,
    )
    assert done.returncode == 2, (done.stdout[-500:], done.stderr[-1500:])
    assert done.stderr.strip().count("\n") == 0 and "SCONE_BT_TORCH_THREADS='abc'" in done.stderr


def test_every_listed_variable_but_the_debug_switch_is_checked():
    from scone_bt.environment import _CHECKS

    assert set(_CHECKS) == set(VARIABLES) - {"SCONE_BT_DEBUG"}
