"""The fine-tuned embedder: learns labelled instruction→action pairs, saves and loads without pickle."""

from __future__ import annotations

import json

import numpy as np
import pytest

from scone_bt.embedding import (
    Embedder,
    FinetunedEmbedder,
    FinetuneOptions,
    InstructionExample,
    load_embedder,
    ranking_accuracy,
    train_finetuned,
)
from scone_bt.errors import ModelUnavailableError, SconeError

ACTIONS = [f"Put {o} on table" for o in ("salt", "flour", "milk", "lemon", "rice", "honey", "tea", "butter")]
# arbitrary pairings a general-purpose encoder cannot know: only training makes them rank first
PAIRS = {
    "Start the bread": "Put honey on table",
    "Prepare the dessert": "Put rice on table",
    "Make the sauce": "Put tea on table",
    "Bake the crust": "Put lemon on table",
    "Finish the salad": "Put milk on table",
    "Brew the drink": "Put salt on table",
}


def _examples() -> list[InstructionExample]:
    return [InstructionExample(i, (a,), tuple(ACTIONS)) for i, a in PAIRS.items()]


@pytest.fixture(scope="module")
def trained(tmp_path_factory):
    base = load_embedder("glove", tmp_path_factory.mktemp("cache"))
    out = tmp_path_factory.mktemp("ft") / "head"
    opts = FinetuneOptions(epochs=150, hidden=64, seed=0)
    return base, train_finetuned(_examples(), base, out, options=opts), out


def test_training_learns_the_pairs(trained):
    base, emb, _ = trained
    assert emb.dim == 128
    vectors = emb.embed(ACTIONS)
    np.testing.assert_allclose(np.linalg.norm(vectors, axis=1), 1.0, atol=1e-5)
    assert ranking_accuracy(_examples(), base) < 0.5
    assert ranking_accuracy(_examples(), emb) == 1.0
    history = emb.meta["history"]
    assert history[-1] < history[0]
    assert emb.meta["n_triplets_per_epoch"] == len(PAIRS) * 10


def test_save_load_round_trip_without_pickle(trained, tmp_path):
    _, emb, out = trained
    assert sorted(p.name for p in out.iterdir()) == ["finetuned.json", "head.safetensors"]
    assert json.loads((out / "finetuned.json").read_text())["base"] == "glove"
    loaded = load_embedder(f"finetuned:{out}", tmp_path)
    assert isinstance(loaded, FinetunedEmbedder)
    assert loaded.name == f"finetuned:{out.resolve()}"
    np.testing.assert_allclose(loaded.embed(ACTIONS), emb.embed(ACTIONS), atol=1e-6)
    also = load_embedder(str(out), tmp_path)  # the bare directory works too
    np.testing.assert_allclose(also.embed(ACTIONS[:1]), emb.embed(ACTIONS[:1]), atol=1e-6)


def test_training_is_seeded(trained):
    base, emb, _ = trained
    again = train_finetuned(_examples(), base, options=FinetuneOptions(epochs=150, hidden=64, seed=0))
    np.testing.assert_allclose(again.head.w2, emb.head.w2, atol=1e-6)


class _BatchSensitive(Embedder):
    """A backend whose low bits depend on the batch, like a transformer padding to the batch's longest text."""

    def __init__(self) -> None:
        super().__init__("batchy", 16, "batchy@1", None)

    def _encode(self, texts):
        rows = [np.random.default_rng(sum(t.encode())).normal(size=16) for t in texts]
        return np.array(rows) + 1e-6 * len(texts)


def test_training_repeats_exactly_whatever_the_cache_holds():
    opts = FinetuneOptions(epochs=20, hidden=16, dim=8, seed=0)
    fresh = train_finetuned(_examples(), _BatchSensitive(), options=opts)
    used = _BatchSensitive()
    for text in [*ACTIONS, *PAIRS]:  # the cache filled one text at a time: other low bits than one pass
        used.embed([text])
    assert not np.array_equal(used.embed(ACTIONS), _BatchSensitive().embed(ACTIONS))
    again = train_finetuned(_examples(), used, options=opts)
    for k in ("w1", "b1", "w2", "b2"):
        assert np.array_equal(getattr(again.head, k), getattr(fresh.head, k))


def test_embed_uncached_is_one_fresh_pass():
    emb = _BatchSensitive()
    emb.embed(["a"])
    fresh = emb.embed_uncached(["a", "b"])
    assert fresh.dtype == np.float32 and fresh.shape == (2, 16)
    np.testing.assert_allclose(np.linalg.norm(fresh, axis=1), 1.0, atol=1e-6)
    assert not np.array_equal(fresh[0], emb.embed(["a"])[0])  # the cache kept its own batch's bits
    assert emb.embed_uncached([]).shape == (0, 16)
    with pytest.raises(ValueError, match="distinct"):
        emb.embed_uncached(["a", "a"])


def test_tuple_examples_and_bad_inputs(trained, tmp_path):
    base, _, _ = trained
    tuples = [(i, [a], ACTIONS) for i, a in PAIRS.items()]
    emb = train_finetuned(tuples, base, options=FinetuneOptions(epochs=2, hidden=16, dim=8))
    assert emb.dim == 8
    with pytest.raises(SconeError, match="no training triplets"):
        train_finetuned([("Preheat the oven", [], ACTIONS)], base)
    with pytest.raises(SconeError, match="semantic base embedder"):
        train_finetuned(tuples, load_embedder("onehot"))
    with pytest.raises(SconeError, match="dropout"):
        FinetuneOptions(dropout=1.5)
    with pytest.raises(ModelUnavailableError, match="train_finetuned"):
        load_embedder(f"finetuned:{tmp_path}", tmp_path)


def test_a_damaged_fine_tuned_folder_is_one_line_naming_the_file_and_key(trained, tmp_path):
    import shutil

    _, _, out = trained
    meta = json.loads((out / "finetuned.json").read_text())
    cases = {
        "no base": (
            "finetuned.json",
            json.dumps({k: v for k, v in meta.items() if k != "base"}),
            r"finetuned\.json: base: missing or not a name",
        ),
        "a list": ("finetuned.json", "[]", r"finetuned\.json: expected a JSON object, got list"),
        "not JSON": ("finetuned.json", "{", r"finetuned\.json: cannot read it"),
        "garbage head": ("head.safetensors", "not tensors", r"head\.safetensors: not a safetensors file"),
    }
    for case, (name, text, message) in cases.items():
        folder = tmp_path / case.replace(" ", "-")
        shutil.copytree(out, folder)
        (folder / name).write_text(text, encoding="utf-8")
        with pytest.raises(ModelUnavailableError, match=message) as info:
            load_embedder(f"finetuned:{folder}", tmp_path / "cache")
        assert "\n" not in str(info.value), case

    from safetensors.numpy import load_file, save_file

    folder = tmp_path / "wrong-shapes"
    shutil.copytree(out, folder)
    tensors = load_file(str(out / "head.safetensors"))
    save_file({**tensors, "b1": tensors["b1"][:3]}, str(folder / "head.safetensors"))
    with pytest.raises(ModelUnavailableError, match=r"tensor shapes do not make a head \(w1 \(64, "):
        load_embedder(f"finetuned:{folder}", tmp_path / "cache")
