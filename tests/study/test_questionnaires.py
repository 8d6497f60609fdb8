import pytest

from scone_bt.errors import UnknownNameError
from scone_bt.study.questionnaires import (
    MDMT_PERFORMANCE,
    TPS_HRI_14,
    QuestionnaireError,
    get_questionnaire,
    validate_answers,
)


def test_published_shapes():
    assert len(MDMT_PERFORMANCE.items) == 8 and MDMT_PERFORMANCE.values == tuple(float(v) for v in range(8))
    assert {i.subscale for i in MDMT_PERFORMANCE.items} == {"reliable", "capable"}
    assert len(TPS_HRI_14.items) == 14 and TPS_HRI_14.values[0] == 0 and TPS_HRI_14.values[-1] == 100
    assert [i.key for i in TPS_HRI_14.items if i.reverse] == [
        "tps_have_errors",
        "tps_unresponsive",
        "tps_malfunction",
    ]


def test_tps_score_reverses_three_items():
    answers = {i.key: 80.0 for i in TPS_HRI_14.items}
    assert TPS_HRI_14.score(answers) == pytest.approx((11 * 80 + 3 * 20) / 14)
    for key in ("tps_have_errors", "tps_unresponsive", "tps_malfunction"):
        answers[key] = 20.0
    assert TPS_HRI_14.score(answers) == pytest.approx(80.0)
    assert (
        TPS_HRI_14.category("tps_malfunction", 20.0) == 8 and TPS_HRI_14.category("tps_reliable", 20.0) == 2
    )


def test_mdmt_score_ignores_does_not_fit():
    answers = {i.key: 6.0 for i in MDMT_PERFORMANCE.items}
    answers["mdmt_meticulous"] = None
    answers["mdmt_capable"] = 2.0
    assert MDMT_PERFORMANCE.score(answers) == pytest.approx((6 * 6 + 2) / 7)
    assert MDMT_PERFORMANCE.subscale_scores(answers) == {"capable": pytest.approx(14 / 3), "reliable": 6.0}


def test_validation_errors_name_the_scale():
    full = {i.key: 50.0 for i in TPS_HRI_14.items}
    with pytest.raises(QuestionnaireError, match="valid: 0, 10, 20"):
        validate_answers(TPS_HRI_14, {**full, "tps_reliable": 55.0})
    with pytest.raises(QuestionnaireError, match="needs an answer"):
        validate_answers(TPS_HRI_14, {**full, "tps_reliable": None})
    with pytest.raises(QuestionnaireError, match="unanswered"):
        validate_answers(TPS_HRI_14, {"tps_reliable": 50.0})
    with pytest.raises(UnknownNameError, match="valid: mdmt, tps_hri"):
        get_questionnaire("sus")
