"""A BERT sentence encoder in numpy: MiniLM's forward pass without torch, for a quick first answer.

Importing torch and sentence-transformers takes about 6 s on the 2-core machine, and an episode on a recipe whose
texts are not in the embedding cache paid it before its first decision. MiniLM is small (6 layers, 384 wide): the
same weights, read from the model's ``model.safetensors``, run in numpy in milliseconds per batch, and the Rust
`tokenizers` library (what sentence-transformers itself uses) splits the texts. The result is sentence-transformers'
own (mean pooling over the tokens, then unit length) to float32 rounding: `TOLERANCE`, tested against it.

Only a plain BERT model with mean pooling and normalisation qualifies (`supports`); any other model directory is
left to sentence-transformers.
"""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from pathlib import Path

import numpy as np

__all__ = ["NumpyBert", "TOLERANCE", "supports"]

TOLERANCE = 1e-5
"""Largest difference allowed (and tested: tests/embedding/test_bert_numpy.py) of any vector component from
sentence-transformers' unit vector of the same text."""

_MODULES = [
    "sentence_transformers.models.Transformer",
    "sentence_transformers.models.Pooling",
    "sentence_transformers.models.Normalize",
]
_DTYPES = {"F32": np.float32, "F16": np.float16, "I64": np.int64}


def _json(path: Path) -> dict | list | None:
    try:
        return json.loads(path.read_text())
    except (OSError, ValueError):
        return None


def supports(model_dir: Path) -> bool:
    """Whether ``model_dir`` is a sentence-transformers BERT (absolute positions, GELU) with mean pooling and
    normalisation, in safetensors with a fast tokenizer: the models `NumpyBert` computes exactly."""
    modules = _json(model_dir / "modules.json")
    config = _json(model_dir / "config.json")
    if not isinstance(modules, list) or not isinstance(config, dict):
        return False
    if [m.get("type") for m in modules if isinstance(m, dict)] != _MODULES:
        return False
    pooling_dir = next((m.get("path", "") for m in modules if m.get("type", "").endswith(".Pooling")), "")
    pooling = _json(model_dir / pooling_dir / "config.json")
    if not isinstance(pooling, dict) or not pooling.get("pooling_mode_mean_tokens"):
        return False
    if any(
        pooling.get(k) for k in pooling if k.startswith("pooling_mode_") and k != "pooling_mode_mean_tokens"
    ):
        return False
    return (
        config.get("model_type") == "bert"
        and config.get("hidden_act") == "gelu"
        and config.get("position_embedding_type", "absolute") == "absolute"
        and (model_dir / "model.safetensors").is_file()
        and (model_dir / "tokenizer.json").is_file()
    )


def _read_safetensors(path: Path) -> dict[str, np.ndarray]:
    """Every tensor of a safetensors file as a read-only view of the file mapped into memory: loading costs
    nothing up front, and of the 47 MB word-embedding table only the rows of the words met are ever read."""
    data = np.memmap(path, dtype=np.uint8, mode="r")
    n = int.from_bytes(data[:8].tobytes(), "little")
    header = json.loads(data[8 : 8 + n].tobytes())
    out = {}
    for name, info in header.items():
        if name == "__metadata__":
            continue
        dtype = np.dtype(_DTYPES[info["dtype"]])
        start, end = info["data_offsets"]
        view = data[8 + n + start : 8 + n + end].view(dtype).reshape(info["shape"])
        out[name] = view if dtype in (np.float32, np.int64) else view.astype(np.float32)
    return out


_ERFC_FIT = (
    -1.26551223,
    1.00002368,
    0.37409196,
    0.09678418,
    -0.18628806,
    0.27886807,
    -1.13520398,
    1.48851587,
    -0.82215223,
    0.17087277,
)
"""Numerical Recipes' Chebyshev fit of erfc (fractional error under 1.2e-7 everywhere)."""


def _erf(x: np.ndarray) -> np.ndarray:
    """erf of a float32 array to float32 precision (numpy has no erf; scipy takes half a second to import)."""
    z = np.abs(x).astype(np.float64)
    t = 1.0 / (1.0 + 0.5 * z)
    poly = np.zeros_like(t)
    for c in reversed(_ERFC_FIT[1:]):
        poly = (poly + c) * t
    erfc = t * np.exp(-z * z + _ERFC_FIT[0] + poly)
    return (np.sign(x) * (1.0 - erfc)).astype(np.float32)


def _layer_norm(x: np.ndarray, weight: np.ndarray, bias: np.ndarray, eps: float) -> np.ndarray:
    mean = x.mean(-1, keepdims=True)
    var = ((x - mean) ** 2).mean(-1, keepdims=True)
    return (x - mean) / np.sqrt(var + eps) * weight + bias


