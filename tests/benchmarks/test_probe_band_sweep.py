"""tools/probe_band_sweep.py: a configuration that names only some of the probe's settings keeps the probe on."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest

TOOL = Path(__file__).resolve().parents[2] / "tools" / "probe_band_sweep.py"


@pytest.fixture(scope="module")
def sweep():
    spec = importlib.util.spec_from_file_location("probe_band_sweep", TOOL)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_only_an_explicit_null_below_turns_the_probe_off(sweep):
    from scone_bt.gate.probe import ProbeOptions

    probe, allowance, power = sweep.configuration({"sure_traction": 0.05})
    assert probe == ProbeOptions(sure_traction=0.05) and allowance == 1.0 and power == 4.0
    assert sweep.configuration({"below": None, "allowance": None}) == (None, None, 4.0)
    probe, _, power = sweep.configuration({"below": 0.5, "power": 2})
    assert probe == ProbeOptions(below=0.5) and power == 2.0
