"""``scone-bench sc generate``: every execution of every profile, in parallel, resumable, with a JSON summary.

One CSV per profile (<out>/<profile>.csv, columns dataset.COLUMNS). Finished rows of an unfinished profile live in
<out>/.<profile>.partial.csv and are not run again; the file becomes <profile>.csv when all are done. Execution i
of a profile uses seed (profile.seed + --seed) * 100000 + i, so any row can be regenerated alone, on any engine.
Every run is appended to <out>/generation.json (command, software, timings; no machine paths). Its
"generations" record what made each profile's rows (robot, kitchen, catalogues, products, seed, profile): a run
with other settings than the rows already in --out is refused before it executes anything, so a dataset never
mixes two generations and no row of another generation is dropped or overwritten.
"""

from __future__ import annotations

import argparse
import dataclasses
import difflib
import hashlib
import json
import math
import os
import platform
import sys
import time
from collections import Counter
from collections.abc import Generator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from scone_bt.benchmarks.progress import progress_bar
from scone_bt.benchmarks.self_confidence.dataset import ExecutionRecord, read_records, write_records
from scone_bt.benchmarks.self_confidence.generate import (
    ENGINES,
    ExecutionTask,
    drawable_products,
    execute_task,
)
from scone_bt.benchmarks.self_confidence.profiles import Profile, load_profiles
from scone_bt.config import ObjectSpec
from scone_bt.config.grasp import GraspParams
from scone_bt.errors import ConfigError
from scone_bt.files import write_atomic

__all__ = [
    "LOG_NAME",
    "SETTINGS",
    "check_writable",
    "generation_settings",
    "parse_products",
    "parse_profile_names",
    "read_log",
    "run_generate",
    "summarise",
]


def parse_profile_names(values: Sequence[str] | None) -> list[str] | None:
    """Profile names given as several words and/or comma-separated lists; None for all."""
    if not values:
        return None
    return [n.strip() for v in values for n in v.split(",") if n.strip()]


def parse_products(value: str | None, names: Sequence[str]) -> tuple[str, ...] | None:
    """The --products restriction: a file of one name a line (# comments) or comma-separated names.

    Raises:
        ConfigError: A name not in the catalogue (with the closest valid names), or an empty list.
    """
    if value is None:
        return None
    path = Path(value)
    if path.is_file():
        from scone_bt.config.schema import read_text

        items = [line.split("#", 1)[0].strip() for line in read_text(path).splitlines()]
        where = f"--products file {value}"
    elif "," not in value and (Path(value).suffix in (".txt", ".csv") or "/" in value):
        # a file the user meant (a path or a file name), not a product: say the file is missing
        raise ConfigError(f"--products {value}: no such file (give a file of product names, or names a,b,c)")
    else:
        items = [v.strip() for v in value.split(",")]
        where = "--products"
    chosen = tuple(dict.fromkeys(i for i in items if i))
    if not chosen:
        raise ConfigError(f"{where}: no product names")
    known = set(names)
    for name in chosen:
        if name not in known:
            close = difflib.get_close_matches(name, names, n=5, cutoff=0.5)
            hint = f"closest: {', '.join(close)}" if close else "none is close"
            raise ConfigError(
                f"{where}: unknown product {name!r} ({hint}; `scone-bench catalogue` lists all {len(names)})"
            )
    return chosen


def check_writable(out: Path) -> None:
    """Create `out` and prove a file can be written there, before any execution runs."""
    try:
        out.mkdir(parents=True, exist_ok=True)
        probe = out / f".write-test-{os.getpid()}"
        probe.write_text("")
        probe.unlink()
    except OSError as exc:
        raise ConfigError(f"--out {out}: not a writable folder ({exc.strerror or exc})") from None


def _note(bar: Any, text: str) -> None:
    """A line above the bar on stderr (nothing with --no-progress; tqdm.write alone would print to stdout)."""
    if not bar.disable:
        bar.write(text, file=sys.stderr)


def _paths(out: Path, profile: Profile) -> tuple[Path, Path]:
    return out / f"{profile.name}.csv", out / f".{profile.name}.partial.csv"


