"""The protocols' splits, the ε-greedy rule (belief untouched, exploration only in what the robot tries), seeding."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from scone_bt.benchmarks.self_confidence.evaldata import load_eval_datasets
from scone_bt.benchmarks.self_confidence.protocols import (
    EvalOptions,
    Protocol,
    algorithm1_split,
    evaluate_calibrated_cells,
    evaluate_cell,
    evaluate_protocols,
    leave_family_out_folds,
    novel_product_rows,
    row_order,
    run_online,
)
from scone_bt.confidence import make_estimator
from scone_bt.errors import ConfigError

OPTS = EvalOptions(n_test=10, steps=(10, 20, 30), lofo_steps=(30,))


def _onehot(datasets):
    vocab = sorted({a for d in datasets for a in d.actions})
    return [np.eye(len(vocab))[[vocab.index(a) for a in d.actions]] for d in datasets]


def test_algorithm1_takes_the_first_rows_to_train_and_the_last_to_test():
    prefix, test = algorithm1_split(row_order(40, 0, 0), OPTS)
    assert prefix.tolist() == list(range(30)) and test.tolist() == list(range(30, 40))
    shuffled = row_order(40, 1, 0, seed=3)
    assert sorted(shuffled.tolist()) == list(range(40)) and shuffled.tolist() != list(range(40))
    assert row_order(40, 1, 0, seed=3).tolist() == shuffled.tolist()  # seeded
    with pytest.raises(ConfigError, match="needs 40"):
        algorithm1_split(np.arange(39), OPTS)


def test_novel_products_have_no_test_product_in_the_training_prefix(sc_data):
    (data,) = load_eval_datasets(sc_data(n_datasets=1, rows=60))
    prefix, test = algorithm1_split(row_order(len(data), 0, 0), EvalOptions(n_test=30, steps=(10, 30)))
    novel = novel_product_rows(data.objects, prefix, test)
    seen = {data.objects[i] for i in prefix}
    assert len(novel) > 0
    assert all(data.objects[i] not in seen for i in novel)
    assert set(novel) == {i for i in test if data.objects[i] not in seen}  # every such row, only those


def test_leave_family_out_never_trains_on_the_test_family(sc_data):
    (data,) = load_eval_datasets(sc_data(n_datasets=1, rows=40))
    prefix, _ = algorithm1_split(row_order(len(data), 0, 0), OPTS)
    folds = leave_family_out_folds(data.families, prefix, np.arange(len(data)))
    fams = np.array(data.families)
    assert {f.family for f in folds} == set(data.families)
    for f in folds:
        assert f.family not in set(fams[f.train]) and set(fams[f.test]) == {f.family}
        assert set(f.train) <= set(prefix)
    tested = np.concatenate([f.test for f in folds])
    assert sorted(tested.tolist()) == list(range(len(data)))  # every row tested exactly once
    unknown = ["unknown"] * len(data)
    assert leave_family_out_folds(unknown, prefix, np.arange(len(data))) == []


def test_epsilon_belief_equals_the_base_belief_on_the_same_labels():
    rng = np.random.default_rng(0)
    X, y = rng.normal(size=(60, 6)), rng.random(60) < 0.5
    for base in ("knn", "lgbm", "gp"):
        eps = make_estimator(f"eps-{base}", seed=4, epsilon=0.9, half_life=1e9).fit(X[:40], y[:40])
        plain = make_estimator(base, seed=4).fit(X[:40], y[:40])
        np.testing.assert_allclose(eps.belief(X[40:]), plain.belief(X[40:]))
        assert eps.explores(X[40:]).any()  # it would explore, yet the belief is untouched
        decide = eps.decide(X[40:], 0.5)
        assert (decide == ((plain.belief(X[40:]) >= 0.5) | eps.explores(X[40:]))).all()


def test_epsilon_zero_never_explores_and_walks_like_the_greedy_robot():
    rng = np.random.default_rng(1)
    X, y = rng.normal(size=(50, 4)), rng.random(50) < 0.4
    stream, test = np.arange(40), np.arange(40, 50)
    opts = EvalOptions(n_test=10, steps=(10, 20, 40), refit_every=5)
    eps0 = make_estimator("eps-knn", seed=2, epsilon=0.0)
    assert not eps0.explores(X).any()
    b0, beh0, got0 = run_online(eps0, stream, X, y, opts.steps, test, opts)
    bg, behg, gotg = run_online(make_estimator("knn", seed=2), stream, X, y, opts.steps, test, opts)
    assert beh0 == behg and beh0.explorations == 0 and got0.tolist() == gotg.tolist()
    for n in opts.steps:
        np.testing.assert_allclose(b0[n], bg[n])


def test_the_online_robot_learns_only_from_what_it_attempts_and_is_seeded():
    rng = np.random.default_rng(2)
    X, y = rng.normal(size=(90, 4)), np.zeros(90, dtype=bool)
    y[rng.random(90) < 0.3] = True
    stream, test = np.arange(80), np.arange(80, 90)
    opts = EvalOptions(n_test=10, steps=(10, 40, 80), refit_every=1)
    runs = [
        run_online(make_estimator("eps-knn", seed=s, epsilon=0.5), stream, X, y, opts.steps, test, opts)
        for s in (5, 5, 6)
    ]
    (_, beh, got), (_, beh_again, got_again), (_, beh_other, _) = runs
    assert beh == beh_again and got.tolist() == got_again.tolist()  # seeded
    assert beh != beh_other
    assert beh.rows == 80 and beh.attempts + beh.help_requests == 80
    assert len(got) == beh.attempts and beh.successes == int(y[got].sum())
    assert beh.explorations > 0
    assert beh.regret == beh.failures + beh.missed_successes
    greedy = run_online(make_estimator("knn", seed=5), stream, X, y, opts.steps, test, opts)[1]
    assert (
        beh.attempts > greedy.attempts
    )  # the greedy robot stops trying after its failures; ε keeps labelling


def test_evaluate_protocols_is_seeded_and_reports_every_protocol(sc_data):
    datasets = load_eval_datasets(sc_data(n_datasets=2, rows=40))
    X = _onehot(datasets)
    runs = [
        evaluate_protocols(
            "onehot", k, datasets, X, lambda s, k=k: make_estimator(k, seed=s), tuple(Protocol), OPTS
        )
        for k in ("knn", "knn", "eps-knn")
    ]
    assert runs[0] == runs[1]  # identical numbers for identical inputs
    for r in runs:
        assert set(r.scores) == set(Protocol)
        a1 = r.scores[Protocol.ALGORITHM1]
        assert a1.n_test == 20 and a1.n_datasets == 2 and len(a1.auc) == 2
        assert 0.0 <= min(a1.auc) <= max(a1.auc) <= 1.0
        assert r.scores[Protocol.NOVEL_PRODUCTS].n_test <= 20
        assert r.scores[Protocol.LEAVE_FAMILY_OUT].n_test == 80  # every row once
    assert runs[0].robot is None
    robot = runs[2].robot
    assert robot is not None and {"epsilon", "greedy", "greedy_auc"} <= set(robot)
    assert robot["epsilon"]["rows"] == robot["greedy"]["rows"] == 60


@pytest.mark.parametrize("name", ["knn", "lgbm"])
def test_a_calibrated_cell_gives_its_base_cell_from_the_same_fits(sc_data, name):
    data = load_eval_datasets(sc_data(n_datasets=1, rows=40))[0]
    X = _onehot([data])[0]
    cal, base = evaluate_calibrated_cells(
        f"{name}-cal", data, X, 0, 0, lambda s: make_estimator(f"{name}-cal", seed=s), tuple(Protocol), OPTS
    )
    alone = evaluate_cell(name, data, X, 0, 0, lambda s: make_estimator(name, seed=s), tuple(Protocol), OPTS)
    assert base.to_json() | {"wall_s": 0} == alone.to_json() | {"wall_s": 0}
    assert cal.to_json()["a1"] != base.to_json()["a1"]  # the calibrated beliefs are its own
    with pytest.raises(ConfigError):
        evaluate_calibrated_cells(name, data, X, 0, 0, lambda s: make_estimator(name, seed=s), (), OPTS)


def test_per_dataset_auc_averages_each_dataset_s_shuffles(sc_data):
    datasets = load_eval_datasets(sc_data(n_datasets=2, rows=40))
    opts = replace(OPTS, shuffles=3)
    r = evaluate_protocols(
        "onehot",
        "knn",
        datasets,
        _onehot(datasets),
        lambda s: make_estimator("knn", seed=s),
        tuple(Protocol),
        opts,
    )
    a1 = r.scores[Protocol.ALGORITHM1]
    assert len(a1.auc) == 6 and a1.groups == (0, 1, 0, 1, 0, 1)  # shuffle by shuffle, datasets in order
    auc = r.entry(Protocol.ALGORITHM1)["auc"]
    assert auc["dataset_index"] == [0, 1]
    assert auc["per_dataset"] == pytest.approx([np.mean(a1.auc[0::2]), np.mean(a1.auc[1::2])])
    assert np.mean(auc["per_dataset"]) == pytest.approx(auc["mean"])
