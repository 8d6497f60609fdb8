"""``scone-bench fleet``: a fleet sharing one experience store, and what a new robot gains from it.

    scone-bench fleet --json runs/fleet.json          # temporary PostgreSQL server + SQLite file
    scone-bench fleet --postgres postgresql://me@db/scone_bench --seeds 20

Part 1, the store (per backend): 4 robot processes append 50 outcomes each to one store, concurrently; robot 0 is
SIGKILLed mid-run and restarted (it resumes from what the store holds and re-sends its last attempt). Reported:
`stored` (rows), `lost` (attempts a robot acknowledged that are not stored), `duplicated` (rows beyond one per
robot attempt), and append latency.

Part 2, learning (replay): the attempt streams are the self-confidence datasets, real simulated pick-and-place
executions with their outcomes (tools/data/sc: 11 Panda profiles × 100; tools/data/fleet/iiwa7: iiwa7
executions), replayed, not new physical episodes. A model is an arm with a profile. For each model and seed, the
model's rows are shuffled; a new robot makes the first 20 attempts; the fleet holds the other rows of its model
(and, for `fleet_pooled`, every other model's rows too). Before each attempt κ̂ (eps-knn on MiniLM, gate 0.5)
predicts; the robot acts if κ̂ ≥ 0.5 (a failure counts if the recorded outcome is a failure, and κ̂ learns the
outcome) or asks for help. `first20_failures_*` are failures per new robot, averaged over models, mean ± std
over seeds; `first20_accuracy_*` is κ̂'s prediction accuracy on those 20 attempts (the SC metric).
Arm transfer: a new iiwa7 (or Panda) robot learning from the other arm's robots of the same profile, pooled, with
the arm one-hot as part of κ̂'s input, or filtered to its own arm.
"""

from __future__ import annotations

import argparse
import os
import signal
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from scone_bt.argparsing import path_arg
from scone_bt.reporting import emit_report

__all__ = ["register", "store_trial", "learning_trial", "ReplayResult", "replay_new_robot"]

GATE = 0.5
FIRST_N = 20


DEFAULT_ESTIMATOR = "eps-knn"
"""κ̂ of the learning replay when --estimator is not given."""
DEFAULT_SEEDS = 10
"""Seeds of the learning replay when --seeds is not given."""


def _stderr(proc: subprocess.Popen[str]) -> str:
    """What a finished robot process wrote to its standard error (piped), stripped."""
    return proc.stderr.read().strip() if proc.stderr is not None else ""


# ----- part 1: the store ---------------------------------------------------------------------------------------
def store_trial(
    spec: str,
    datasets: Sequence[Path],
    per_robot: int = 50,
    kill_after: int = 20,
    interval_s: float = 0.01,
) -> dict[str, Any]:
    """4 (len(datasets)) robot processes × per_robot outcomes into `spec`; robot 0 SIGKILLed after kill_after."""
    from scone_bt.experience import open_store

    open_store(spec).close()  # create the schema before the robots start
    env = {**os.environ, "OMP_NUM_THREADS": "1"}

    def launch(k: int) -> subprocess.Popen[str]:
        path = datasets[k]
        args = [spec, f"robot{k}", "panda", path.stem, str(path), str(per_robot), str(interval_s)]
        return subprocess.Popen(
            [sys.executable, "-m", "scone_bt.benchmarks.fleet_robot", *args],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            env=env,
        )

    t0 = time.perf_counter()
    procs = [launch(k) for k in range(len(datasets))]
    acked: dict[int, set[int]] = {k: set() for k in range(len(datasets))}
    latencies: list[float] = []

    def read(k: int, proc: subprocess.Popen[str], stop_after: int | None = None) -> None:
        assert proc.stdout is not None
        for line in proc.stdout:
            attempt, ms = line.split()
            acked[k].add(int(attempt))
            latencies.append(float(ms))
            if stop_after is not None and len(acked[k]) >= stop_after:
                return

    read(0, procs[0], stop_after=kill_after)
    procs[0].send_signal(signal.SIGKILL)
    procs[0].wait()
    read(0, procs[0])  # lines it printed before dying
    killed_at = len(acked[0])
    for k in range(1, len(procs)):
        read(k, procs[k])
    errors = [_stderr(p) for p in procs[1:] if p.wait() != 0]
    restarted = launch(0)
    read(0, restarted)
    if restarted.wait() != 0:
        errors.append(_stderr(restarted))
    for p in [*procs, restarted]:
        for stream in (p.stdout, p.stderr):
            if stream is not None:
                stream.close()
    wall = time.perf_counter() - t0
    with open_store(spec) as store:
        rows = store.outcomes()
    keys = [(o.robot_id, o.context.get("attempt")) for o in rows]
    stored_keys = set(keys)
    lost = sum(1 for k, attempts in acked.items() for a in attempts if (f"robot{k}", a) not in stored_keys)
    return {
        "robots": len(datasets),
        "outcomes_per_robot": per_robot,
        "killed": {"robot": "robot0", "after_acknowledged": killed_at},
        "stored": len(rows),
        "lost": lost,
        "duplicated": len(keys) - len(stored_keys),
        "expected": len(datasets) * per_robot,
        "append_latency_ms": {
            "median": round(float(np.median(latencies)), 2) if latencies else None,
            "p99": round(float(np.percentile(latencies, 99)), 2) if latencies else None,
            "max": round(float(np.max(latencies)), 2) if latencies else None,
        },
        "wall_s": round(wall, 2),
        "errors": errors,
    }


