"""`python -m scone_bt.motion.warm` (run by make after installing) plans in its own scene, so every kernel a plan
runs is compiled into numba's cache before the first episode, and a bad robot name is one line."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from scone_bt.motion.warm import main, warm_kernels

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize("robot", ["panda", "iiwa7"])
def test_the_warm_up_scene_gives_each_arm_a_plan(robot):
    planned, seconds = warm_kernels(robot)
    assert planned and seconds > 0.0


def test_an_unknown_robot_is_one_line_naming_the_valid_ones(capsys):
    assert main(["nosuch"]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "nosuch" in err and "panda" in err


def test_make_runs_it_after_installing():
    makefile = (ROOT / "Makefile").read_text()
    install = makefile[makefile.index("$(STAMP): pyproject.toml") : makefile.index("@touch $(STAMP)")]
    assert "-m scone_bt.motion.warm" in install.split("pip install", 1)[1]


def test_the_module_runs_as_a_command():
    done = subprocess.run(
        [sys.executable, "-m", "scone_bt.motion.warm"], cwd=ROOT, capture_output=True, text=True, timeout=600
    )
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.startswith("motion kernels compiled and cached for panda")
