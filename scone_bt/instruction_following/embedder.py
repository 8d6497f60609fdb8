""" "mpnet-ft", the paper's "MPNet ft": MPNet plus the triplet head trained on this benchmark's train states.

The head is trained on tools/data/if/train.jsonl (recipe instruction → the actions that serve it). It never sees an
execution outcome, so it leaks nothing into the self-confidence test rows. It is trained once (about a minute on one
CPU core once MPNet's vectors are cached) and cached under <cache dir>/models/finetuned-<base>-<key>, where the key
hashes the states file, the base and the training options.

The benchmark owns that data, so it is this module, not the embedder registry, that reads it: importing it
registers "mpnet-ft" with `scone_bt.embedding.register_embedder` (scone-run, scone-models and scone-bench import it).
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import asdict
from pathlib import Path

from scone_bt.embedding.base import Embedder
from scone_bt.embedding.cache import default_cache_dir
from scone_bt.embedding.finetuned import FinetunedEmbedder, FinetuneOptions, train_finetuned
from scone_bt.embedding.registry import load_embedder, load_finetuned, mpnet_dir, register_embedder
from scone_bt.errors import ModelUnavailableError
from scone_bt.instruction_following.cli import default_states_dir

__all__ = ["MPNET_FT", "load_or_train_finetuned", "mpnet_ft"]

MPNET_FT = "mpnet-ft"


def load_or_train_finetuned(
    states_file: Path,
    base: str = "mpnet",
    cache_dir: Path | None = None,
    *,
    options: FinetuneOptions | None = None,
    disk_cache: bool = True,
) -> FinetunedEmbedder:
    """The head trained on an instruction-following states file, from the cache or trained now and cached.

    Args:
        states_file: JSON lines with instruction, available and relevant (the IF benchmark's schema).
        base: Frozen encoder name ("mpnet", "minilm", "glove").
        cache_dir: Cache folder (default: scone_bt's); the head lands in models/finetuned-<base>-<key>.
        options: Training settings (FinetuneOptions()).
        disk_cache: Keep embeddings in the SQLite cache.

    Raises:
        RecipeError: the states file is missing or malformed.
    """
    from scone_bt.instruction_following.states import load_states

    opts = options or FinetuneOptions()
    states_file = Path(states_file)
    states = load_states(states_file)  # validates; one-line RecipeError naming the line
    key = hashlib.sha1(
        states_file.read_bytes() + base.encode() + json.dumps(asdict(opts), sort_keys=True).encode()
    ).hexdigest()[:12]
    root = Path(cache_dir if cache_dir is not None else default_cache_dir())
    target = root / "models" / f"finetuned-{base}-{key}"
    if (target / "finetuned.json").is_file():
        return load_finetuned(target, cache_dir, disk_cache)
    examples = [(s.instruction, tuple(sorted(s.relevant)), tuple(s.available)) for s in states]
    encoder = load_embedder(base, cache_dir)
    trained = train_finetuned(examples, encoder, None, options=opts, cache_dir=cache_dir)
    trained.meta["trained_on"] = states_file.name
    target.parent.mkdir(parents=True, exist_ok=True)
    tmp = target.parent / f".{target.name}.tmp"
    trained.save(tmp)
    tmp.replace(target)  # a half-written head never looks finished
    return load_finetuned(target, cache_dir, disk_cache)


def mpnet_ft(cache_dir: Path | None = None, disk_cache: bool = True) -> Embedder:
    """MPNet with the triplet head trained on the checkout's instruction-following train states."""
    if mpnet_dir(cache_dir) is None:
        raise ModelUnavailableError("mpnet-ft needs MPNet; run `scone-models install mpnet`")
    folder = default_states_dir()
    states = folder / "train.jsonl" if folder is not None else None
    if states is None or not states.is_file():
        raise ModelUnavailableError(
            "mpnet-ft trains on tools/data/if/train.jsonl of a checkout; train a head with "
            "scone_bt.embedding.train_finetuned and pass finetuned:<dir>"
        )
    return load_or_train_finetuned(states, "mpnet", cache_dir, disk_cache=disk_cache)


register_embedder(
    MPNET_FT,
    mpnet_ft,
    detail="MPNet + triplet head (128-d), trained on first use",
    available=lambda cache_dir: mpnet_dir(cache_dir) is not None,
)
