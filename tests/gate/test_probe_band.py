"""The probe band below τ narrows with a stricter promise (gate.probe.band_below)."""

from __future__ import annotations

import pytest

from scone_bt.errors import SconeError
from scone_bt.gate.probe import ProbeOptions, band_below, in_band


def test_the_band_below_is_full_from_full_band_at_and_narrows_under_it() -> None:
    options = ProbeOptions(below=1.0, above=0.45, full_band_at=0.15)
    assert band_below(options, 0.15) == 1.0 and band_below(options, 0.2) == 1.0
    assert band_below(options, 0.10) == pytest.approx((0.10 / 0.15) ** 4)
    assert band_below(options, 0.05) == pytest.approx((1 / 3) ** 4)
    assert band_below(options, None) == 1.0  # no budget: the full band
    assert band_below(ProbeOptions(below=1.0, full_band_at=0.0), 0.05) == 1.0  # 0: never narrows


def test_a_strict_promise_probes_only_what_kappa_is_nearly_sure_of() -> None:
    """τ = 0.85 at α = 0.05: κ̂ 0.6 is probed at the full band, asked about under the narrowed one."""
    options = ProbeOptions(below=1.0, above=0.45)
    assert in_band(0.6, 0.85, options)
    assert not in_band(0.6, 0.85, options, alpha=0.05)
    assert in_band(0.84, 0.85, options, alpha=0.05)  # within 0.012 of τ
    assert in_band(0.9, 0.85, options, alpha=0.05)  # above τ: the band above does not narrow


def test_full_band_at_is_validated() -> None:
    with pytest.raises(SconeError, match=r"probe.full_band_at must be in \[0, 1\), got 1.0"):
        ProbeOptions(full_band_at=1.0)