# ----- part 2: learning -------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Model:
    """The rows of one robot model (arm + profile): action embeddings and outcomes, in the dataset's order."""

    arm: str
    profile: str
    X: np.ndarray
    y: np.ndarray

    @property
    def name(self) -> str:
        return f"{self.arm}/{self.profile}"


@dataclass(frozen=True)
class ReplayResult:
    """A new robot's first attempts: failures (acted and failed), help requests, and κ̂'s accuracy."""

    failures: int
    asks: int
    accuracy: float


def replay_new_robot(
    stream_X: np.ndarray,
    stream_y: np.ndarray,
    prior_X: np.ndarray,
    prior_y: np.ndarray,
    estimator: str = DEFAULT_ESTIMATOR,
    seed: int = 0,
) -> ReplayResult:
    """Run the gate over an attempt stream, κ̂ first fitted on the prior outcomes (none: a cold start)."""
    from scone_bt.confidence import make_estimator

    est = make_estimator(estimator, seed=seed)
    if len(prior_y):
        est.fit(prior_X, prior_y)
    failures = asks = correct = 0
    for x, y in zip(stream_X, stream_y, strict=True):
        p = float(np.asarray(est.predict(x[None, :])).reshape(-1)[0])
        correct += int((p >= GATE) == bool(y))
        if p >= GATE:
            failures += int(not y)
            est.update(x, bool(y))
        else:
            asks += 1
    return ReplayResult(failures, asks, correct / len(stream_y))


def _with_arm(X: np.ndarray, arm: str, arms: Sequence[str]) -> np.ndarray:
    onehot = np.zeros((len(X), len(arms)), dtype=X.dtype)
    onehot[:, list(arms).index(arm)] = 1.0
    return np.hstack([X, onehot])


def load_models(sc_dir: Path, iiwa_dir: Path | None, embed: Callable[[list[str]], np.ndarray]) -> list[Model]:
    """Every dataset as a Model (Panda profiles from sc_dir, iiwa7 ones from iiwa_dir if present)."""
    from scone_bt.benchmarks.self_confidence import load_datasets

    sources = [("panda", sc_dir)]
    if iiwa_dir is not None and any(iiwa_dir.glob("[!.]*.csv")):
        sources.append(("iiwa7", iiwa_dir))
    models = []
    for arm, folder in sources:
        for d in load_datasets(folder, min_rows=FIRST_N + 1):
            X = np.asarray(embed(list(d.actions)), dtype=np.float32)
            models.append(Model(arm, d.name, X, np.asarray(d.success, dtype=bool)))
    return models


