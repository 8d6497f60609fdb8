"""MiniLM in numpy gives sentence-transformers' vectors (within `bert_numpy.TOLERANCE`) without importing torch."""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from scone_bt.embedding.bert_numpy import TOLERANCE, NumpyBert, supports
from scone_bt.embedding.registry import minilm_dir

ROOT = Path(__file__).resolve().parents[2]

TEXTS = [
    "Put salt on table",
    "Put extra virgin olive oil on table",
    "Bring a large pot of salted water to the boil.",
    "Cut onions into half-rings and let them sweat in the same pot.",
    "Älplermagronen: fry the bacon cubes; add 400g (15 oz) potatoes, then the macaroni!",
    "",
    "tomato " * 300,  # past max_seq_length: truncated as sentence-transformers truncates
]


def test_minilm_qualifies_and_a_model_with_another_head_does_not(tmp_path):
    assert supports(minilm_dir())
    (tmp_path / "modules.json").write_text(json.dumps([{"type": "sentence_transformers.models.Transformer"}]))
    (tmp_path / "config.json").write_text(json.dumps({"model_type": "bert", "hidden_act": "gelu"}))
    assert not supports(tmp_path)


def test_numpy_minilm_matches_sentence_transformers_within_the_tolerance():
    from sentence_transformers import SentenceTransformer

    ours = NumpyBert(minilm_dir()).encode(TEXTS)
    model = SentenceTransformer(str(minilm_dir()), device="cpu", local_files_only=True)
    theirs = model.encode(TEXTS, convert_to_numpy=True, normalize_embeddings=True, show_progress_bar=False)
    assert ours.shape == theirs.shape == (len(TEXTS), 384) and ours.dtype == np.float32
    assert np.allclose(np.linalg.norm(ours, axis=1), 1.0, atol=1e-6)
    assert float(np.abs(ours - theirs).max()) <= TOLERANCE
    # Batched alone or together, a text gets the same vector (padding is masked out).
    alone = NumpyBert(minilm_dir()).encode(TEXTS[:1])
    assert float(np.abs(alone[0] - ours[0]).max()) <= TOLERANCE


_SCRIPT = textwrap.dedent(
    """
    import json, sys
    from pathlib import Path
    from scone_bt.embedding import load_embedder

    emb = load_embedder("minilm", cache_dir=Path(sys.argv[1]))
    vec = emb.embed(["Drain the spaghetti", "Put salt on table"])
    print(json.dumps({"torch": "torch" in sys.modules, "st": "sentence_transformers" in sys.modules,
                      "shape": list(vec.shape)}))
    """
)


@pytest.mark.parametrize("runtime", ["", "torch"])
def test_a_cold_cache_embeds_minilm_without_torch_unless_asked(tmp_path, runtime):
    env = {**__import__("os").environ, "SCONE_BT_EMBED_RUNTIME": runtime}
    done = subprocess.run(
        [sys.executable, "-c", _SCRIPT, str(tmp_path)],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
        env=env,
    )
    assert done.returncode == 0, done.stderr[-3000:]
    out = json.loads(done.stdout.strip().splitlines()[-1])
    assert out["shape"] == [2, 384]
    assert out["torch"] == out["st"] == (runtime == "torch")


@pytest.mark.parametrize("runtime", ["", "torch"])
def test_a_vector_is_the_same_to_the_bit_whatever_it_was_batched_with(tmp_path, monkeypatch, runtime):
    """A seeded run must not depend on what an embedding cache saw before: the ε-greedy draw hashes the vector's
    bits. Padded batches left ~1e-7 in a third of the rows (31 of 64 action texts of tools/data/sc)."""
    from scone_bt.embedding import load_embedder

    monkeypatch.setenv("SCONE_BT_EMBED_RUNTIME", runtime)
    emb = load_embedder("minilm", cache_dir=tmp_path / runtime)
    texts = [t for t in TEXTS if t] + [
        "Put salt on table now",
        "Put garlic on table",
        "salt",
        "sugar",
        "flour",
        "",
    ]
    alone = np.stack([emb.embed_uncached([t])[0] for t in texts])
    together = emb.embed_uncached(texts)
    reversed_ = emb.embed_uncached(texts[::-1])[::-1]
    assert np.array_equal(alone, together) and np.array_equal(alone, reversed_)


def test_the_numpy_model_sees_one_text_per_forward_pass(tmp_path, monkeypatch):
    """Batches of equal token count gave a text its own bits only on some BLAS kernels (not on an AMD EPYC with
    OpenBLAS's Haswell kernel, where every row count differed): every text is encoded on its own."""
    from scone_bt.embedding import load_embedder
    from scone_bt.embedding.bert_numpy import NumpyBert

    monkeypatch.setenv("SCONE_BT_EMBED_RUNTIME", "")
    emb = load_embedder("minilm", cache_dir=tmp_path)
    seen: list[int] = []
    encode = NumpyBert.encode

    def counting(self, texts):
        seen.append(len(texts))
        return encode(self, texts)

    monkeypatch.setattr(NumpyBert, "encode", counting)
    emb.embed_uncached(["Put salt on table", "Put garlic on table", "salt", "Stir the sauce gently"])
    assert seen == [1, 1, 1, 1]
