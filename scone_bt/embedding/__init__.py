"""ζ, the joint embedder: action texts and recipe instructions mapped to unit vectors in one space.

    emb = load_embedder("minilm")            # or "mpnet", "glove", "onehot", "finetuned:<dir>", a model dir
    vectors = emb.embed(["Put salt on table"])  # float32 (n, emb.dim), unit-norm rows

Every embedder caches vectors by model and text (memory + SQLite file in the cache dir), so a repeated action
text never costs a second forward pass.
"""

from scone_bt.embedding.base import Embedder, normalize_rows
from scone_bt.embedding.cache import EmbeddingCache, default_cache_dir
from scone_bt.embedding.finetuned import (
    FinetunedEmbedder,
    FinetuneOptions,
    InstructionExample,
    ranking_accuracy,
    train_finetuned,
)
from scone_bt.embedding.glove import GloveEmbedder
from scone_bt.embedding.onehot import OneHotEmbedder
from scone_bt.embedding.registry import (
    EMBEDDER_NAMES,
    EmbedderInfo,
    available_embedders,
    install_mpnet,
    load_embedder,
    minilm_dir,
    mpnet_dir,
)
from scone_bt.embedding.sentence import SentenceTransformerEmbedder

__all__ = [
    "EMBEDDER_NAMES",
    "Embedder",
    "EmbedderInfo",
    "EmbeddingCache",
    "FinetuneOptions",
    "FinetunedEmbedder",
    "GloveEmbedder",
    "InstructionExample",
    "OneHotEmbedder",
    "SentenceTransformerEmbedder",
    "available_embedders",
    "default_cache_dir",
    "install_mpnet",
    "load_embedder",
    "minilm_dir",
    "mpnet_dir",
    "normalize_rows",
    "ranking_accuracy",
    "train_finetuned",
]
