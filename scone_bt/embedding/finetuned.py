"""The paper's fine-tuned embedder: a frozen sentence encoder plus a small MLP head trained with a triplet loss.

Training (torch, imported inside `train_finetuned` only): anchor = instruction, positive = one of its relevant
actions, 10 random negatives = other available actions; loss = triplet margin on cosine distance; the head maps
the encoder's vector through Linear → ReLU → Dropout → Linear to 128-d, normalised. The same head embeds
instructions and actions, so both stay in one joint space.

Inference runs the head in NumPy (no torch), after the frozen encoder's cached vectors. Saved as
`head.safetensors` + `finetuned.json`; loading never unpickles anything.

"mpnet-ft" (the paper's "MPNet ft") is this head trained on MPNet with the instruction-following benchmark's train
states; that benchmark trains and registers it (`scone_bt.instruction_following.embedder`), so the product reads
no benchmark data.
"""

from __future__ import annotations

import hashlib
import json
import time
from collections.abc import Callable, Iterable, Sequence
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from scone_bt.embedding.base import Embedder, normalize_rows
from scone_bt.errors import ModelUnavailableError, SconeError

if TYPE_CHECKING:
    import torch

__all__ = [
    "FORMAT",
    "FinetuneOptions",
    "FinetunedEmbedder",
    "HEAD_FILES",
    "InstructionExample",
    "is_finetuned_dir",
    "ranking_accuracy",
    "train_finetuned",
]

FORMAT = "scone-bt-finetuned-embedder"
_VERSION = 1
_TENSORS = ("w1", "b1", "w2", "b2")
HEAD_FILES = ("finetuned.json", "head.safetensors")
"""The files a saved fine-tuned embedder is: its description, then its head's tensors."""


def is_finetuned_dir(path: Path) -> bool:
    """True if `path` holds a saved fine-tuned embedder (both `HEAD_FILES`)."""
    return all((Path(path) / name).is_file() for name in HEAD_FILES)


@dataclass(frozen=True)
class InstructionExample:
    """One labelled instruction.

    Attributes:
        instruction: Recipe instruction text ("Season with salt and pepper").
        relevant: Action texts that serve it ("Put salt on table", "Put pepper on table"); may be empty for an
            instruction the robot cannot help with (it then only contributes negatives' geometry, not triplets).
        available: Action texts the robot could take at that moment (relevant ones may be included); negatives
            are drawn from available minus relevant, or from every action in the data set when that is empty.
    """

    instruction: str
    relevant: tuple[str, ...]
    available: tuple[str, ...] = ()

    @classmethod
    def coerce(cls, item: InstructionExample | Sequence) -> InstructionExample:
        """Accept an InstructionExample or an (instruction, relevant, available) tuple."""
        if isinstance(item, InstructionExample):
            return item
        instruction, relevant, *rest = item
        available = rest[0] if rest else ()
        return cls(str(instruction), tuple(relevant), tuple(available))


@dataclass(frozen=True)
class FinetuneOptions:
    """Training settings (defaults follow the paper where it says, else chosen for a few-minute CPU run).

    Attributes:
        dim: Output length.
        hidden: Hidden layer width.
        dropout: Dropout probability after the hidden layer (training only).
        negatives: Random negative actions per (instruction, relevant action) pair, redrawn every epoch.
        margin: Triplet margin on cosine distance (1 - cos), in (0, 2).
        epochs: Passes over all triplets.
        batch_size: Triplets per step.
        learning_rate: Adam step size.
        weight_decay: Adam L2 penalty.
        seed: Seeds initialisation, negative sampling, dropout and batch order.
    """

    dim: int = 128
    hidden: int = 256
    dropout: float = 0.2
    negatives: int = 10
    margin: float = 0.4
    epochs: int = 30
    batch_size: int = 256
    learning_rate: float = 1e-3
    weight_decay: float = 1e-5
    seed: int = 0

    def __post_init__(self) -> None:
        if not 0.0 <= self.dropout < 1.0:
            raise SconeError(f"dropout must be in [0, 1), got {self.dropout}")
        if not 0.0 < self.margin < 2.0:
            raise SconeError(f"margin must be in (0, 2), got {self.margin}")
        for name in ("dim", "hidden", "negatives", "epochs", "batch_size"):
            if getattr(self, name) < 1:
                raise SconeError(f"{name} must be at least 1, got {getattr(self, name)}")


@dataclass(frozen=True)
class _Head:
    w1: np.ndarray  # (hidden, base_dim)
    b1: np.ndarray  # (hidden,)
    w2: np.ndarray  # (dim, hidden)
    b2: np.ndarray  # (dim,)

    def __call__(self, x: np.ndarray) -> np.ndarray:
        h = np.maximum(x @ self.w1.T + self.b1, 0.0)
        return normalize_rows(h @ self.w2.T + self.b2)


