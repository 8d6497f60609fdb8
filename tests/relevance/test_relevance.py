"""Relevance: ranking by cosine similarity, the learnt threshold, and instruction progress."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pytest

from scone_bt.embedding import Embedder, load_embedder
from scone_bt.errors import ConfigError, SconeError
from scone_bt.relevance import (
    InstructionStatus,
    RankedAction,
    RelevanceFilter,
    instruction_progress,
    rank_actions,
    relevance_matrix,
)


class TableEmbedder(Embedder):
    """Hand-made vectors, so expected similarities are known exactly."""

    VECTORS = {
        "season": [1.0, 0.0, 0.0],
        "salt": [0.8, 0.6, 0.0],
        "pepper": [0.6, 0.8, 0.0],
        "sugar": [0.0, 0.0, 1.0],
        "same-as-salt": [0.8, 0.6, 0.0],
    }

    def __init__(self) -> None:
        super().__init__("table", 3, "table", None)

    def _encode(self, texts: Sequence[str]) -> np.ndarray:
        return np.array([self.VECTORS[t] for t in texts], dtype=np.float32)


def test_rank_hand_made_case_best_first_with_stable_ties():
    ranked = rank_actions("season", ["sugar", "pepper", "salt", "same-as-salt"], TableEmbedder())
    assert [r.text for r in ranked] == ["salt", "same-as-salt", "pepper", "sugar"]
    assert [r.relevance for r in ranked] == pytest.approx([0.8, 0.8, 0.6, 0.0])
    assert rank_actions("season", [], TableEmbedder()) == []
    assert relevance_matrix(["season", "sugar"], ["salt", "sugar"], TableEmbedder()) == pytest.approx(
        np.array([[0.8, 0.0], [0.0, 1.0]])
    )


def test_rank_with_minilm_puts_the_named_ingredient_first(tmp_path):
    emb = load_embedder("minilm", tmp_path)
    actions = ["Put sugar on table", "Put milk on table", "Put salt on table", "Put olive oil on table"]
    assert rank_actions("Season the soup with salt", actions, emb)[0].text == "Put salt on table"
    assert rank_actions("Drizzle with olive oil", actions, emb)[0].text == "Put olive oil on table"


def test_fit_separable_scores_takes_the_middle_of_the_gap():
    f = RelevanceFilter.fit([0.1, 0.2, 0.5, 0.6], [False, False, True, True], embedder="minilm")
    assert f.threshold == pytest.approx(0.35)
    assert f.balanced_accuracy == 1.0 and f.embedder == "minilm"
    assert f.is_relevant(0.36) and not f.is_relevant(0.34)


def test_fit_overlapping_scores_maximises_balanced_accuracy():
    scores = [0.1, 0.2, 0.3, 0.45, 0.5, 0.6, 0.7, 0.8]
    labels = [False, False, True, False, True, True, True, True]
    f = RelevanceFilter.fit(scores, labels)
    y = np.array(labels)

    def bacc(t: float) -> float:
        s = np.array(scores)
        return ((s[y] >= t).mean() + (s[~y] < t).mean()) / 2

    assert f.balanced_accuracy == pytest.approx(max(bacc(t) for t in np.linspace(0, 1, 1001)))
    predictions = [f.is_relevant(s) for s in scores]
    tpr = np.mean([p for p, y in zip(predictions, labels, strict=True) if y])
    tnr = np.mean([not p for p, y in zip(predictions, labels, strict=True) if not y])
    assert (tpr + tnr) / 2 == pytest.approx(f.balanced_accuracy)


def test_fit_needs_both_classes():
    with pytest.raises(SconeError, match="relevant and irrelevant"):
        RelevanceFilter.fit([0.1, 0.2], [True, True])
    with pytest.raises(SconeError, match="one label per score"):
        RelevanceFilter.fit([0.1, 0.2], [True])


def test_save_load_round_trip_and_bad_files(tmp_path):
    f = RelevanceFilter(0.42, "mpnet", 0.9)
    assert RelevanceFilter.load(f.save(tmp_path / "f.json")) == f
    (tmp_path / "bad.json").write_text("{not json")
    with pytest.raises(ConfigError, match="not JSON"):
        RelevanceFilter.load(tmp_path / "bad.json")
    (tmp_path / "other.json").write_text('{"threshold": 0.3}')
    with pytest.raises(ConfigError, match="not a relevance filter"):
        RelevanceFilter.load(tmp_path / "other.json")
    with pytest.raises(ConfigError, match="cannot read"):
        RelevanceFilter.load(tmp_path / "missing.json")
    with pytest.raises(SconeError, match=r"\[-1, 1\]"):
        RelevanceFilter(1.5)


def test_instruction_progress_irrelevant_pending_completed():
    f = RelevanceFilter(0.5)
    ranked = [RankedAction("salt", 0.8), RankedAction("pepper", 0.6), RankedAction("sugar", 0.1)]
    pending = instruction_progress(ranked, done=set(), relevance=f)
    assert pending.status == InstructionStatus.PENDING and pending.relevant == ("salt", "pepper")
    half = instruction_progress(ranked, done={"salt"}, relevance=f)
    assert half.status == InstructionStatus.PENDING and half.pending == ("pepper",)
    assert instruction_progress(ranked, {"salt", "pepper"}, f).status == InstructionStatus.COMPLETED
    assert instruction_progress(ranked, set(), RelevanceFilter(0.9)).status == InstructionStatus.IRRELEVANT
