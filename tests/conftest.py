"""Shared fixtures: configs, and a fresh PyBullet kitchen in DIRECT mode."""

from __future__ import annotations

import os

import numpy as np
import pytest

os.environ.setdefault("HF_HUB_OFFLINE", "1")
os.environ.setdefault("TRANSFORMERS_OFFLINE", "1")
os.environ.setdefault("TOKENIZERS_PARALLELISM", "false")


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
