"""A warm embedding cache never imports torch (issue 29): the model loads on the first text the cache misses.

Runs in a fresh interpreter, since this test session may have imported torch already.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]

_SCRIPT = textwrap.dedent(
    """
    import json, sys
    from pathlib import Path
    import numpy as np
    from scone_bt.embedding import load_embedder

    cache_dir = Path(sys.argv[1])
    texts = ["Put salt on table", "Bring a large pot of water to the boil"]
    warm = load_embedder("minilm", cache_dir=cache_dir)
    rng = np.random.default_rng(0)
    stored = rng.normal(size=(len(texts), warm.dim)).astype(np.float32)
    stored /= np.linalg.norm(stored, axis=1, keepdims=True)
    warm.cache.put(texts, stored)  # as an earlier run would have left it in embeddings.sqlite
    warm.cache.close()

    emb = load_embedder("minilm", cache_dir=cache_dir)  # a new run: reads the cache file
    hit = emb.embed(texts)
    after_hits = "torch" in sys.modules or "sentence_transformers" in sys.modules
    miss = emb.embed(["Drain the spaghetti"])
    print(json.dumps({
        "from_cache": bool(np.array_equal(hit, stored)),
        "torch_after_hits": after_hits,
        "torch_after_miss": "torch" in sys.modules,
        "miss_norm": float(np.linalg.norm(miss[0])),
    }))
    """
)


def test_a_warm_cache_embeds_without_torch_and_a_miss_loads_the_model(tmp_path) -> None:
    done = subprocess.run(
        [sys.executable, "-c", _SCRIPT, str(tmp_path)],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
        # MiniLM runs in numpy by default (never torch: tests/embedding/test_bert_numpy.py); torch's laziness here
        env={**os.environ, "SCONE_BT_EMBED_RUNTIME": "torch"},
    )
    assert done.returncode == 0, done.stderr[-3000:]
    out = json.loads(done.stdout.strip().splitlines()[-1])
    assert out["from_cache"], "the vectors did not come from the cache file"
    assert not out["torch_after_hits"], "embedding cached texts imported torch / sentence-transformers"
    # the first miss does load the model: the laziness defers the forward pass, it does not skip it
    assert out["torch_after_miss"] and abs(out["miss_norm"] - 1.0) < 1e-5