LOG_NAME = "generation.json"
"""The log of every run in --out, and the settings each profile's rows were generated with."""

SETTINGS: dict[str, str] = {
    "robot": "--arm",
    "kitchen": "--kitchen",
    "catalogues": "--catalogue",
    "products": "--products",
    "seed": "--seed",
    "profile": "the profile",
    "backend": "--robot",
    "slide_pinch": "--arm's grasp.slide_pinch",
}
"""What defines a generation, and the option that sets each (for messages). A generation recorded before the
engine was a setting has no "backend": it was PyBullet's (``sim``); one recorded before the arm slid and pinched
flat packs (`motion.slide`) has no "slide_pinch": it did not."""


def _file_id(path: Path) -> str:
    """A file's name and the start of its SHA-256: the same file from any folder, an edited one told apart."""
    from scone_bt.config.schema import read_bytes

    return f"{path.name} sha256:{hashlib.sha256(read_bytes(path)).hexdigest()[:12]}"


def _profile_id(profile: Profile) -> str:
    """The profile's name and a digest of its parameters (base seed included; not its description or file)."""
    # A reworded description changes no row: only the parameters define the generation.
    text = repr(dataclasses.replace(profile, description="", source=Path(".")))
    return f"{profile.name} sha256:{hashlib.sha256(text.encode()).hexdigest()[:12]}"


def generation_settings(
    profile: Profile,
    robot: Path,
    kitchen: Path,
    catalogues: Sequence[str],
    products: Sequence[str] | None,
    seed: int,
    backend: str = "sim",
    slide_pinch: bool = False,
) -> dict[str, Any]:
    """What made a profile's rows, as generation.json records it (file names and digests, no machine paths).

    Args:
        profile: The profile as its file gives it (before --seed).
        robot: The robot file.
        kitchen: The kitchen file.
        catalogues: The --catalogue files.
        products: The --products restriction (None: the whole catalogue).
        seed: The --seed offset (0 without --seed).
        backend: The engine the rows were run on (--robot: sim is PyBullet, mujoco).
        slide_pinch: The arm slid and pinched flat packs on a lowest tier (the robot file's grasp.slide_pinch):
            the replay's gate then leaves those to κ̂ (`gate.rules.GateRules.slide_pinch`).
    """
    return {
        "robot": _file_id(robot),
        "kitchen": _file_id(kitchen),
        "catalogues": [_file_id(Path(c)) for c in catalogues],
        "products": None if products is None else list(products),
        "seed": seed,
        "profile": _profile_id(profile),
        "backend": backend,
        "slide_pinch": slide_pinch,
    }


def read_log(path: Path) -> dict[str, Any]:
    """generation.json, read and checked before any execution runs ({"runs": []} when there is none).

    Raises:
        ConfigError: One line naming the file and what is wrong (not a file, not UTF-8, not JSON, a bad shape).
    """
    from scone_bt.config.schema import read_text

    if not path.exists() and not path.is_symlink():
        return {"runs": []}
    text = read_text(path)  # a folder, a device, a file that is not UTF-8: one line
    fix = "fix it (it records how the datasets in this folder were made), or give another --out"
    try:
        log = json.loads(text)
    except json.JSONDecodeError as exc:
        raise ConfigError(f"{path}: not valid JSON (line {exc.lineno}: {exc.msg}); {fix}") from None
    except RecursionError:
        raise ConfigError(f"{path}: nested too deeply to be a generation log; {fix}") from None
    if not isinstance(log, dict):
        raise ConfigError(
            f'{path}: must be a JSON object with a "runs" list, not {type(log).__name__}; {fix}'
        )
    runs = log.setdefault("runs", [])
    if not isinstance(runs, list) or not all(isinstance(r, dict) for r in runs):
        raise ConfigError(f'{path}: "runs" must be a list of objects; {fix}')
    generations = log.get("generations", {})
    if not isinstance(generations, dict):
        raise ConfigError(f'{path}: "generations" must be an object (profile name -> settings); {fix}')
    for name, recorded in generations.items():
        if isinstance(recorded, dict):
            recorded.setdefault("backend", "sim")  # recorded before the engine was a setting: PyBullet's
            recorded.setdefault("slide_pinch", False)  # recorded before the arm slid flat packs
        if not isinstance(recorded, dict) or set(recorded) != set(SETTINGS):
            raise ConfigError(
                f'{path}: "generations" / {name!r} must be an object with exactly the keys '
                f"{', '.join(SETTINGS)}; {fix}"
            )
    return log


