"""The analysis recovers a known condition effect from simulated participants (Eq. 3), and Eq. (4) runs."""

from __future__ import annotations

import pytest

from scone_bt.errors import SconeError, UnknownNameError
from scone_bt.study.analysis import AnalysisOptions, analyze, decide, load_study, write_outputs
from scone_bt.study.simulate import SimulationOptions, simulate_study
from scone_bt.study.trust import TrustParameters

# A zero effect is accepted only when the whole 95 % HDI (about ±2 sd) lies inside the ROPE (±0.18): the contrast's
# posterior sd must be near 0.04, which takes about 160 participants × 2 sessions × 22 items. Short chains keep it quick.
PARTICIPANTS = 160
FAST_SAMPLER = AnalysisOptions(chains=2, tune=200, draws=250, cores=2, seed=1, models=("trust",))


def test_decision_rule():
    rope = (-0.18, 0.18)
    assert decide((-0.1, 0.1), rope) == "accept"
    assert decide((0.2, 1.4), rope) == "reject" and decide((-1.4, -0.19), rope) == "reject"
    assert decide((-0.1, 0.5), rope) == "undecided"
    with pytest.raises(SconeError, match="ROPE"):
        AnalysisOptions(rope=(0.2, -0.2))
    with pytest.raises(UnknownNameError, match="valid: interventions, mdmt, tps_hri, trust"):
        AnalysisOptions(models=("sus",))


@pytest.mark.slow
@pytest.mark.parametrize(("condition_effect", "session_effect"), [(0.0, 1.0), (1.0, 0.0)])
def test_recovers_known_condition_effect(condition_effect, session_effect, tmp_path):
    # Static trust: the episodes do not move trust, so the only difference between conditions is the known effect.
    trust = TrustParameters(
        success_gain=0.0,
        failure_loss=0.0,
        help_gain=0.0,
        condition_effect=condition_effect,
        session_effect=session_effect,
        response_noise_sd=0.0,
    )
    log = simulate_study(
        tmp_path / "sim.db",
        SimulationOptions(participants=PARTICIPANTS, fast=True, trust=trust, seed=3),
        printer=lambda _l: None,
    )
    data = load_study(log)
    result = analyze(data, FAST_SAMPLER)
    condition = result.contrast("trust", "b_C")
    assert condition.hdi[0] <= condition_effect <= condition.hdi[1], condition
    assert condition.decision == {0.0: "accept", 1.0: "reject"}[condition_effect], condition
    session = result.contrast("trust", "b_S")  # the crossed effect: its decision must be right too
    assert session.decision == {0.0: "accept", 1.0: "reject"}[session_effect], session
    fit = result.fits["trust"]
    assert fit.r_hat_max < 1.1 and fit.divergences == 0
    assert fit.n_observations == PARTICIPANTS * 2 * 22
    assert result.simulated and "SIMULATED DATA" in result.format()
    if condition_effect:
        paths = write_outputs(result, data, tmp_path / "out")
        assert paths["figure"].stat().st_size > 10_000
        on = data.sessions[data.sessions["condition"] == "on"]["mdmt"].mean()
        off = data.sessions[data.sessions["condition"] == "off"]["mdmt"].mean()
        assert on > off  # the original scores show the effect too