def _ms(values: Sequence[float]) -> dict[str, float]:
    v = np.asarray(values, dtype=float)
    return {"mean": round(float(v.mean()), 3), "std": round(float(v.std(ddof=1)) if len(v) > 1 else 0.0, 3)}


def learning_trial(
    models: Sequence[Model], seeds: int = DEFAULT_SEEDS, estimator: str = DEFAULT_ESTIMATOR
) -> dict[str, Any]:
    """Cold vs same-model vs pooled fleet for a new robot of every Panda model; arm transfer if iiwa7 data exists."""
    arms = sorted({m.arm for m in models})
    panda = [m for m in models if m.arm == "panda"]
    per_seed: dict[str, list[list[ReplayResult]]] = {"cold": [], "same_model": [], "fleet_pooled": []}
    per_model: dict[str, dict[str, list[int]]] = {m.name: {k: [] for k in per_seed} for m in panda}
    for s in range(seeds):
        rows: dict[str, list[ReplayResult]] = {k: [] for k in per_seed}
        for mi, m in enumerate(panda):
            order = np.random.default_rng([s, mi]).permutation(len(m.y))
            new, rest = order[:FIRST_N], order[FIRST_N:]
            # Another arm's dataset of the same profile shares this one's execution seeds (row i: same scene):
            # only its `rest` rows are fleet data, so no scene of the new robot's stream leaks in.
            others = [(o, rest if o.profile == m.profile else slice(None)) for o in models if o is not m]
            priors = {
                "cold": (m.X[:0], m.y[:0]),
                "same_model": (m.X[rest], m.y[rest]),
                "fleet_pooled": (
                    np.vstack([m.X[rest], *[o.X[idx] for o, idx in others]]),
                    np.concatenate([m.y[rest], *[o.y[idx] for o, idx in others]]),
                ),
            }
            for key, (pX, py) in priors.items():
                r = replay_new_robot(m.X[new], m.y[new], pX, py, estimator, seed=s)
                rows[key].append(r)
                per_model[m.name][key].append(r.failures)
        for key in per_seed:
            per_seed[key].append(rows[key])

    def summary(key: str, attr: str) -> dict[str, float]:
        return _ms([float(np.mean([getattr(r, attr) for r in seed_rows])) for seed_rows in per_seed[key]])

    out: dict[str, Any] = {
        "protocol": f"replay of recorded executions; {len(panda)} Panda models × {seeds} seeds; first {FIRST_N} "
        f"attempts of a new robot; κ̂ {estimator} on MiniLM, gate {GATE}",
        "first20_failures_cold": summary("cold", "failures"),
        "first20_failures_fleet": summary("same_model", "failures"),
        "first20_failures_fleet_pooled": summary("fleet_pooled", "failures"),
        "first20_asks_cold": summary("cold", "asks"),
        "first20_asks_fleet": summary("same_model", "asks"),
        "first20_asks_fleet_pooled": summary("fleet_pooled", "asks"),
        "first20_accuracy_cold": summary("cold", "accuracy"),
        "first20_accuracy_fleet": summary("same_model", "accuracy"),
        "first20_accuracy_fleet_pooled": summary("fleet_pooled", "accuracy"),
        "per_model_failures_mean": {
            name: {k: round(float(np.mean(v)), 2) for k, v in d.items()} for name, d in per_model.items()
        },
    }
    out["arm_transfer"] = _arm_transfer(models, arms, seeds, estimator) if len(arms) > 1 else None
    return out


