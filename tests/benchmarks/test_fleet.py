"""scone-bench fleet: concurrent robots (one SIGKILLed) on real PostgreSQL and SQLite stores; the learning replay."""

from __future__ import annotations

import numpy as np
import pytest

from scone_bt.benchmarks.fleet import learning_trial, load_models, replay_new_robot, store_trial
from scone_bt.experience.pg_server import TemporaryPostgres, find_postgres_bin
from scone_bt.resources import repo_root

SC = repo_root() / "tools" / "data" / "sc"


def _datasets(n: int):
    return sorted(SC.glob("p0*.csv"))[:n]


@pytest.mark.parametrize("backend", ["sqlite", "postgresql"])
def test_store_trial_loses_and_duplicates_nothing(backend, tmp_path):
    if backend == "postgresql":
        if find_postgres_bin() is None:
            pytest.skip("PostgreSQL server binaries are not installed: apt-get install postgresql")
        with TemporaryPostgres() as pg:
            result = store_trial(pg.create_database("fleet_test"), _datasets(3), per_robot=15, kill_after=6)
    else:
        result = store_trial(str(tmp_path / "fleet.sqlite"), _datasets(3), per_robot=15, kill_after=6)
    assert result["errors"] == []
    assert (result["stored"], result["lost"], result["duplicated"]) == (45, 0, 0)
    assert result["killed"]["after_acknowledged"] >= 6


def test_replay_counts_failures_only_when_the_robot_acts():
    X = np.eye(2, dtype=np.float32)
    eggs, salt = X[0], X[1]
    prior_X = np.array([eggs] * 5 + [salt] * 5)
    prior_y = np.array([False] * 5 + [True] * 5)
    stream_X = np.array([eggs, salt, eggs, salt])
    stream_y = np.array([False, True, False, False])
    informed = replay_new_robot(stream_X, stream_y, prior_X, prior_y, estimator="knn")
    assert (informed.failures, informed.asks) == (
        1,
        2,
    )  # asks for the eggs twice, acts on salt twice, fails once
    assert informed.accuracy == 0.75
    cold = replay_new_robot(stream_X, stream_y, prior_X[:0], prior_y[:0], estimator="knn")
    assert cold.failures >= 1  # with nothing learnt, it acts on the first (failing) attempt


def test_learning_trial_reports_cold_and_fleet_with_spread():
    from scone_bt.benchmarks.self_confidence import load_datasets

    vocabulary = sorted({a for d in load_datasets(SC) for a in d.actions})
    index = {a: i for i, a in enumerate(vocabulary)}

    def embed(texts):
        out = np.zeros((len(texts), len(vocabulary)), dtype=np.float32)
        out[np.arange(len(texts)), [index[t] for t in texts]] = 1.0
        return out

    models = load_models(SC, None, embed)
    subset = [m for m in models if m.profile in ("p00_nominal", "p01_weak_gripper", "p02_slippery_fingers")]
    result = learning_trial(subset, seeds=2, estimator="knn")
    for key in ("first20_failures_cold", "first20_failures_fleet", "first20_accuracy_fleet"):
        assert set(result[key]) == {"mean", "std"} and result[key]["mean"] >= 0
    assert set(result["per_model_failures_mean"]) == {m.name for m in subset}
    assert result["arm_transfer"] is None  # only Panda models given


@pytest.mark.parametrize(
    ("argv", "flag"),
    [
        (["--postgres", "notaurl", "--stores", "postgresql", "--no-learning"], "--postgres notaurl"),
        (["--robots", "0"], "--robots 0"),
        (["--robots", "-1"], "--robots -1"),
        (["--outcomes", "0"], "--outcomes 0"),
        (["--kill-after", "-1"], "--kill-after -1"),
        (["--seeds", "0"], "--seeds 0"),
        (["--stores", "sqlite,mysql"], "--stores sqlite,mysql"),
        (["--estimator", "nope"], "--estimator 'nope'"),  # was found after the store trial
        (["--no-learning", "--estimator", "knn"], "--estimator"),  # was ignored
        (["--no-learning", "--seeds", "3"], "--seeds"),
        (["--no-learning", "--seeds", "0"], "--seeds"),
        (["--no-learning", "--iiwa-datasets", "x"], "--iiwa-datasets"),
        (["--estimator", ""], "--estimator ''"),
    ],
)
def test_bad_fleet_options_are_one_line_before_any_store(argv, flag, tmp_path, monkeypatch, capsys):
    from scone_bt.benchmarks import fleet
    from scone_bt.cli.bench import main

    def never(*args, **kwargs):
        raise AssertionError("the store trial ran")

    monkeypatch.setattr(fleet, "store_trial", never)
    monkeypatch.chdir(tmp_path)
    assert main(["fleet", *argv]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith(f"scone-bench: {flag}:")
    assert list(tmp_path.iterdir()) == []  # no SQLite file named after the "URL"
