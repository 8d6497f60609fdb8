"""One-hot baseline: each known action text is its own axis, so no two actions share anything."""

from __future__ import annotations

import threading
from collections.abc import Sequence

import numpy as np

from scone_bt.embedding.base import Embedder
from scone_bt.errors import SconeError, UnknownNameError

__all__ = ["OneHotEmbedder"]


class OneHotEmbedder(Embedder):
    """One axis per text, over a vocabulary given at construction or grown on first sight.

    - `vocabulary` given and `capacity` None: closed vocabulary, `dim = len(vocabulary)`; an unknown text raises
      UnknownNameError naming the known ones.
    - otherwise: the vocabulary grows, each new text taking the next free axis, up to `capacity` axes (`dim`
      is `capacity` from the start, so estimators see a fixed length). Axis order is first-seen order within
      this process, so these vectors are never written to the on-disk cache; κ̂ rebuilt from the experience
      store re-embeds the stored action texts with the same embedder object, which keeps it consistent.

    Args:
        vocabulary: Known texts (axis i is vocabulary[i]).
        capacity: Maximum number of texts when growing; None with a vocabulary means closed.
    """

    def __init__(self, vocabulary: Sequence[str] | None = None, capacity: int | None = None) -> None:
        vocab = list(dict.fromkeys(vocabulary or ()))
        if vocabulary is None and capacity is None:
            capacity = 512
        self.growable = capacity is not None
        dim = capacity if capacity is not None else len(vocab)
        if dim < max(1, len(vocab)):
            raise SconeError(f"one-hot capacity {dim} is smaller than the vocabulary ({len(vocab)} texts)")
        self._axis = {text: i for i, text in enumerate(vocab)}
        self._lock = threading.Lock()
        super().__init__("onehot", dim, "onehot", None)

    @property
    def vocabulary(self) -> tuple[str, ...]:
        """Known texts in axis order."""
        return tuple(self._axis)

    def _encode(self, texts: Sequence[str]) -> np.ndarray:
        out = np.zeros((len(texts), self.dim), dtype=np.float32)
        with self._lock:
            for row, text in enumerate(texts):
                axis = self._axis.get(text)
                if axis is None:
                    if not self.growable:
                        raise UnknownNameError("one-hot action text", text, self._axis)
                    if len(self._axis) >= self.dim:
                        raise SconeError(
                            f"one-hot vocabulary is full ({self.dim} texts); pass a larger capacity"
                        )
                    axis = self._axis[text] = len(self._axis)
                out[row, axis] = 1.0
        return out
