"""tools/probe_band_sweep.py: a configuration that names only some of the probe's settings keeps the probe on."""

from __future__ import annotations

import pytest


@pytest.fixture(scope="module")
def sweep(tool):
    return tool("probe_band_sweep")


def test_only_an_explicit_null_below_turns_the_probe_off(sweep):
    from scone_bt.gate.probe import ProbeOptions

    probe, allowance, power = sweep.configuration({"sure_traction": 0.05})
    assert probe == ProbeOptions(sure_traction=0.05) and allowance == 1.0 and power == 4.0
    assert sweep.configuration({"below": None, "allowance": None}) == (None, None, 4.0)
    probe, _, power = sweep.configuration({"below": 0.5, "power": 2})
    assert probe == ProbeOptions(below=0.5) and power == 2.0