def _show(key: str, value: Any) -> str:
    """A recorded setting in a message: "all" products, "none" for no catalogue, long lists cut."""
    if key == "products" and value is None:
        return "all products"
    if isinstance(value, list):
        text = ",".join(str(v) for v in value) or "none"
        return text if len(text) <= 80 else f"{text[:77]}... ({len(value)} in all)"
    return str(value)


def _differences(recorded: dict[str, Any], asked: dict[str, Any]) -> list[str]:
    """Each setting that differs, as "--robot: it holds A, this run asks B"."""
    lines = []
    for key, flag in SETTINGS.items():
        old, new = recorded.get(key), asked[key]
        if old == new:
            continue
        changed = (
            " (the file changed)"
            if isinstance(old, str) and isinstance(new, str) and old.split(" ")[0] == new.split(" ")[0]
            else ""
        )
        lines.append(f"{flag}: it holds {_show(key, old)}, this run asks {_show(key, new)}{changed}")
    return lines


def _another_generation(file: Path, what: str, advice: str) -> ConfigError:
    return ConfigError(
        f"{file}: holds executions of another generation ({what}); its rows are never dropped or overwritten: "
        f"give another --out, or {advice} to resume it"
    )


def _resume(
    out: Path,
    profile: Profile,
    offset: int,
    recorded: dict[str, Any] | None,
    asked: dict[str, Any],
) -> dict[int, ExecutionRecord]:
    """Every row already recorded for `profile` (complete file first, else the partial one).

    Raises:
        ConfigError: The rows are of another generation: settings recorded in generation.json differ from this
            run's, or a row's seed is not the one this run gives its index (another --seed). Checked before any
            execution runs; nothing is dropped.
    """
    final, partial = _paths(out, profile)
    rows, file = read_records(final), final
    if not rows:
        rows, file = read_records(partial), partial
    if not rows:
        return {}
    if recorded is not None:
        diffs = _differences(recorded, asked)
        if diffs:
            seed_only = [k for k in SETTINGS if recorded.get(k) != asked[k]] == ["seed"]
            advice = (
                f"--seed {recorded['seed']}" if seed_only else f"the settings recorded in {out / LOG_NAME}"
            )
            raise _another_generation(file, "; ".join(diffs), advice)
    # Rows made before generation.json recorded settings: their seeds still tell another --seed apart.
    wrong = next((r for r in rows if r.seed != profile.execution_seed(r.index)), None)
    if wrong is not None:
        base = profile.seed - offset
        held, rest = divmod(wrong.seed - wrong.index, 100_000)
        held -= base
        what = f"row {wrong.index} has seed {wrong.seed}, this run gives it {profile.execution_seed(wrong.index)}"
        if rest == 0 and 0 <= held + base <= 42_949:
            what = f"--seed {held}, this run asks --seed {offset}: {what}"
            raise _another_generation(file, what, f"--seed {held}")
        raise _another_generation(file, what, "the seed it was made with")
    return {r.index: r for r in rows}


def _save(out: Path, profile: Profile, records: dict[int, ExecutionRecord], complete: bool) -> None:
    final, partial = _paths(out, profile)
    if complete:
        write_records(final, records.values())
        partial.unlink(missing_ok=True)
    else:
        write_records(partial, records.values())