class NumpyBert:
    """A sentence-transformers BERT model (`supports`) evaluated in numpy.

    Args:
        model_dir: The model directory (config.json, model.safetensors, tokenizer.json).
        max_seq_length: Tokens kept per text (sentence_bert_config.json's, else 256), as sentence-transformers.
    """

    def __init__(self, model_dir: Path, max_seq_length: int | None = None) -> None:
        from tokenizers import Tokenizer

        config = _json(model_dir / "config.json")
        assert isinstance(config, dict)
        self.heads = int(config["num_attention_heads"])
        self.layers = int(config["num_hidden_layers"])
        self.eps = float(config.get("layer_norm_eps", 1e-12))
        if max_seq_length is None:
            sbert = _json(model_dir / "sentence_bert_config.json")
            max_seq_length = int(sbert.get("max_seq_length", 256)) if isinstance(sbert, dict) else 256
        max_seq_length = min(max_seq_length, int(config.get("max_position_embeddings", 512)))
        self.tokenizer = Tokenizer.from_file(str(model_dir / "tokenizer.json"))
        self.tokenizer.enable_truncation(max_seq_length)
        self.tokenizer.enable_padding(pad_id=int(config.get("pad_token_id", 0)))
        w = _read_safetensors(model_dir / "model.safetensors")
        prefix = "bert." if "bert.embeddings.word_embeddings.weight" in w else ""
        self.w = {k.removeprefix(prefix): v for k, v in w.items()}
        self.dim = int(self.w["embeddings.word_embeddings.weight"].shape[1])

    def encode(self, texts: Sequence[str]) -> np.ndarray:
        """(n, dim) unit vectors of ``texts``: BERT, mean pooling over the tokens, L2 normalisation."""
        if not texts:
            return np.zeros((0, self.dim), dtype=np.float32)
        batch = self.tokenizer.encode_batch(list(texts))
        ids = np.array([e.ids for e in batch], dtype=np.int64)
        types = np.array([e.type_ids for e in batch], dtype=np.int64)
        mask = np.array([e.attention_mask for e in batch], dtype=np.float32)
        w, n, length = self.w, ids.shape[0], ids.shape[1]
        x = (
            w["embeddings.word_embeddings.weight"][ids]
            + w["embeddings.position_embeddings.weight"][np.arange(length)][None]
            + w["embeddings.token_type_embeddings.weight"][types]
        )
        x = _layer_norm(x, w["embeddings.LayerNorm.weight"], w["embeddings.LayerNorm.bias"], self.eps)
        # Padding tokens get no attention: a large negative added to their scores before the softmax.
        blocked = ((1.0 - mask) * np.float32(-1e9))[:, None, None, :]
        head = self.dim // self.heads
        scale = np.float32(1.0 / math.sqrt(head))
        for i in range(self.layers):
            p = f"encoder.layer.{i}."

            def dense(h: np.ndarray, name: str, p: str = p) -> np.ndarray:
                # Weights are stored (out, in); BLAS reads the transpose in place. 2-D: one GEMM per layer.
                flat = h.reshape(-1, h.shape[-1]) @ w[f"{p}{name}.weight"].T + w[f"{p}{name}.bias"]
                return flat.reshape(*h.shape[:-1], -1)

            def split(h: np.ndarray) -> np.ndarray:
                return h.reshape(n, length, self.heads, head).transpose(0, 2, 1, 3)

            q = split(dense(x, "attention.self.query"))
            k = split(dense(x, "attention.self.key"))
            v = split(dense(x, "attention.self.value"))
            scores = (q @ k.transpose(0, 1, 3, 2)) * scale + blocked
            scores = np.exp(scores - scores.max(-1, keepdims=True))
            attn = scores / scores.sum(-1, keepdims=True)
            ctx = (attn @ v).transpose(0, 2, 1, 3).reshape(n, length, self.dim)
            x = _layer_norm(
                dense(ctx, "attention.output.dense") + x,
                w[f"{p}attention.output.LayerNorm.weight"],
                w[f"{p}attention.output.LayerNorm.bias"],
                self.eps,
            )
            inner = dense(x, "intermediate.dense")
            inner = (
                inner * np.float32(0.5) * (np.float32(1.0) + _erf(inner * np.float32(1.0 / math.sqrt(2.0))))
            )
            x = _layer_norm(
                dense(inner, "output.dense") + x,
                w[f"{p}output.LayerNorm.weight"],
                w[f"{p}output.LayerNorm.bias"],
                self.eps,
            )
        pooled = (x * mask[..., None]).sum(1) / np.maximum(mask.sum(1, keepdims=True), 1e-9)
        norms = np.maximum(np.linalg.norm(pooled, axis=1, keepdims=True), 1e-12)
        return (pooled / norms).astype(np.float32)
