"""scone-bench decisions: fetch judging, the online gate replay's counts, and the same report for any --jobs."""

from __future__ import annotations

import json
import os
import shutil
import time
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from scone_bt.benchmarks.decisions import (
    GateCounts,
    _refit_is_stateless,
    _warm_up,
    judge_fetches,
    replay_gate,
)
from scone_bt.benchmarks.workers import ordered_map, process_pool
from scone_bt.errors import SconeError
from scone_bt.events import DecisionMade, StepDone
from scone_bt.gate.types import DecisionKind

SC = Path(__file__).resolve().parents[2] / "tools" / "data" / "sc"

STEPS = [("salt",), ("pasta",), ("garlic", "olive oil"), ()]


def _d(kind: str, item: str | None, step: int, need: str = "now") -> DecisionMade:
    action = f"Put {item} on table" if item else None
    return DecisionMade(1.0, step, "a step", action, 0.5, 0.5, DecisionKind(kind), need)


def test_judge_counts_wrong_ahead_never_used_and_clarify() -> None:
    done = StepDone(2.0, "a step")
    events = [
        _d("act", "salt", 1),  # right: the human's step 1 needs it
        _d("act", "garlic", 1, "later"),  # ahead: step 3 needs it
        _d("act", "honey", 1),  # wrong and never used
        done,
        done,
        _d("ask", "pasta", 3),  # wrong: step 2 (pasta) is over
        _d("ask", "olive oil", 3),  # right
        _d("clarify", None, 3),
        _d("idle", None, 4),
    ]
    out = judge_fetches(events, STEPS)
    assert out == {"decisions": 7, "fetches": 5, "wrong": 2, "ahead": 1, "never_used": 1, "clarifications": 1}


def test_gate_replay_acts_learns_and_asks_without_learning() -> None:
    vectors = {"Put a on table": np.array([1.0, 0.0], dtype=np.float32)}
    # κ̂ starts at the prior (0.5 ≥ 0.5: act); after failures it asks, and asking teaches it nothing
    counts = replay_gate(["Put a on table"] * 6, [False] * 6, vectors, "knn", seed=0)
    assert counts.decisions == 6
    assert counts.acted_failure >= 1 and counts.asked_would_fail >= 1
    assert counts.acted_success == counts.asked_would_succeed == 0
    rates = counts.rates()
    assert rates["over_step_rate"] == counts.acted_failure / 6
    assert rates["attempted_failure_rate"] == counts.acted_failure / 6
    assert rates["help_rate"] + rates["over_step_rate"] == 1.0


def test_rates_of_an_all_success_stream() -> None:
    c = GateCounts(decisions=4, acted_success=3, acted_failure=0, asked_would_succeed=1, asked_would_fail=0)
    assert c.rates()["over_ask_rate"] == 0.25 and c.rates()["attempted_failure_rate"] == 0.0


def test_warmup_is_learnt_but_not_scored() -> None:
    vectors = {"Put a on table": np.array([1.0, 0.0], dtype=np.float32)}
    counts = replay_gate(["Put a on table"] * 6, [False] * 6, vectors, "knn", seed=0, warmup=4)
    assert counts.decisions == 2
    assert counts.asked_would_fail == 2  # four failures seen: it asks


# ----- the replay's batched warm-up, and --jobs --------------------------------------------------------------

STATELESS = ("knn", "lgbm", "rf", "svm", "mlp", "xgb", "conformal", "eps-rf", "eps-conformal")


@pytest.mark.parametrize("name", STATELESS)
def test_batched_warm_up_leaves_the_estimator_as_updates_would(name: str) -> None:
    from scone_bt.confidence import make_estimator

    rng = np.random.default_rng(3)
    X = rng.normal(size=(14, 8)).astype(np.float32)
    y = np.array([True, False] * 7)
    y[:4] = True  # one class first: the online path refits nothing until a failure arrives
    batched, online = make_estimator(name, seed=5), make_estimator(name, seed=5)
    _warm_up(batched, list(X), list(y))
    for x, ok in zip(X, y, strict=True):
        online.update(x, bool(ok))
    probe = rng.normal(size=(6, 8)).astype(np.float32)
    assert batched.n_observations == online.n_observations == 14
    np.testing.assert_array_equal(batched.predict(probe), online.predict(probe))  # bit for bit
    batched.update(X[0], False)  # and they keep learning alike
    online.update(X[0], False)
    np.testing.assert_array_equal(batched.predict(probe), online.predict(probe))


@pytest.mark.parametrize("name", ["gp", "eps-gp"])
def test_the_gp_warms_up_outcome_by_outcome(name: str) -> None:
    from scone_bt.confidence import make_estimator

    # when it re-optimises its kernel depends on the sizes of its earlier refits: one fit is not the same
    assert not _refit_is_stateless(make_estimator(name, seed=0))


def _timeless(report: dict[str, Any]) -> dict[str, Any]:
    """The report without what depends on the machine and on --jobs (wall times, load, jobs)."""
    out = json.loads(json.dumps(report))
    for key in ("wall_s", "jobs", "machine"):
        out.pop(key, None)
    out["gate"].pop("replay_wall_s_by_estimator")
    out["episodes"].pop("wall_s")
    return out