def summarise(
    profile: Profile, records: dict[int, ExecutionRecord], executions: int, walls: Sequence[float]
) -> dict[str, Any]:
    """Per-profile summary: rows, success rate, failure stages, seeds, mean wall time per execution."""
    recs = list(records.values())
    stages = Counter(r.failure_stage for r in recs if not r.success)
    return {
        "rows": len(recs),
        "complete": len(recs) >= executions,
        "success_rate": round(sum(r.success for r in recs) / len(recs), 3) if recs else None,
        "failure_stages": dict(sorted(stages.items())),
        "distinct_objects": len({r.object for r in recs}),
        "seeds": [profile.execution_seed(0), profile.execution_seed(executions - 1)],
        "mean_execution_wall_s": round(sum(walls) / len(walls), 3) if walls else None,
    }


def _cpu_s() -> float:
    """CPU seconds (user + system) of this process and of its child processes that have ended."""
    import resource

    own, children = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime


def _portable(argv: Sequence[str]) -> str:
    """The command line without machine paths (an absolute path keeps only its last two parts)."""
    parts = []
    for a in argv:
        parts.append(f".../{Path(a).parent.name}/{Path(a).name}" if os.path.isabs(a) else a)
    return " ".join(["scone-bench", *parts])


def _code_version() -> str | None:
    """The checkout's commit, with "-dirty" when files differ from it (None outside a git checkout)."""
    import subprocess

    try:
        out = subprocess.run(
            ["git", "describe", "--always", "--dirty", "--abbrev=12"],
            capture_output=True,
            text=True,
            timeout=10,
            cwd=Path(__file__).resolve().parent,
        )
    except (OSError, subprocess.SubprocessError):
        return None
    return out.stdout.strip() or None if out.returncode == 0 else None


def _write_log(
    path: Path, log: dict[str, Any], argv: Sequence[str], summary: dict[str, Any], engine: str = "sim"
) -> None:
    """Append this run to generation.json (read and checked before the run), keeping earlier runs."""
    from importlib.metadata import version

    engine_version = {"pybullet": version("pybullet")} if engine == "sim" else {engine: version(engine)}
    log.setdefault("runs", []).append(
        {
            "command": _portable(argv),
            "when": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
            "python": platform.python_version(),
            **engine_version,
            "cpu_count": os.cpu_count(),
            "code": _code_version(),
            **summary,
        }
    )
    write_atomic(path, json.dumps(log, indent=1) + "\n")  # an interrupted write keeps the old log whole


def _check_numbers(args: argparse.Namespace) -> None:
    """--executions, --workers, --max-minutes and every --catalogue file, before anything is loaded."""
    if args.executions < 1:
        raise ConfigError(f"--executions {args.executions}: must be at least 1")
    if args.workers < 1:
        raise ConfigError(f"--workers {args.workers}: must be at least 1")
    if args.max_minutes is not None and not (math.isfinite(args.max_minutes) and args.max_minutes > 0):
        raise ConfigError(
            f"--max-minutes {args.max_minutes}: must be a finite number above 0 (leave it out: no limit)"
        )
    for c in args.catalogue:
        if not Path(c).is_file():
            raise ConfigError(f"--catalogue {c}: no such file")


def _backend(args: argparse.Namespace) -> str:
    """The --robot backend, refused unless the generator drives its kitchen (MuJoCo's rendering checked)."""
    from scone_bt.robot.flags import check_backend

    engine = check_backend(args.robot)
    if engine not in ENGINES:
        raise ConfigError(
            f"scone-bench sc generate --robot {engine}: the generator runs on {', '.join(ENGINES)} "
            "(it drives the kitchen of the engine directly)"
        )
    if engine == "mujoco":  # the extra and headless rendering, checked before any work (one line each)
        from scone_bt.world.mj_camera import check_rendering
        from scone_bt.world.mj_model import import_mujoco

        check_rendering(import_mujoco())
    return engine


def _offset_profiles(args: argparse.Namespace) -> tuple[list[Profile], dict[str, Profile], int]:
    """(the profiles with --seed added to their seeds, the profiles as their files give them, --seed)."""
    profiles_dir = Path(args.profiles_dir)
    if not profiles_dir.is_dir():
        raise ConfigError(f"--profiles-dir {profiles_dir}: no such folder")
    profiles = load_profiles(profiles_dir, parse_profile_names(args.profiles))
    offset = int(args.seed or 0)
    base_profiles = {p.name: p for p in profiles}  # as their files give them, for the generation's record
    if offset:
        profiles = [dataclasses.replace(p, seed=p.seed + offset) for p in profiles]
        bad = [p for p in profiles if not 0 <= p.seed <= 42_949]
        if bad:
            raise ConfigError(
                f"--seed {offset}: profile {bad[0].name} would get seed {bad[0].seed}, not in 0-42949"
            )
    return profiles, base_profiles, offset


