"""``scone-bench soak``: many seeded episodes in one process, with the process's resources sampled after each.

A lab runs the robot for hours and a study runs dozens of sessions in one process: whatever an episode leaves
behind adds up. The soak runs ``--episodes`` corpus recipes back to back (one `ModelPool`, one experience store,
as a long-running robot would) and samples after every episode: resident memory, open file descriptors, OS
threads, the backend's bodies and constraints, the experience store's size, and the embedding cache's entries.

``rss_growth_mb_per_episode`` is the least-squares slope of resident memory over the episodes after a warm-up
(``--warmup``, 10 by default: the models and the first recipes' caches load there). ``fd_growth`` and
``thread_growth`` are the last episode's count less the count at the end of the warm-up.

``--record`` records every episode with rerun, as ``scone-run --save`` does, to a file deleted after the episode's
sample (its size is ``recording_bytes``): what the recorder keeps in the process after closing shows in the memory,
descriptors and threads sampled.

    scone-bench soak --episodes 200 --json docs/results/soak.json --plot docs/results/soak.png
"""

from __future__ import annotations

import argparse
import gc
import os
import tempfile
import threading
import time
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

from scone_bt.argparsing import path_arg
from scone_bt.benchmarks.progress import progress_bar
from scone_bt.process_stats import process_sample, slope
from scone_bt.reporting import emit_report

__all__ = ["EpisodeSample", "TARGETS", "corpus_recipes", "register", "run"]

TARGETS = {"rss_growth_mb_per_episode": 0.5, "fd_growth": 0, "thread_growth": 0}
"""Issue 51's targets over 200 episodes: memory (MB per episode after the warm-up), descriptors and threads flat."""


@dataclass(frozen=True)
class EpisodeSample:
    """The process after one episode of the soak.

    Attributes:
        episode: Its index (0 first).
        recipe: The recipe id.
        completed: Whether the recipe was done before the tick limit.
        wall_s: The episode's wall seconds.
        rss_mb: Resident memory of the process, MB (2**20 bytes).
        fds: Open file descriptors (/proc/self/fd).
        threads: OS threads of the process (/proc/self/status), the interpreter's and native ones (torch, BLAS).
        python_threads: Threads the interpreter knows (`threading.active_count`).
        bodies: Bodies in the backend's world at the episode's end (PyBullet's; 0 where it has none).
        constraints: Constraints in the backend's world at the episode's end.
        store_bytes: The experience store's file size, bytes (main file plus its WAL).
        outcomes: Outcomes in the experience store.
        embedding_cache_entries: Texts the shared embedder holds in memory.
        steps: Recipe steps done, "done/total".
        control_ticks: Control ticks the episode ran (its limit is ``--max-ticks``).
        recording_bytes: With ``--record``: the size of the episode's rerun recording (.rrd), bytes; else 0.
    """

    episode: int
    recipe: str
    completed: bool
    wall_s: float
    rss_mb: float
    fds: int
    threads: int
    python_threads: int
    bodies: int
    constraints: int
    store_bytes: int
    outcomes: int
    embedding_cache_entries: int
    steps: str = ""
    control_ticks: int = 0
    recording_bytes: int = 0


def corpus_recipes(count: int, seed: int, max_steps: int) -> list[str]:
    """``count`` corpus recipe ids drawn with ``seed`` (without replacement while the corpus lasts).

    Only recipes of at most ``max_steps`` steps that name something the kitchen stocks are drawn, so every
    episode asks the robot for something and the soak's wall time stays bounded.
    """
    import numpy as np

    from scone_bt.config import load_kitchen
    from scone_bt.defaults import EPISODE
    from scone_bt.errors import ConfigError
    from scone_bt.recipes.recipe import corpus_entries
    from scone_bt.stocking import stock_recipe

    catalogue = load_kitchen(EPISODE.kitchen).catalogue
    ids = []
    for entry in corpus_entries():
        try:
            recipe = entry.recipe()
        except Exception:  # a damaged corpus line is not the soak's to judge: it is left out
            continue
        if len(recipe.steps) <= max_steps and stock_recipe(recipe, catalogue).needed:
            ids.append(recipe.id)
    if not ids:
        raise ConfigError(
            f"--max-steps {max_steps}: no corpus recipe has this few steps and stocked products"
        )
    rng = np.random.default_rng(seed)
    out: list[str] = []
    while len(out) < count:
        out.extend(ids[i] for i in rng.permutation(len(ids)))
    return out[:count]


def _store_bytes(path: Path) -> int:
    return sum(p.stat().st_size for p in (path, Path(f"{path}-wal")) if p.exists())


def _plot(samples: list[EpisodeSample], warmup: int, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    x = [s.episode for s in samples]
    fig, axes = plt.subplots(2, 2, figsize=(10, 6), sharex=True)
    series = (
        ("resident memory (MB)", [s.rss_mb for s in samples]),
        ("open file descriptors", [s.fds for s in samples]),
        ("OS threads", [s.threads for s in samples]),
        ("experience store (kB)", [s.store_bytes / 1024 for s in samples]),
    )
    for ax, (title, ys) in zip(axes.flat, series, strict=True):
        ax.plot(x, ys, lw=1)
        ax.axvline(warmup - 0.5, color="grey", ls=":", lw=1)
        ax.set_title(title, fontsize=10)
    for ax in axes[1]:
        ax.set_xlabel("episode")
    fig.suptitle(f"scone-bench soak: {len(samples)} episodes in one process (dotted: end of the warm-up)")
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=100)
    plt.close(fig)