def _decisions(tmp_path: Path, jobs: int) -> dict[str, Any]:
    from scone_bt.cli.bench import main

    datasets = tmp_path / "sc"
    if not datasets.exists():
        datasets.mkdir()
        for name in ("p01_weak_gripper.csv", "p07_rushed_planner.csv"):
            shutil.copy(SC / name, datasets / name)
    out = tmp_path / f"decisions_{jobs}.json"
    argv = ["decisions", "--datasets", str(datasets), "--estimators", "knn,eps-knn,conformal"]
    argv += ["--target-error-rates", "0.2", "--episodes", "2", "--recipes", "2", "--quiet"]
    assert main([*argv, "--jobs", str(jobs), "--json", str(out)]) == 0
    return json.loads(out.read_text())


@pytest.mark.slow
def test_jobs_2_reports_what_jobs_1_reports(tmp_path: Path) -> None:
    serial, parallel = _decisions(tmp_path, 1), _decisions(tmp_path, 2)
    assert serial["jobs"] == 1 and parallel["jobs"] == 2
    assert set(serial["gate"]["replay_wall_s_by_estimator"]) == {
        "knn",
        "eps-knn",
        "conformal",
        "conformal@0.2",
    }
    assert [e["seed"] for e in parallel["episodes"]["per_episode"]] == [
        0,
        1,
    ]  # episode order, not finish order
    # The report says what the episodes ran with: the benchmark's default κ̂ unless --estimator names another.
    assert {k: serial["episodes"][k] for k in ("estimator", "distractors", "relevance_threshold")} == {
        "estimator": "eps-knn",
        "distractors": 4,
        "relevance_threshold": None,
    }
    assert _timeless(parallel) == _timeless(serial)


def test_a_worker_error_is_raised_here_and_a_dead_worker_is_a_scone_error() -> None:
    from scone_bt.confidence import make_estimator

    # UnknownNameError cannot be rebuilt from its pickle: it comes back as a SconeError with its message
    with pytest.raises(SconeError, match="unknown estimator 'no-such-estimator'"), process_pool(2) as pool:
        list(ordered_map(pool, make_estimator, [("knn",), ("no-such-estimator",)]))
    with pytest.raises(SconeError, match="worker process died"), process_pool(2) as pool:
        list(ordered_map(pool, os._exit, [(3,)]))


def test_an_interrupt_terminates_the_workers_without_waiting() -> None:
    t0 = time.perf_counter()
    with pytest.raises(KeyboardInterrupt), process_pool(2) as pool:
        pool.submit(int).result()  # the workers are up
        sleeping = [pool.submit(time.sleep, 60) for _ in range(4)]
        while not sleeping[0].running():
            time.sleep(0.05)
        workers = list(pool._processes.values())  # type: ignore[union-attr]
        raise KeyboardInterrupt  # Ctrl-C while a worker is busy and more work is queued
    elapsed = time.perf_counter() - t0
    alive = [w.pid for w in workers if _running(w.pid)]
    assert elapsed < 30 and workers and not alive, (elapsed, len(workers), alive)


def _running(pid: int) -> bool:
    """Whether the process still runs (not gone, not a zombie). Not ``Process.is_alive()``: the pool's manager
    thread may reap a terminated worker first, and then ``is_alive()`` keeps answering True for it."""
    try:
        with open(f"/proc/{pid}/stat") as f:
            state = f.read().rsplit(")", 1)[1].split()[0]
    except (FileNotFoundError, ProcessLookupError):
        return False
    return state != "Z"


def test_jobs_must_be_positive(capsys: pytest.CaptureFixture[str]) -> None:
    from scone_bt.cli.bench import main

    assert main(["decisions", "--jobs", "0", "--episodes", "0"]) == 2
    assert "--jobs" in capsys.readouterr().err


@pytest.mark.parametrize("rate", ["0", "nan", "2", "inf", "-0.1"])
def test_target_error_rates_outside_the_gates_range_are_refused(
    rate: str, capsys: pytest.CaptureFixture[str]
) -> None:
    from scone_bt.cli.bench import main

    argv = ["decisions", "--episodes", "0", "--jobs", "1", "--target-error-rates", "0.1", rate]
    assert main([*argv, "--datasets", "/nonexistent"]) == 2  # refused before the datasets are read
    err = capsys.readouterr().err.strip()
    assert err == f"scone-bench: --target-error-rates {float(rate)}: must be a number in (0, 1)"


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--episodes", "-1"], "--episodes -1: must be 0 or more"),
        (["--recipes", "0"], "--recipes 0: must be 1 or more"),
        (["--jobs", "0"], "--jobs 0: must be an integer >= 1"),
    ],
)
def test_a_bad_count_names_its_option(
    argv: list[str], message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    from scone_bt.cli.bench import main

    assert main(["decisions", *argv, "--datasets", "/nonexistent"]) == 2
    assert capsys.readouterr().err.strip() == f"scone-bench: {message}"


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--episodes", "0", "--no-gate"], "--no-gate with --episodes 0: nothing to run"),
        (["--no-gate", "--estimators", "knn"], "--estimators: only the gate replay reads it"),
        (["--no-gate", "--warmup", "5"], "--warmup: only the gate replay reads it"),
        (["--episodes", "0", "--estimator", "knn"], "--estimator: only the episodes read it"),
        (["--episodes", "0", "--distractors", "2"], "--distractors: only the episodes read it"),
    ],
)
def test_an_option_no_part_of_the_run_reads_is_refused(
    argv: list[str], message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    """They were accepted and ignored (an empty report for the first)."""
    from scone_bt.cli.bench import main

    assert main(["decisions", *argv, "--jobs", "1"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"scone-bench: {message}") and "\n" not in err