def same_seeds(profiles: Sequence[Profile], every: Sequence[Profile]) -> dict[str, list[str]]:
    """Name → the other profiles of ``every`` (as their files give them) whose executions use the same seeds as
    this one's (its seed offset by --seed): the same products, slots and neighbours, on another robot. A split
    meant to hold out new draws wants none."""
    return {p.name: [q.name for q in every if q.seed == p.seed and q.name != p.name] for p in profiles}


def _warn_same_seeds(shared: dict[str, list[str]], offset: int) -> None:
    """One line on stderr for each profile that draws what another profile draws at --seed 0."""
    for name, others in shared.items():
        if others:
            print(
                f"note: --seed {offset} gives {name} the seeds of {', '.join(others)} at --seed 0 (the same "
                "products, slots and neighbours); a split of new draws wants a --seed that shares none",
                file=sys.stderr,
            )


def _check_injections(catalogue_pool: Sequence[ObjectSpec], profiles: list[Profile]) -> None:
    """Refuse an injected failure for a material no product of the catalogue is made of: a misspelt one never
    fires. (Against the whole catalogue, not --products: a run over dairy alone may keep the glass profile.)"""
    materials = sorted({o.material for o in catalogue_pool})
    for profile in profiles:
        for k, injection in enumerate(profile.injected):
            for material in injection.materials:
                if material not in materials:
                    raise ConfigError(
                        f"{profile.source}: injected[{k}].materials: no product of the catalogue is of material "
                        f"{material!r}; valid: {', '.join(materials)}"
                    )


def _check_pool(pool: Sequence[ObjectSpec], products: Sequence[str] | None, profiles: list[Profile]) -> None:
    """Refuse a product pool smaller than a profile's products per execution, naming those that fit no tier."""
    most = max(p.objects_on_shelf for p in profiles)
    if len(pool) < most:
        drawn = {o.name for o in pool}
        unfit = [n for n in (products or ()) if n not in drawn]
        shown = ", ".join(unfit[:5]) + (f" and {len(unfit) - 5} more" if len(unfit) > 5 else "")
        why = f" ({shown} stand on no shelf tier: too deep or too long)" if unfit else ""
        raise ConfigError(
            f"--products: {len(pool)} product(s) fit the shelving{why}, profile needs {most} per execution "
            f"(objects_on_shelf); name more products"
        )


@dataclass(frozen=True)
class _Setup:
    """A generation run's checked settings.

    Attributes:
        engine: The backend (`ENGINES`).
        profiles: The profiles, their seeds offset by --seed.
        base_profiles: Name → the profile as its file gives it (the generation's record).
        offset: --seed.
        products: The --products restriction, or None.
        pool: The products executions draw from.
        catalogues: The --catalogue files.
        asked: Profile name → the settings this run generates with (`generation_settings`).
        shared: Profile name → the profiles whose seeds it shares (`same_seeds`).
    """

    engine: str
    profiles: list[Profile]
    base_profiles: dict[str, Profile]
    offset: int
    products: tuple[str, ...] | None
    pool: tuple[ObjectSpec, ...]
    catalogues: tuple[str, ...]
    asked: dict[str, dict[str, Any]]
    shared: dict[str, list[str]]