def run(args: argparse.Namespace) -> int:
    """Run the soak; print the JSON report (and write it to --json, the plot to --plot)."""
    _check_args(args)
    recipes = corpus_recipes(args.episodes, args.seed, args.max_steps)
    started = time.perf_counter()
    samples, unfinished, interrupted = _run_episodes(args, recipes)
    if not samples:
        raise KeyboardInterrupt
    result = _report(args, samples, unfinished, interrupted, time.perf_counter() - started)
    if args.plot:
        _plot(samples, result["warmup"], Path(args.plot))
    emit_report(result, args.json, force=args.force)
    return 0


def _check_args(args: argparse.Namespace) -> None:
    """Every bad option is one line now, before hours of episodes."""
    from scone_bt.checks import check_output_file, check_positive_int
    from scone_bt.config import load_robot
    from scone_bt.robot.registry import backend_factory

    check_positive_int(args.episodes, "--episodes")
    check_positive_int(args.max_ticks, "--max-ticks")
    check_positive_int(args.max_steps, "--max-steps")
    backend_factory(args.robot)
    load_robot(args.arm)
    if args.plot:  # a file the plot must not replace
        inputs = {"--json": [args.json]} if args.json else {}
        check_output_file(Path(args.plot), "--plot", kind="image", inputs=inputs, force=args.force)


def _run_episodes(
    args: argparse.Namespace, recipes: list[str]
) -> tuple[list[EpisodeSample], list[dict[str, Any]], bool]:
    """The episodes back to back, one sample after each: (samples, unfinished episodes, interrupted)."""
    from scone_bt.episode.resources import ModelPool

    samples: list[EpisodeSample] = []
    unfinished: list[dict[str, Any]] = []
    interrupted = False
    with tempfile.TemporaryDirectory(prefix="scone-soak-") as tmp, ModelPool() as models:
        store = Path(tmp) / "experience.sqlite"
        # A cache folder of the soak's own: every recipe starts with its texts unembedded, as a new user's would,
        # and the user's own cache is neither used nor filled.
        cache_dir = Path(args.cache_dir) if args.cache_dir else Path(tmp) / "cache"
        # With --record every episode is recorded, as `scone-run --save` does, to a file thrown away after it.
        recording = Path(tmp) / "episode.rrd" if args.record else None
        bar = progress_bar(len(recipes), "soak", args.quiet, unit="episode")
        try:
            for i, recipe in enumerate(recipes):
                bar.set_postfix_str(recipe)
                summary = _episode(args, recipe, i, store, cache_dir, recording, models)
                sample = _sample(i, recipe, summary, store, recording, models)
                samples.append(sample)
                if not summary.completed:  # what the robot and the human did last, to find why it never ended
                    unfinished.append(
                        {"episode": i, "recipe": recipe, "decisions_last": list(summary.decision_log[-12:])}
                    )
                bar.set_postfix_str(f"{sample.rss_mb:.0f} MB, {sample.fds} fds, {sample.threads} threads")
                bar.update()
        except KeyboardInterrupt:
            # Hours of samples are not lost to a Ctrl-C: the report covers the episodes that ran.
            interrupted = True
        bar.close()
    return samples, unfinished, interrupted


def _episode(
    args: argparse.Namespace,
    recipe: str,
    index: int,
    store: Path,
    cache_dir: Path,
    recording: Path | None,
    models: Any,
) -> Any:
    """Episode ``index`` of the soak (seed ``--seed`` + index), on the shared store, cache and models."""
    from scone_bt.behaviours import BehaviourOptions
    from scone_bt.episode import EpisodeOptions, run_episode
    from scone_bt.quiet import c_stdout_silenced

    seed = args.seed + index
    options = EpisodeOptions(
        arm=args.arm,
        backend=args.robot,
        recipe=recipe,
        seed=seed,
        distractors=args.distractors,
        max_ticks=args.max_ticks,
        behaviour=BehaviourOptions(seed=seed, experience_path=store, cache_dir=cache_dir),
        save=recording,
    )
    with c_stdout_silenced():
        return run_episode(options, printer=lambda _line: None, models=models)


