"""Adapter for sentence-transformers models loaded from a local directory (MiniLM, MPNet, BGE, ...).

torch and sentence_transformers are imported here only, and only when a text is first missing from the embedding
cache: with a warm on-disk cache an episode never imports them (about 6 s of start-up on the 2-core machine).
A plain BERT with mean pooling (MiniLM) is not run in torch at all but in numpy (`bert_numpy`): the same vectors
within `bert_numpy.TOLERANCE`, a first answer on a new recipe without torch's start-up, and none of torch's
per-shape kernel caches in a process that runs all day. ``SCONE_BT_EMBED_RUNTIME=torch`` runs such a model in
torch instead.
"""

from __future__ import annotations

import hashlib
import json
import os
import threading
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from scone_bt.embedding.base import Embedder
from scone_bt.errors import ModelUnavailableError

__all__ = [
    "SentenceTransformerEmbedder",
    "encode_threads",
    "is_sentence_transformer_dir",
    "model_fingerprint",
    "numpy_runtime",
    "VECTOR_FORM",
]

_MODELS: dict[str, object] = {}  # loaded once per process, shared by every embedder of the same directory
_LOCK = threading.Lock()
VECTOR_FORM = "alone-v3"
"""Part of the cache key: how a vector's bits were made. Every text is encoded on its own (`_raw_encode`). A
text's vector must not depend on what it was encoded with: the ε-greedy draw hashes its bits, so the same seeded
run went another way depending on what an embedding cache had seen before. Padding to a longer neighbour left the
low bits ~1e-7 off (no suffix); then texts of the same token count were batched (``alone``, ``alone-v2``), which
gave a text its own bits only where OpenBLAS's sgemm gives a row the same bits whatever the number of rows (on the
earlier development machine from 4 rows up; on an AMD EPYC with the Haswell kernel, for no two row counts). None of
those is read. One text per forward pass costs about 2x on a batch of new texts (the cache keeps them)."""


def is_sentence_transformer_dir(path: Path) -> bool:
    """True if `path` looks like a saved sentence-transformers (or plain Hugging Face) model."""
    return path.is_dir() and ((path / "modules.json").is_file() or (path / "config.json").is_file())


def model_fingerprint(path: Path) -> str:
    """Short hash of a model directory's weight files (names, sizes, mtimes): changes when the weights do."""
    h = hashlib.sha1()
    for f in sorted(path.rglob("*")):
        if f.is_file() and f.suffix in {".safetensors", ".bin", ".json", ".npz", ".npy", ".txt"}:
            st = f.stat()
            h.update(f"{f.relative_to(path)}:{st.st_size}:{int(st.st_mtime)}".encode())
    return h.hexdigest()[:12]


