"""Grid scheduling (longest cells first, results back in task order) and the MLP's full-batch setting."""

from __future__ import annotations

import numpy as np

from scone_bt.benchmarks.self_confidence.evaluate import cell_cost, schedule_longest_first
from scone_bt.confidence import make_estimator


def test_expensive_cells_go_first_and_every_cell_once():
    dims = {"mpnet": 768, "onehot": 600}
    tasks = [
        (e, k, 0, d) for e in dims for k in ("knn", "mlp", "grounded-lgbm-cal", "eps-rf") for d in range(3)
    ]
    order = schedule_longest_first(tasks, dims)
    assert sorted(order) == list(range(len(tasks)))
    costs = [cell_cost(tasks[i], dims) for i in order]
    assert costs == sorted(costs, reverse=True)
    assert tasks[order[0]][1] == "grounded-lgbm-cal" and tasks[order[-1]][1] == "knn"
    # Undoing the permutation gives the task order back (what run_evaluate aggregates).
    ran = [tasks[i] for i in order]
    assert [ran[k] for k in np.argsort(order)] == tasks


def test_mlp_reshuffles_only_when_the_batch_is_not_the_whole_set():
    rng = np.random.default_rng(0)
    for n, shuffled in ((60, False), (260, True)):
        X = rng.standard_normal((n, 4)).astype(np.float32)
        est = make_estimator("mlp", seed=0).fit(X, X[:, 0] > 0)
        assert est._model.shuffle is shuffled