def _setup(args: argparse.Namespace) -> _Setup:
    """Check and load everything a run needs, in the order a bad value is best reported, before any work."""
    from scone_bt.config import load_kitchen, load_robot

    _check_numbers(args)
    kitchen_cfg = load_kitchen(args.kitchen, args.catalogue)
    engine = _backend(args)
    robot_cfg = load_robot(args.arm)  # a bad robot name fails here, before any work
    profiles, base_profiles, offset = _offset_profiles(args)
    products = parse_products(args.products, kitchen_cfg.catalogue.names())
    pool = drawable_products(kitchen_cfg, products)
    _check_injections(drawable_products(kitchen_cfg) if products else pool, profiles)
    _check_pool(pool, products, profiles)
    catalogues = tuple(str(c) for c in args.catalogue)
    asked = {
        p.name: generation_settings(
            base_profiles[p.name],
            robot_cfg.source,
            kitchen_cfg.source,
            catalogues,
            products,
            offset,
            engine,
            GraspParams.of(robot_cfg).slide_pinch,
        )
        for p in profiles
    }
    shared = same_seeds(profiles, load_profiles(args.profiles_dir))
    return _Setup(engine, profiles, base_profiles, offset, products, pool, catalogues, asked, shared)


@dataclass(frozen=True)
class _Work:
    """What a run resumes and what it executes.

    Attributes:
        log_path: --out's generation.json.
        log: Its contents, read and checked before the run.
        done: Profile name → index → the rows of this run's executions (recorded ones, then new ones).
        beyond: Profile name → rows past --executions (not this run's; kept in the file it rewrites).
        tasks: The executions still to run.
    """

    log_path: Path
    log: dict[str, Any]
    done: dict[str, dict[int, ExecutionRecord]]
    beyond: dict[str, dict[int, ExecutionRecord]]
    tasks: list[ExecutionTask]


def _work(args: argparse.Namespace, setup: _Setup) -> _Work:
    """Read --out's rows and log; refuse rows of another generation; the executions still to run."""
    out = Path(args.out)
    check_writable(out)
    log_path = out / LOG_NAME
    log = read_log(log_path)  # a damaged log stops the run now, not after every execution has run
    recorded = log.get("generations", {})
    profiles, asked = setup.profiles, setup.asked
    # Every profile's rows are checked before anything runs: one of another generation stops the whole run.
    rows = {p.name: _resume(out, p, setup.offset, recorded.get(p.name), asked[p.name]) for p in profiles}
    done = {name: {i: r for i, r in got.items() if i < args.executions} for name, got in rows.items()}
    # Rows past --executions are not this run's, but they stay in the file it rewrites.
    beyond = {name: {i: r for i, r in got.items() if i >= args.executions} for name, got in rows.items()}
    tasks = [
        ExecutionTask(p, i, args.kitchen, args.arm, setup.catalogues, setup.products, setup.engine)
        for p in profiles
        for i in range(args.executions)
        if i not in done[p.name]
    ]
    return _Work(log_path, log, done, beyond, tasks)


def _record_generations(work: _Work, asked: dict[str, dict[str, Any]]) -> None:
    """Record the settings of every profile this run adds rows to, before the first row is written."""
    recorded = work.log.get("generations", {})
    to_record = {t.profile.name for t in work.tasks if recorded.get(t.profile.name) != asked[t.profile.name]}
    if to_record:
        # Recorded before the first row is written: an interrupted run is resumed only with the same settings.
        work.log["generations"] = {**recorded, **{name: asked[name] for name in sorted(to_record)}}
        write_atomic(work.log_path, json.dumps(work.log, indent=1) + "\n")


@dataclass(frozen=True)
class _Ran:
    """How the executions went.

    Attributes:
        walls: Profile name → the wall time of each execution this run ran, s.
        resumed: Executions already recorded (not run again).
        stopped: Whether --max-minutes stopped the run early.
        elapsed: Wall time of the run, s.
        cpu: CPU time of this process and its finished worker processes, s.
        load_before: The 1-minute load average at the start (None where the system has none).
    """

    walls: dict[str, list[float]]
    resumed: int
    stopped: bool
    elapsed: float
    cpu: float
    load_before: float | None