def encode_threads() -> int:
    """Torch threads for a forward pass: $SCONE_BT_TORCH_THREADS, else half the cores (at least one).

    Half leaves room for the simulator and the tree; on a busy 2-core machine one thread encoded MiniLM ~5x faster
    than two (130-150 vs 26-32 texts/s), since the second thread mostly waits for a core.
    """
    from scone_bt.environment import torch_threads

    return torch_threads() or max(1, (os.cpu_count() or 2) // 2)


_PLAIN_MODULES = {
    "sentence_transformers.models.Transformer",
    "sentence_transformers.models.Pooling",
    "sentence_transformers.models.Normalize",
}


def declared_dim(path: Path) -> int | None:
    """The output length a saved model declares (its Pooling module), or None when only loading it tells (a
    Dense layer, an unusual layout, unreadable files)."""
    try:
        modules = json.loads((path / "modules.json").read_text())
        if {m["type"] for m in modules} - _PLAIN_MODULES:
            return None
        pooling = next(m for m in modules if m["type"].endswith(".Pooling"))
        config = json.loads((path / pooling["path"] / "config.json").read_text())
        return int(config["word_embedding_dimension"])
    except (OSError, ValueError, KeyError, TypeError, StopIteration):
        return None


def _load_model(path: Path) -> object:
    key = str(path.resolve())
    with _LOCK:
        if key not in _MODELS and numpy_runtime(path):
            from scone_bt.embedding.bert_numpy import NumpyBert

            _MODELS[key] = NumpyBert(path)
        if key not in _MODELS:
            # No hub traffic, ever: the workplace is offline and a run must not wait on a network timeout.
            os.environ.setdefault("HF_HUB_OFFLINE", "1")
            os.environ.setdefault("TRANSFORMERS_OFFLINE", "1")
            os.environ.setdefault("HF_HUB_DISABLE_PROGRESS_BARS", "1")
            os.environ.setdefault("TOKENIZERS_PARALLELISM", "false")
            from sentence_transformers import SentenceTransformer
            from transformers.utils import logging as hf_logging

            hf_logging.set_verbosity_error()
            hf_logging.disable_progress_bar()
            try:
                _MODELS[key] = SentenceTransformer(key, device="cpu", local_files_only=True)
            except Exception as exc:  # the library raises many types for a broken directory
                raise ModelUnavailableError(
                    f"cannot load a sentence-transformers model from {path}: {type(exc).__name__}: {exc}"
                ) from None
        return _MODELS[key]


def numpy_runtime(path: Path) -> bool:
    """Whether the model in ``path`` runs in numpy (`bert_numpy.supports`, unless $SCONE_BT_EMBED_RUNTIME=torch)."""
    from scone_bt.embedding.bert_numpy import supports
    from scone_bt.environment import embed_runtime

    return embed_runtime() != "torch" and supports(path)


class SentenceTransformerEmbedder(Embedder):
    """A sentence-transformers model from a local directory; vectors are the model's pooled, normalised output.

    Args:
        name: Name reported to users and stored with outcomes.
        model_dir: Directory holding the saved model (modules.json, config.json, weights).
        cache_file: SQLite embedding cache, or None for memory only.
    """

    def __init__(self, name: str, model_dir: Path, cache_file: Path | None) -> None:
        model_dir = Path(model_dir)
        if not is_sentence_transformer_dir(model_dir):
            raise ModelUnavailableError(
                f"{model_dir} is not a sentence-transformers model directory (no modules.json or config.json)"
            )
        self.model_dir = model_dir
        self._model: Any = None  # a SentenceTransformer, imported only when first used
        dim = declared_dim(model_dir)
        if dim is None:  # the layout does not say: load now and measure
            dim = int(self._raw_encode(["probe"]).shape[1])
        key = f"{name}@{model_fingerprint(model_dir)}/{VECTOR_FORM}"
        super().__init__(name, dim, key, cache_file)

    @property
    def model(self) -> Any:
        """The loaded model (loaded on first use; a broken directory raises ModelUnavailableError then)."""
        if self._model is None:
            self._model = _load_model(self.model_dir)
        return self._model

    def _raw_encode(self, texts: Sequence[str]) -> np.ndarray:
        """Vectors of ``texts`` in input order, each encoded on its own (`VECTOR_FORM`)."""
        from scone_bt.embedding.bert_numpy import NumpyBert

        model = self.model
        if (
            not texts
        ):  # the length comes from the model: `__init__` measures it when the directory does not say
            return np.zeros((0, getattr(self, "dim", 0)), dtype=np.float32)
        if isinstance(model, NumpyBert):
            from threadpoolctl import threadpool_limits

            # BLAS threads as torch's (`encode_threads`): on a busy 2-core machine two threads made a batch ~10x
            # slower than one (each waits for the other's core).
            with threadpool_limits(limits=encode_threads(), user_api="blas"):
                rows = [model.encode([text]) for text in texts]
        else:
            rows = [self._torch_encode([text]) for text in texts]
        return np.concatenate(rows).astype(np.float32, copy=False)

    def _torch_encode(self, texts: Sequence[str]) -> np.ndarray:
        import torch

        before = torch.get_num_threads()
        torch.set_num_threads(encode_threads())
        try:
            with torch.inference_mode():
                out = self.model.encode(
                    list(texts),
                    batch_size=1,  # one text per pass (`VECTOR_FORM`)
                    convert_to_numpy=True,
                    normalize_embeddings=True,
                    show_progress_bar=False,
                )
        finally:
            torch.set_num_threads(before)
        return np.asarray(out, dtype=np.float32)

    def _encode(self, texts: Sequence[str]) -> np.ndarray:
        out = self._raw_encode(texts)
        if out.shape[1] != self.dim:
            raise ModelUnavailableError(
                f"{self.model_dir} declares {self.dim}-d vectors but its model gives {out.shape[1]}-d"
            )
        return out
