"""Similarity policies and the learnt stopping threshold, with hand-set scores."""

from __future__ import annotations

import numpy as np
import pytest

from scone_bt.instruction_following.metric import evaluate
from scone_bt.instruction_following.policies import SimilarityPolicy, fit_threshold, relative_scores
from scone_bt.instruction_following.states import IfState

SCORES = {
    "Put olive oil on table": 0.8,
    "Put vinegar on table": 0.6,
    "Put salt on table": 0.5,
    "Put sugar on table": 0.1,
    "Put flour on table": 0.0,
}


def _fixed(state: IfState) -> dict[str, float]:
    return {a: SCORES[a] for a in state.available}


def test_threshold_stops(salad_state) -> None:
    ep = evaluate(SimilarityPolicy(None, "p", threshold=0.55, score_fn=_fixed), [salad_state]).episodes[0]
    assert ep.picks == ("Put olive oil on table", "Put vinegar on table")
    assert ep.accuracy == 1.0
    lax = evaluate(SimilarityPolicy(None, "p", threshold=0.45, score_fn=_fixed), [salad_state])
    assert lax.accuracy == pytest.approx(2 / 3)


def test_relative_threshold_and_oracle(salad_state) -> None:
    rel = evaluate(
        SimilarityPolicy(None, "p", threshold=-0.25, relative=True, score_fn=_fixed), [salad_state]
    )
    assert rel.episodes[0].picks == ("Put olive oil on table", "Put vinegar on table")
    oracle = evaluate(SimilarityPolicy(None, "p", oracle_count=True, score_fn=_fixed), [salad_state])
    assert len(oracle.episodes[0].picks) == len(salad_state.relevant)


def test_fit_threshold_separates(salad_state) -> None:
    scores = [np.array([SCORES[a] for a in salad_state.available])]
    rho = fit_threshold(scores, [salad_state])
    assert 0.5 < rho <= 0.6
    assert relative_scores(scores)[0].max() == 0.0
    with pytest.raises(ValueError, match="valid: accuracy, f1"):
        fit_threshold(scores, [salad_state], objective="precision")  # type: ignore[arg-type]