class FinetunedEmbedder(Embedder):
    """Frozen base embedder followed by a trained MLP head; `name` is "finetuned:<dir>" once saved.

    Args:
        base: The frozen encoder (its own cache serves repeated texts).
        head: Trained weights.
        meta: JSON-serialisable description (base spec, options, training history).
        directory: Where it was saved or loaded from, or None.
        cache_file: SQLite embedding cache, or None for memory only.
    """

    def __init__(
        self,
        base: Embedder,
        head: _Head,
        meta: dict,
        directory: Path | None = None,
        cache_file: Path | None = None,
    ) -> None:
        self.base = base
        self.head = head
        self.meta = meta
        self.directory = directory
        digest = hashlib.sha1(b"".join(np.ascontiguousarray(getattr(head, k)).tobytes() for k in _TENSORS))
        name = f"finetuned:{directory}" if directory is not None else "finetuned"
        key = f"finetuned[{base.cache_key}]@{digest.hexdigest()[:12]}"
        super().__init__(name, int(head.w2.shape[0]), key, cache_file)

    def _encode(self, texts: Sequence[str]) -> np.ndarray:
        return self.head(self.base.embed(texts))

    def save(self, directory: Path) -> Path:
        """Write head.safetensors and finetuned.json into `directory` (created); returns it."""
        from safetensors.numpy import save_file

        directory = Path(directory)
        directory.mkdir(parents=True, exist_ok=True)
        tensors = {k: np.ascontiguousarray(getattr(self.head, k), dtype=np.float32) for k in _TENSORS}
        meta_path, head_path = (directory / name for name in HEAD_FILES)
        save_file(tensors, str(head_path))
        meta_path.write_text(json.dumps(self.meta, indent=2) + "\n")
        self.directory = directory
        self.name = f"finetuned:{directory}"
        return directory

    @classmethod
    def load(
        cls, directory: Path, load_base: Callable[[str], Embedder], cache_file: Path | None = None
    ) -> FinetunedEmbedder:
        """Load a saved head and its base embedder (`load_base` of the name or path recorded at training).

        `load_embedder("finetuned:<dir>")` is the usual way in; it passes itself as `load_base`.
        """
        directory = Path(directory)
        meta_path, head_path = (directory / name for name in HEAD_FILES)
        if not is_finetuned_dir(directory):
            raise ModelUnavailableError(
                f"{directory} is not a fine-tuned embedder (needs finetuned.json and head.safetensors); "
                "train one with scone_bt.embedding.train_finetuned"
            )
        meta = _read_meta(meta_path)
        head = _read_head(head_path)
        base = load_base(meta["base"])
        if base.dim != head.w1.shape[1]:
            raise ModelUnavailableError(
                f"fine-tuned head in {directory} expects {head.w1.shape[1]}-d input but {meta['base']!r} is {base.dim}-d"
            )
        return cls(base, head, meta, directory.resolve(), cache_file)


def _read_meta(meta_path: Path) -> dict[str, Any]:
    """finetuned.json: a mapping of this format and version naming its base embedder, or ModelUnavailableError
    naming the file and the key."""
    try:
        meta = json.loads(meta_path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, ValueError) as exc:
        raise ModelUnavailableError(f"{meta_path}: cannot read it ({exc})") from None
    if not isinstance(meta, dict):
        raise ModelUnavailableError(f"{meta_path}: expected a JSON object, got {type(meta).__name__}")
    if meta.get("format") != FORMAT or meta.get("version") != _VERSION:
        raise ModelUnavailableError(
            f"{meta_path} is not a version-{_VERSION} {FORMAT} file "
            f"(format={meta.get('format')!r}, version={meta.get('version')!r})"
        )
    if not isinstance(meta.get("base"), str) or not meta["base"]:
        raise ModelUnavailableError(
            f"{meta_path}: base: missing or not a name; the base embedder's name or path (e.g. 'mpnet')"
        )
    return meta