def _execute(args: argparse.Namespace, setup: _Setup, work: _Work, pool_engine: Any) -> _Ran:
    """Run the tasks on the engine, saving each profile's rows after every execution; stop at --max-minutes."""
    from scone_bt.distributed import imap_tasks

    done, tasks, out = work.done, work.tasks, Path(args.out)
    by_name = {p.name: p for p in setup.profiles}
    walls: dict[str, list[float]] = {p.name: [] for p in setup.profiles}
    load_before = os.getloadavg()[0] if hasattr(os, "getloadavg") else None
    cpu0 = _cpu_s()
    t0 = time.perf_counter()
    deadline = None if args.max_minutes is None else t0 + 60.0 * args.max_minutes
    bar = progress_bar(len(tasks), "executions", quiet=args.no_progress, unit="run")
    skipped = sum(len(v) for v in done.values())
    if skipped:
        _note(bar, f"resuming: {skipped} executions already recorded, {len(tasks)} to run")
    stopped = False
    results: Generator[tuple[int, tuple[str, ExecutionRecord, float]], None, None] = imap_tasks(
        execute_task, tasks, engine=pool_engine
    )
    try:
        for _i, (name, record, wall) in results:
            done[name][record.index] = record
            walls[name].append(wall)
            _save(out, by_name[name], {**work.beyond[name], **done[name]}, len(done[name]) >= args.executions)
            bar.set_postfix_str(f"{name} {len(done[name])}/{args.executions}")
            bar.update(1)
            if deadline is not None and time.perf_counter() > deadline:
                _note(bar, "--max-minutes reached: stopping (finished rows are saved)")
                stopped = True
                break
    finally:
        results.close()  # stops the pool or cancels the Ray tasks still running
        bar.close()
    elapsed = time.perf_counter() - t0
    cpu = _cpu_s() - cpu0  # this process and its finished worker processes (a Ray cluster's are not counted)
    return _Ran(walls, skipped, stopped, elapsed, cpu, load_before)


def _summary(
    args: argparse.Namespace, setup: _Setup, work: _Work, ran: _Ran, pool_engine: Any
) -> dict[str, Any]:
    """The run's JSON summary (also appended to generation.json)."""
    run = sum(len(w) for w in ran.walls.values())
    elapsed = ran.elapsed
    return {
        "profiles": {
            p.name: {
                **summarise(p, work.done[p.name], args.executions, ran.walls[p.name]),
                "same_seeds_as": setup.shared[p.name],
            }
            for p in setup.profiles
        },
        "executions_run": run,
        "executions_resumed": ran.resumed,
        "wall_s": round(elapsed, 1),
        "executions_per_s": round(run / elapsed, 3) if run and elapsed > 0 else None,
        "cpu_s_per_execution": round(ran.cpu / run, 3) if run and pool_engine.kind.value == "local" else None,
        "workers": args.workers,
        "engine": pool_engine.label,
        "backend": setup.engine,
        "products_drawn_from": len(setup.pool),
        "user_catalogues": [Path(c).name for c in setup.catalogues],
        "load_average_1min": {
            "start": round(ran.load_before, 2) if ran.load_before is not None else None,
            "end": round(os.getloadavg()[0], 2) if hasattr(os, "getloadavg") else None,
        },
        "stopped_early": ran.stopped,
    }


def run_generate(args: argparse.Namespace) -> int:
    """Run the executions `args` asks for; print (and with --json write) the summary. 0 when every profile is
    complete, 1 when stopped early (--max-minutes)."""
    from scone_bt.distributed import engine_from_args, start_engine
    from scone_bt.reporting import emit_report

    setup = _setup(args)
    work = _work(args, setup)
    pool_engine = engine_from_args(args, args.workers)
    start_engine(pool_engine)  # an unreachable Ray cluster fails here, before any work
    _warn_same_seeds(setup.shared, setup.offset)  # after every check that refuses the run (one line each)
    _record_generations(work, setup.asked)
    ran = _execute(args, setup, work, pool_engine)
    summary = _summary(args, setup, work, ran, pool_engine)
    _write_log(
        work.log_path,
        work.log,
        sys.argv[1:] if sys.argv and "scone-bench" in sys.argv[0] else ["sc", "generate"],
        summary,
        setup.engine,
    )
    emit_report(summary, args.json, force=bool(getattr(args, "force", False)))
    return 0 if all(v["complete"] for v in summary["profiles"].values()) else 1
