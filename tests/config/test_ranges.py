"""The heft test's intervals are declared once: the tree file, the gate's and the motion's options refuse alike."""

from __future__ import annotations

import math

import pytest
from pydantic import ValidationError

from scone_bt.config.ranges import Range
from scone_bt.config.tree_parameters import PROBE_RANGES, ProbeParameters
from scone_bt.errors import SconeError
from scone_bt.gate.probe import ProbeOptions
from scone_bt.motion.probe import ProbeSettings


def test_a_range_reads_its_ends_from_the_field_and_says_them() -> None:
    assert str(PROBE_RANGES["lift_m"]) == "[0.005, 0.05] (metres)"
    assert str(PROBE_RANGES["full_band_at"]) == "[0, 1)"
    assert 1.0 not in PROBE_RANGES["full_band_at"] and 0.0 in PROBE_RANGES["full_band_at"]
    assert 0.0 not in PROBE_RANGES["max_traction"] and math.nan not in Range(-1.0, 1.0)
    with pytest.raises(SconeError, match=r"^probe.hold_s must be a number, got True$"):
        PROBE_RANGES["hold_s"].check("probe.hold_s", True)


def _outside(r: Range) -> list[float]:
    step = max(1e-6, (r.high - r.low) * 1e-3)
    return [r.low if r.low_open else r.low - step, r.high if r.high_open else r.high + step]


def _inside(r: Range) -> list[float]:
    step = max(1e-6, (r.high - r.low) * 1e-3)
    return [r.low + step if r.low_open else r.low, r.high - step if r.high_open else r.high]


@pytest.mark.parametrize("name", sorted(PROBE_RANGES))
def test_every_holder_of_a_probe_setting_takes_and_refuses_the_same_values(name: str) -> None:
    allowed = PROBE_RANGES[name]
    holders = [ProbeOptions]
    if name in ProbeSettings.__dataclass_fields__:
        holders.append(ProbeSettings)  # type: ignore[arg-type]
    in_tree = name in ProbeParameters.model_fields
    for value in _inside(allowed):
        sure = {"sure_traction": value} if name == "max_traction" else {}  # sure_traction ≤ max_traction
        for holder in holders:
            holder(**{name: value}, **(sure if holder is ProbeOptions else {}))
        if in_tree:
            ProbeParameters(**{name: value})
    for value in _outside(allowed):
        for holder in holders:
            with pytest.raises(SconeError, match=rf"^probe.{name} must be in "):
                holder(**{name: value})
        if in_tree:
            with pytest.raises(ValidationError):
                ProbeParameters(**{name: value})
