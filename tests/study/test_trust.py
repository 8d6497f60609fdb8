import numpy as np
import pytest

from scone_bt.errors import SconeError
from scone_bt.events import ActOutcome, DecisionMade, HelpRequested
from scone_bt.gate.types import DecisionKind
from scone_bt.study import MDMT_PERFORMANCE, TPS_HRI_14, SimulatedParticipant, TrustParameters
from scone_bt.study.design import Condition, Group


def _outcome(success: bool) -> ActOutcome:
    return ActOutcome(1.0, "Put salt on table", "salt", success, None if success else "grasp")


def test_successes_raise_failures_lower_trust():
    p = SimulatedParticipant("S1", Group.A, seed=3)
    start = p.trust
    p.observe(_outcome(True))
    assert p.trust > start
    high = p.trust
    p.observe(_outcome(False))
    assert p.trust < high
    assert high - start < p.params.failure_loss * high  # failures weigh more than successes
    before = p.trust
    p.observe(HelpRequested(1.0, "Put salt on table", "salt"))
    assert p.trust > before
    p.observe(DecisionMade(1.0, 1, "Add salt.", None, 0.0, 0.0, DecisionKind.IDLE, ""))
    assert p.history[-1][0] == "help_request"


def test_low_trust_intervenes_more():
    p = SimulatedParticipant("S1", Group.A, seed=0)
    p.trust = 0.9
    high = p.takeover_probability()
    for _ in range(10):
        p.observe(_outcome(False))
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


@pytest.mark.parametrize("questionnaire", [MDMT_PERFORMANCE, TPS_HRI_14], ids=lambda q: q.name)
def test_static_answers_are_drawn_from_eq3_with_the_known_effect_on_the_logit_scale(questionnaire):
    """With static trust and no session noise the analysed categories follow Eq. (3) as documented.

    Eq. (3) written out independently of trust.py: P(category <= k) = sigmoid(c_k - phi), phi = disposition
    + condition_effect [on] + d_q, c = linspace(-3, 3, K - 1) (x 1.15 above 8 categories), reverse-scored items
    flipped back by Questionnaire.category. The observed category sums must match the model's expectation within
    4 sd per condition; a halved effect, an unflipped reverse item or extra noise would move them by far more.
    """
    from scone_bt.study.trust import item_offsets

    params = TrustParameters(
        success_gain=0.0, failure_loss=0.0, help_gain=0.0, condition_effect=1.0, response_noise_sd=0.0
    )
    k = questionnaire.n_categories
    cuts = np.linspace(-3.0, 3.0, k - 1) * (1.15 if k > 8 else 1.0)
    offsets = item_offsets(questionnaire, params.item_sd)
    cats = np.arange(k)
    effects = (1.0, 0.5)  # the truth, and half of it (what a halving contrast coding would estimate)
    observed = {Condition.OFF: 0.0, Condition.ON: 0.0}
    expected = {(c, e): 0.0 for c in observed for e in effects}
    variance = dict(expected)
    for i in range(300):
        p = SimulatedParticipant(f"P{i}", Group.A, params, seed=1000 + i)
        for session, condition in ((1, Condition.ON), (2, Condition.OFF)):
            p.start_session(session)
            answers = p.answer(questionnaire, condition, session)
            for item in questionnaire.items:
                observed[condition] += questionnaire.category(item.key, answers[item.key])
                for effect in effects:
                    phi = p.disposition + (effect if condition is Condition.ON else 0.0) + offsets[item.key]
                    cdf = np.append(1.0 / (1.0 + np.exp(-(cuts - phi))), 1.0)
                    prob = np.diff(np.concatenate([[0.0], cdf]))
                    mean = float(prob @ cats)
                    expected[condition, effect] += mean
                    variance[condition, effect] += float(prob @ cats**2) - mean**2

    def z(condition: Condition, effect: float) -> float:
        key = (condition, effect)
        return (observed[condition] - expected[key]) / np.sqrt(variance[key])

    assert abs(z(Condition.OFF, 1.0)) < 4.0 and abs(z(Condition.ON, 1.0)) < 4.0, expected
    assert z(Condition.ON, 0.5) > 8.0  # the test can tell the truth from half of it