def _sample(
    index: int, recipe: str, summary: Any, store: Path, recording: Path | None, models: Any
) -> EpisodeSample:
    """The process right after the episode (its recording, if any, measured and deleted)."""
    recording_bytes = 0
    if recording is not None and recording.exists():
        recording_bytes = recording.stat().st_size
        recording.unlink()  # the file is not what is measured: what the process keeps after closing it is
    gc.collect()  # what is still reachable is what the sample should see, not garbage awaiting a pass
    rss_mb, fds, threads = process_sample()
    caches = [getattr(e, "cache", None) for e in models.embedders()]
    return EpisodeSample(
        episode=index,
        recipe=recipe,
        completed=summary.completed,
        wall_s=round(summary.wall_time, 3),
        rss_mb=round(rss_mb, 2),
        fds=fds,
        threads=threads,
        python_threads=threading.active_count(),
        bodies=summary.bodies,
        constraints=summary.constraints,
        store_bytes=_store_bytes(store),
        outcomes=_outcomes(store),
        embedding_cache_entries=sum(len(c) for c in caches if c is not None),
        steps=f"{summary.steps_completed}/{summary.steps_total}",
        control_ticks=summary.control_ticks,
        recording_bytes=recording_bytes,
    )


def _report(
    args: argparse.Namespace,
    samples: list[EpisodeSample],
    unfinished: list[dict[str, Any]],
    interrupted: bool,
    wall_s: float,
) -> dict[str, Any]:
    """The JSON report: the slopes and growths after the warm-up, the targets, the per-episode table."""
    warmup = min(args.warmup, len(samples) - 1)
    growth = slope([s.rss_mb for s in samples[warmup:]])
    last = samples[-1]
    base = samples[warmup - 1] if warmup > 0 else samples[0]
    result: dict[str, Any] = {
        "episodes": args.episodes,
        "robot": args.robot,
        "arm": args.arm,
        "seed": args.seed,
        "max_steps": args.max_steps,
        "max_ticks": args.max_ticks,
        "record": bool(args.record),
        "warmup": warmup,
        "episodes_completed": sum(s.completed for s in samples),
        "episodes_run": len(samples),
        "interrupted": interrupted,
        "rss_growth_mb_per_episode": round(growth, 4) if growth is not None else None,
        "rss_mb_after_warmup": base.rss_mb,
        "rss_mb_last": last.rss_mb,
        "rss_mb_max": max(s.rss_mb for s in samples),
        "fd_growth": last.fds - base.fds,
        "thread_growth": last.threads - base.threads,
        "python_thread_growth": last.python_threads - base.python_threads,
        "bodies_growth": last.bodies - base.bodies,
        "constraints_growth": last.constraints - base.constraints,
        "store_bytes_per_outcome": round(last.store_bytes / last.outcomes, 1) if last.outcomes else None,
        "outcomes": last.outcomes,
        "recording_mb_mean": round(sum(s.recording_bytes for s in samples) / len(samples) / 2**20, 2)
        if args.record
        else None,
        "wall_s": round(wall_s, 1),
        "cpu_count": os.cpu_count(),
        "targets": TARGETS,
        "unfinished": unfinished,
        "per_episode": [asdict(s) for s in samples],
    }
    result["meets_targets"] = bool(
        growth is not None
        and growth <= TARGETS["rss_growth_mb_per_episode"]
        and result["fd_growth"] <= 0
        and result["thread_growth"] <= 0
        and result["episodes_completed"] == args.episodes
    )
    return result


def _outcomes(path: Path) -> int:
    """Outcomes in the SQLite store at ``path`` (0 before its first)."""
    if not path.exists():
        return 0
    from scone_bt.experience import open_store

    with open_store(path) as store:
        return len(store)


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``soak`` to ``scone-bench``."""
    from scone_bt.defaults import EPISODE
    from scone_bt.robot.registry import BACKENDS, DEFAULT_BACKEND

    p = sub.add_parser(
        "soak", help="many episodes in one process: memory, descriptors, threads per episode (JSON)"
    )
    p.add_argument("--episodes", type=int, default=200, help="episodes to run (default 200)")
    p.add_argument(
        "--robot",
        default=DEFAULT_BACKEND,
        help=f"robot backend: {', '.join(BACKENDS)} (default {DEFAULT_BACKEND})",
    )
    p.add_argument("--arm", default=EPISODE.arm, help=f"robot file name or path (default {EPISODE.arm})")
    p.add_argument("--seed", type=int, default=0, help="seeds the recipes' draw; episode i uses seed + i")
    p.add_argument(
        "--warmup", type=int, default=10, help="episodes before the memory slope is fitted (default 10)"
    )
    p.add_argument("--distractors", type=int, default=4, help="distractor products per episode (default 4)")
    p.add_argument(
        "--max-ticks", type=int, default=4000, help="control-tick limit per episode (default 4000)"
    )
    p.add_argument(
        "--max-steps",
        type=int,
        default=12,
        help="draw corpus recipes of at most this many steps (default 12)",
    )
    p.add_argument(
        "--record",
        action="store_true",
        help="record every episode with rerun to a throwaway .rrd (as scone-run --save): the recorder's memory",
    )
    p.add_argument(
        "--cache-dir", type=path_arg, help="embedding cache folder (default: a temporary one, empty)"
    )
    p.add_argument("--plot", type=path_arg, help="also plot the per-episode series to this PNG")
    p.add_argument("--json", type=path_arg, help="also write the JSON report to this file")
    p.add_argument("--quiet", action="store_true", help="no progress bar on stderr")
    p.set_defaults(func=run)