def _read_head(head_path: Path) -> _Head:
    """head.safetensors: the head's tensors, or ModelUnavailableError naming the file and what is wrong."""
    from safetensors.numpy import load_file

    try:
        tensors = load_file(str(head_path))
    except Exception as exc:  # noqa: BLE001 - safetensors raises its own SafetensorError for a damaged file
        raise ModelUnavailableError(f"{head_path}: not a safetensors file ({exc})") from None
    missing = [k for k in _TENSORS if k not in tensors]
    if missing:
        raise ModelUnavailableError(
            f"{head_path}: missing tensors {', '.join(missing)}; needs {', '.join(_TENSORS)}"
        )
    w1, b1, w2, b2 = (np.asarray(tensors[k]) for k in _TENSORS)
    if not (
        w1.ndim == 2 and w2.ndim == 2 and b1.shape == (w1.shape[0],) and w2.shape[1] == w1.shape[0]
    ) or b2.shape != (w2.shape[0],):
        shapes = ", ".join(f"{k} {tuple(np.shape(tensors[k]))}" for k in _TENSORS)
        raise ModelUnavailableError(
            f"{head_path}: tensor shapes do not make a head ({shapes}); needs w1 (hidden, base dim), b1 (hidden,), "
            "w2 (dim, hidden), b2 (dim,)"
        )
    return _Head(w1, b1, w2, b2)


def ranking_accuracy(examples: Iterable[InstructionExample | Sequence], embedder: Embedder) -> float:
    """Fraction of examples with relevant actions whose most similar available action is a relevant one."""
    hits = total = 0
    for item in examples:
        ex = InstructionExample.coerce(item)
        candidates = list(dict.fromkeys((*ex.available, *ex.relevant)))
        if not ex.relevant or not candidates:
            continue
        scores = embedder.embed(candidates) @ embedder.embed_one(ex.instruction)
        hits += candidates[int(np.argmax(scores))] in ex.relevant
        total += 1
    return hits / total if total else float("nan")


@dataclass(frozen=True)
class _Triplets:
    """The texts training sees and its (instruction, positive, negatives) triplets.

    Attributes:
        instructions: Every instruction, sorted (their ids index it).
        actions: Every action, relevant or available, sorted (their ids index it).
        pairs: (instruction id, relevant action id, ids of the actions its negatives are drawn from).
    """

    instructions: list[str]
    actions: list[str]
    pairs: list[tuple[int, int, np.ndarray]]


@dataclass(frozen=True)
class _Fit:
    """A trained head and how its training went.

    Attributes:
        head: The trained weights.
        history: Mean triplet loss per epoch.
        triplets_per_epoch: Triplets in one epoch (pairs × negatives).
        seconds: Wall time of the training epochs, s.
    """

    head: _Head
    history: list[float]
    triplets_per_epoch: int
    seconds: float


def _triplets(data: list[InstructionExample]) -> _Triplets:
    """Every relevant action that has something to contrast with, as a triplet of ids.

    Raises:
        SconeError: No example has both a relevant action and a negative.
    """
    actions = sorted({a for ex in data for a in (*ex.relevant, *ex.available)})
    instructions = sorted({ex.instruction for ex in data})
    action_id = {a: i for i, a in enumerate(actions)}
    inst_id = {t: i for i, t in enumerate(instructions)}
    pairs: list[tuple[int, int, np.ndarray]] = []
    for ex in data:
        relevant = set(ex.relevant)
        pool = [a for a in dict.fromkeys(ex.available) if a not in relevant]
        if not pool:
            pool = [a for a in actions if a not in relevant]
        if not pool:
            continue
        pool_ids = np.array([action_id[a] for a in pool])
        pairs.extend((inst_id[ex.instruction], action_id[p], pool_ids) for p in dict.fromkeys(ex.relevant))
    if not pairs:
        raise SconeError(
            "no training triplets: give examples with relevant actions and other available actions"
        )
    return _Triplets(instructions, actions, pairs)


def _fit_head(encoder: Embedder, triplets: _Triplets, opts: FinetuneOptions) -> _Fit:
    """Train the MLP head on the triplets, seeded: initialisation, negatives, dropout and order repeat."""
    import torch

    pairs = triplets.pairs
    torch.manual_seed(opts.seed)
    rng = np.random.default_rng(opts.seed)
    # One fresh pass per list, not the cache: cached vectors carry the low bits of whatever batches filled the
    # cache, and those bits changed the trained head (mean cosine 0.92 between two heads trained on the same
    # texts, one from a fresh cache, one from a used one). Fresh passes make training repeat exactly.
    x_inst = torch.from_numpy(encoder.embed_uncached(triplets.instructions))
    x_act = torch.from_numpy(encoder.embed_uncached(triplets.actions))
    model = torch.nn.Sequential(
        torch.nn.Linear(encoder.dim, opts.hidden),
        torch.nn.ReLU(),
        torch.nn.Dropout(opts.dropout),
        torch.nn.Linear(opts.hidden, opts.dim),
    )
    loss_fn = torch.nn.TripletMarginWithDistanceLoss(
        distance_function=lambda a, b: 1.0 - torch.nn.functional.cosine_similarity(a, b), margin=opts.margin
    )
    optim = torch.optim.Adam(model.parameters(), lr=opts.learning_rate, weight_decay=opts.weight_decay)
    anchors = np.repeat([p[0] for p in pairs], opts.negatives)
    positives = np.repeat([p[1] for p in pairs], opts.negatives)
    history: list[float] = []
    start = time.perf_counter()
    threads = torch.get_num_threads()
    # a 2-layer head on a few thousand triplets gains nothing from threads, and on a loaded machine loses a lot
    torch.set_num_threads(1)
    try:
        _run_epochs(model, loss_fn, optim, x_inst, x_act, pairs, anchors, positives, opts, rng, history)
    finally:
        torch.set_num_threads(threads)
    model.eval()
    lin1: Any = model[0]  # nn.Linear layers (indexing a Sequential is typed as Module)
    lin2: Any = model[3]
    head = _Head(
        lin1.weight.detach().numpy().copy(),
        lin1.bias.detach().numpy().copy(),
        lin2.weight.detach().numpy().copy(),
        lin2.bias.detach().numpy().copy(),
    )
    return _Fit(head, history, len(anchors), time.perf_counter() - start)


