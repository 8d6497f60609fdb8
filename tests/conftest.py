"""Shared fixtures: configs, a fresh PyBullet kitchen in DIRECT mode, and the scripts in tools/ as modules."""

from __future__ import annotations

import importlib.util
import os
from collections.abc import Callable
from pathlib import Path
from types import ModuleType

import numpy as np
import pytest

os.environ.setdefault("HF_HUB_OFFLINE", "1")
os.environ.setdefault("TRANSFORMERS_OFFLINE", "1")
os.environ.setdefault("TOKENIZERS_PARALLELISM", "false")
# mujoco picks its OpenGL backend when first imported, and the tests' `pytest.importorskip("mujoco")` may import it
# before `world.mj_model.import_mujoco` sets this default: a test run alone then rendered through glfw (no display).
os.environ.setdefault("MUJOCO_GL", "egl")


@pytest.fixture(scope="session")
def kitchen_cfg():
    from scone_bt.config import load_kitchen

    return load_kitchen()


@pytest.fixture(scope="session")
def robot_cfg():
    from scone_bt.config import load_robot

    return load_robot()


@pytest.fixture
def kitchen(kitchen_cfg, robot_cfg):
    from scone_bt.world import Kitchen

    with Kitchen(kitchen_cfg, robot_cfg) as k:
        yield k


@pytest.fixture
def rng():
    return np.random.default_rng(0)


_TOOLS = Path(__file__).resolve().parents[1] / "tools"


@pytest.fixture(scope="session")
def tool() -> Callable[[str], ModuleType]:
    """Load a script of tools/ as a module by its stem ("motion_replay"); the scripts are not an installed package."""

    def load(name: str) -> ModuleType:
        spec = importlib.util.spec_from_file_location(name, _TOOLS / f"{name}.py")
        assert spec is not None and spec.loader is not None
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        return module

    return load
