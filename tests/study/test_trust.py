import numpy as np
import pytest

from scone_bt.errors import SconeError
from scone_bt.study import MDMT_PERFORMANCE, TPS_HRI_14, SimulatedParticipant, TrustParameters
from scone_bt.study.design import Condition, Group


def test_successes_raise_failures_lower_trust():
    p = SimulatedParticipant("S1", Group.A, seed=3)
    start = p.trust
    p.observe("outcome", {"success": True})
    assert p.trust > start
    high = p.trust
    p.observe("outcome", {"success": False})
    assert p.trust < high
    assert high - start < p.params.failure_loss * high  # failures weigh more than successes
    before = p.trust
    p.observe("help_request", {})
    assert p.trust > before
    p.observe("decision", {})
    assert p.history[-1][0] == "help_request"


def test_low_trust_intervenes_more():
    p = SimulatedParticipant("S1", Group.A, seed=0)
    p.trust = 0.9
    high = p.takeover_probability()
    for _ in range(10):
        p.observe("outcome", {"success": False})
    assert p.trust < 0.3
    assert p.takeover_probability() > 0.5 > 0.05 > high
    draws = sum(p.decides_to_take_over() for _ in range(400))
    assert draws > 200


def test_answers_follow_latent_trust():
    quiet = TrustParameters(response_noise_sd=0.0)
    low, high = (
        SimulatedParticipant("lo", Group.A, quiet, seed=1),
        SimulatedParticipant("hi", Group.A, quiet, seed=1),
    )
    low.trust, high.trust = 0.15, 0.9
    lo_scores = [MDMT_PERFORMANCE.score(low.answer(MDMT_PERFORMANCE, Condition.OFF, 1)) for _ in range(20)]
    hi_scores = [MDMT_PERFORMANCE.score(high.answer(MDMT_PERFORMANCE, Condition.OFF, 1)) for _ in range(20)]
    assert np.mean(hi_scores) > np.mean(lo_scores) + 2
    answers = high.answer(TPS_HRI_14, Condition.OFF, 1)
    assert set(answers) == {i.key for i in TPS_HRI_14.items} and set(answers.values()) <= set(
        TPS_HRI_14.values
    )
    assert answers["tps_malfunction"] < 50 < answers["tps_reliable"] or TPS_HRI_14.score(answers) > 60


def test_parameters_are_checked():
    with pytest.raises(SconeError, match="failure_loss must be in"):
        TrustParameters(failure_loss=1.5)
