""" "mpnet-ft": the benchmark that owns the train states trains the head and registers the name with the registry."""

from __future__ import annotations

import json

import numpy as np
import pytest

from scone_bt.embedding import FinetuneOptions, available_embedders, load_embedder
from scone_bt.errors import RecipeError, UnknownNameError
from scone_bt.instruction_following.embedder import MPNET_FT, load_or_train_finetuned

ACTIONS = [f"Put {o} on table" for o in ("salt", "flour", "milk", "lemon", "rice", "honey", "tea", "butter")]
PAIRS = {
    "Start the bread": "Put honey on table",
    "Prepare the dessert": "Put rice on table",
    "Make the sauce": "Put tea on table",
}


def test_a_head_trained_from_a_states_file_is_cached(tmp_path):
    states = tmp_path / "train.jsonl"
    states.write_text(
        "".join(
            json.dumps({"instruction": i, "available": ACTIONS, "relevant": [a]}) + "\n"
            for i, a in PAIRS.items()
        )
    )
    opts = FinetuneOptions(epochs=3, hidden=16, dim=8, seed=0)
    first = load_or_train_finetuned(states, "glove", tmp_path / "cache", options=opts)
    cached = list((tmp_path / "cache" / "models").glob("finetuned-glove-*"))
    assert len(cached) == 1 and first.directory == cached[0].resolve() and first.dim == 8
    again = load_or_train_finetuned(states, "glove", tmp_path / "cache", options=opts)
    assert again.cache_key == first.cache_key  # loaded, not retrained (same weights)
    np.testing.assert_allclose(again.embed(ACTIONS), first.embed(ACTIONS), atol=1e-6)
    states.write_text("not json\n")
    with pytest.raises(RecipeError, match="train.jsonl:1"):
        load_or_train_finetuned(states, "glove", tmp_path / "cache", options=opts)


def test_importing_the_benchmark_registers_mpnet_ft(tmp_path):
    names = [info.name for info in available_embedders(tmp_path)]
    assert names.index(MPNET_FT) == names.index("onehot") + 1  # where the registry listed it before
    with pytest.raises(UnknownNameError, match="mpnet-ft"):
        load_embedder("no-such-embedder", tmp_path)