def _arm_transfer(models: Sequence[Model], arms: list[str], seeds: int, estimator: str) -> dict[str, Any]:
    """A new robot of arm A and profile P, learning from arm B's P robots (and A's other P robots)."""
    by_key = {(m.arm, m.profile): m for m in models}
    pairs = [(p, a, b) for (a, p) in by_key for b in arms if b != a and (b, p) in by_key]
    results: dict[str, dict[str, Any]] = {}
    for profile, arm, other_arm in pairs:
        m, o = by_key[arm, profile], by_key[other_arm, profile]
        runs: dict[str, list[ReplayResult]] = {
            k: [] for k in ("cold", "other_arm_only", "pooled", "arm_as_input", "arm_as_filter")
        }
        for s in range(seeds):
            order = np.random.default_rng([s, 7]).permutation(len(m.y))
            new, rest = order[:FIRST_N], order[FIRST_N:]
            sX, sy = m.X[new], m.y[new]
            # Both arms' datasets share execution seeds (row i: same target and scene), so the other arm's rows
            # are taken at the same `rest` indices: no scene of the new robot's stream is in the fleet's data.
            oX, oy = o.X[rest], o.y[rest]
            both_X, both_y = np.vstack([m.X[rest], oX]), np.concatenate([m.y[rest], oy])
            arm_X = np.vstack([_with_arm(m.X[rest], arm, arms), _with_arm(oX, other_arm, arms)])
            runs["cold"].append(replay_new_robot(sX, sy, sX[:0], sy[:0], estimator, s))
            runs["other_arm_only"].append(replay_new_robot(sX, sy, oX, oy, estimator, s))
            runs["pooled"].append(replay_new_robot(sX, sy, both_X, both_y, estimator, s))
            runs["arm_as_input"].append(
                replay_new_robot(_with_arm(sX, arm, arms), sy, arm_X, both_y, estimator, s)
            )
            runs["arm_as_filter"].append(replay_new_robot(sX, sy, m.X[rest], m.y[rest], estimator, s))
        results[f"new {arm} {profile} from {other_arm}"] = {
            "own_success_rate": round(float(m.y.mean()), 3),
            "other_arm_success_rate": round(float(o.y.mean()), 3),
            **{
                k: {
                    "failures": _ms([r.failures for r in v]),
                    "asks": _ms([r.asks for r in v]),
                    "accuracy": _ms([r.accuracy for r in v]),
                }
                for k, v in runs.items()
            },
        }
    return results


# ----- command ------------------------------------------------------------------------------------------------
STORES = ("postgresql", "sqlite")


def _check_args(args: argparse.Namespace) -> None:
    """Every option of ``fleet`` before any store is opened or robot started: one line naming the flag."""
    from scone_bt.checks import check_positive_int
    from scone_bt.errors import SconeError
    from scone_bt.experience import redact_url
    from scone_bt.experience.open import is_postgres_url

    backends = [b for b in args.stores.split(",") if b]
    unknown = [b for b in backends if b not in STORES]
    if unknown or not backends:
        raise SconeError(f"--stores {args.stores}: give a comma list of {', '.join(STORES)}")
    if args.postgres is not None and not is_postgres_url(args.postgres):
        raise SconeError(
            f"--postgres {redact_url(args.postgres)}: not a PostgreSQL URL; give postgresql://USER@HOST/DATABASE "
            "(or leave it out for a temporary server)"
        )
    check_positive_int(args.robots, "--robots", maximum=64)
    check_positive_int(args.outcomes, "--outcomes", maximum=100_000)
    if not 0 <= args.kill_after <= args.outcomes:
        raise SconeError(
            f"--kill-after {args.kill_after}: must be an integer in 0..{args.outcomes} (0..--outcomes)"
        )
    if args.no_learning:
        from scone_bt.argparsing import refuse_unread, subcommand_defaults

        learning_only = {"estimator": "--estimator", "seeds": "--seeds", "iiwa_datasets": "--iiwa-datasets"}
        why = "only the learning trial reads it, and --no-learning skips that trial"
        refuse_unread(args, subcommand_defaults(register, "fleet"), learning_only, why)
        return
    from scone_bt.cli.run import _check_estimator  # the one check of registry names

    _check_estimator(args.estimator)
    check_positive_int(args.seeds, "--seeds", maximum=10_000)


