"""The declarative files must travel inside the wheel and be found there."""

from __future__ import annotations

import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def wheel(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("wheel")
    subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "--no-deps", "--quiet", "-w", str(out), str(ROOT)],
        check=True,
        capture_output=True,
    )
    return next(out.glob("scone_bt-*.whl"))


def test_wheel_carries_declarative_files(wheel):
    names = zipfile.ZipFile(wheel).namelist()
    for required in (
        "scone_bt/_data/robots/panda.yaml",
        "scone_bt/_data/perception/kitchen.yaml",
        "scone_bt/_data/trees/assistive_cooking.yaml",
    ):
        assert required in names
    assert not any(n.startswith(("robots/", "perception/", "trees/")) for n in names), (
        "no top-level data packages"
    )


def test_installed_wheel_finds_its_files(wheel, tmp_path):
    target = tmp_path / "site"
    subprocess.run(
        [sys.executable, "-m", "pip", "install", "--no-deps", "--quiet", "--target", str(target), str(wheel)],
        check=True,
    )
    code = "from scone_bt.resources import data_dir; from scone_bt.config import load_kitchen; print(data_dir('robots')); print(len(load_kitchen().catalogue))"
    out = subprocess.run(
        [sys.executable, "-c", code],
        cwd=tmp_path,
        env={"PYTHONPATH": str(target)},
        capture_output=True,
        text=True,
        check=True,
    )
    robots_dir, n_objects = out.stdout.split()
    assert Path(robots_dir).is_relative_to(target) and int(n_objects) >= 21