def train_finetuned(
    examples: Iterable[InstructionExample | Sequence],
    base: Embedder,
    out_dir: Path | None = None,
    *,
    options: FinetuneOptions | None = None,
    cache_dir: Path | None = None,
) -> FinetunedEmbedder:
    """Train the paper's MLP head on labelled instructions and return the fine-tuned embedder.

    Args:
        examples: InstructionExample objects, or (instruction, relevant actions, available actions) tuples.
        base: Frozen encoder (e.g. `load_embedder("minilm")`).
        out_dir: If given, the result is saved there (load it later with load_embedder("finetuned:<out_dir>")).
        options: Training settings (FinetuneOptions()); seeded, and the base vectors are encoded afresh (not
            from the cache), so a run repeats exactly on one machine whatever the cache holds.
        cache_dir: Embedding cache directory of the result (default: the base's own cache file).

    Returns:
        The trained embedder (`meta["history"]` holds the mean loss per epoch).

    Raises:
        SconeError: no example has both a relevant action and a negative to contrast it with.
    """
    from scone_bt.embedding.cache import cache_file_for

    opts = options or FinetuneOptions()
    data = [InstructionExample.coerce(e) for e in examples]
    encoder = base
    base_spec = _base_spec(encoder)
    fit = _fit_head(encoder, _triplets(data), opts)
    meta = {
        "format": FORMAT,
        "version": _VERSION,
        "base": base_spec,
        "base_dim": encoder.dim,
        "options": asdict(opts),
        "n_examples": len(data),
        "n_triplets_per_epoch": fit.triplets_per_epoch,
        "train_seconds": round(fit.seconds, 3),
        "history": [round(h, 6) for h in fit.history],
    }
    cache_file = encoder.cache.path if cache_dir is None else cache_file_for(cache_dir)
    result = FinetunedEmbedder(encoder, fit.head, meta, None, cache_file)
    if out_dir is not None:
        result.save(Path(out_dir))
    return result


def _run_epochs(
    model: torch.nn.Module,
    loss_fn: torch.nn.Module,
    optim: torch.optim.Optimizer,
    x_inst: torch.Tensor,
    x_act: torch.Tensor,
    pairs: list[tuple[int, int, np.ndarray]],
    anchors: np.ndarray,
    positives: np.ndarray,
    opts: FinetuneOptions,
    rng: np.random.Generator,
    history: list[float],
) -> None:
    """Triplet training epochs (negatives redrawn each epoch); appends the mean loss of each to `history`."""
    model.train()
    for _ in range(opts.epochs):
        negatives = np.concatenate([rng.choice(p[2], size=opts.negatives, replace=True) for p in pairs])
        order = rng.permutation(len(anchors))
        total = 0.0
        for lo in range(0, len(order), opts.batch_size):
            idx = order[lo : lo + opts.batch_size]
            a = model(x_inst[anchors[idx]])
            p = model(x_act[positives[idx]])
            n = model(x_act[negatives[idx]])
            loss = loss_fn(a, p, n)
            optim.zero_grad()
            loss.backward()
            optim.step()
            total += float(loss.detach()) * len(idx)
        history.append(total / len(order))


def _base_spec(base: Embedder) -> str:
    """How to find `base` again at load time: its registry name, or its model directory."""
    model_dir = getattr(base, "model_dir", None)
    if base.name in {"minilm", "mpnet", "glove"} or model_dir is None:
        if base.name == "onehot":
            raise SconeError(
                "a fine-tuned head needs a semantic base embedder; valid: minilm, mpnet, glove, a dir"
            )
        return base.name
    return str(Path(model_dir).resolve())