def _handler(args: argparse.Namespace) -> int:
    from scone_bt.errors import SconeError
    from scone_bt.resources import repo_root

    _check_args(args)
    root = repo_root()
    if root is None:
        raise SconeError("scone-bench fleet reads tools/data/sc of a checkout")
    sc_dir = Path(args.datasets or root / "tools" / "data" / "sc")
    iiwa_dir = Path(args.iiwa_datasets or root / "tools" / "data" / "fleet" / "iiwa7")
    files = sorted(p for p in sc_dir.glob("*.csv") if not p.name.startswith("."))[: args.robots]
    if len(files) < args.robots:
        raise SconeError(f"{sc_dir} has {len(files)} datasets; --robots {args.robots} needs one each")
    t0 = time.perf_counter()
    report: dict[str, Any] = {"benchmark": "fleet", "stores": {}}
    with tempfile.TemporaryDirectory(prefix="scone-fleet-") as tmp:
        backends = [b for b in args.stores.split(",") if b]
        for backend in backends:
            print(f"store trial on {backend} ...", file=sys.stderr)
            if backend == "sqlite":
                report["stores"]["sqlite"] = store_trial(
                    str(Path(tmp) / "fleet.sqlite"), files, args.outcomes, args.kill_after
                )
            elif backend == "postgresql":
                report["stores"]["postgresql"] = _postgres_trial(args, files)
            else:
                raise SconeError(f"unknown store {backend!r}; valid: {', '.join(STORES)}")
    if not args.no_learning:
        from scone_bt.embedding import load_embedder

        print("learning trial (replay of recorded executions) ...", file=sys.stderr)
        emb = load_embedder("minilm")
        models = load_models(sc_dir, iiwa_dir, emb.embed)
        report["learning"] = learning_trial(models, seeds=args.seeds, estimator=args.estimator)
        for key in ("first20_failures_cold", "first20_failures_fleet"):
            report[key] = report["learning"][key]
    report["wall_s"] = round(time.perf_counter() - t0, 1)
    report["load_average"] = [round(x, 2) for x in os.getloadavg()]
    emit_report(report, args.json, indent=1, make_parent=True, force=args.force)
    ok = all(r["lost"] == 0 and r["duplicated"] == 0 and not r["errors"] for r in report["stores"].values())
    return 0 if ok else 1


def _postgres_trial(args: argparse.Namespace, files: list[Path]) -> dict[str, Any]:
    from scone_bt.experience import redact_url

    if args.postgres:
        result = store_trial(args.postgres, files, args.outcomes, args.kill_after)
        return {"server": redact_url(args.postgres), **result}
    from scone_bt.experience.pg_server import TemporaryPostgres

    with TemporaryPostgres() as pg:
        url = pg.create_database("scone_fleet_bench")
        return {
            "server": "temporary PostgreSQL on 127.0.0.1",
            **store_trial(url, files, args.outcomes, args.kill_after),
        }


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``fleet`` to ``scone-bench``."""
    f = sub.add_parser("fleet", help="shared experience store (PostgreSQL, SQLite) and fleet learning (JSON)")
    f.add_argument("--stores", default="postgresql,sqlite", help="comma list of postgresql, sqlite")
    f.add_argument(
        "--postgres", help="an existing database URL (default: a temporary server, needs Debian's postgresql)"
    )
    f.add_argument("--robots", type=int, default=4, help="concurrent robot processes (default: 4)")
    f.add_argument("--outcomes", type=int, default=50, help="outcomes per robot (default: 50)")
    f.add_argument("--kill-after", type=int, default=20, help="SIGKILL robot 0 after this many (default: 20)")
    f.add_argument(
        "--seeds",
        type=int,
        default=DEFAULT_SEEDS,
        help=f"seeds of the learning replay (default: {DEFAULT_SEEDS})",
    )
    f.add_argument(
        "--estimator",
        default=DEFAULT_ESTIMATOR,
        help=f"κ̂ of the learning replay (default: {DEFAULT_ESTIMATOR})",
    )
    f.add_argument("--datasets", type=path_arg, help="Panda datasets (default: tools/data/sc)")
    f.add_argument("--iiwa-datasets", type=path_arg, help="iiwa7 datasets (default: tools/data/fleet/iiwa7)")
    f.add_argument("--no-learning", action="store_true", help="only the store trial")
    f.add_argument("--json", type=path_arg, help="also write the JSON report to this file")
    f.set_defaults(func=_handler)
