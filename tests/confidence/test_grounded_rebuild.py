"""A restarted robot rebuilds a grounded κ̂ from stored outcomes and their contexts (older rows: imputed)."""

from __future__ import annotations

import numpy as np
import pytest

from scone_bt.confidence import grounded_features, make_estimator, rebuild_estimator, training_data
from scone_bt.confidence.grounded import is_grounded
from scone_bt.experience import ExperienceStore, Outcome
from scone_bt.experience.types import CONTEXT_FIELDS, ExecutionContext

SALT = "Put salt on table"
TIGHT = ExecutionContext(0, 0.005, 2, True, 0.05, 0.12)
ROOMY = ExecutionContext(0, 0.30, 0, True, 0.05, 0.12)


class _Embedder:
    """Two fixed unit vectors: the context, not the action, decides these outcomes."""

    dim = 2

    def embed(self, texts):
        return np.array([[1.0, 0.0] if t == SALT else [0.0, 1.0] for t in texts], dtype=np.float32)


def _store(tmp_path, with_old_rows: bool = False) -> ExperienceStore:
    store = ExperienceStore(tmp_path / "exp.sqlite")
    for i in range(12):  # salt fails between neighbours and succeeds with room, alternately
        tight = i % 2 == 0
        store.append(
            Outcome(float(i), SALT, "salt", "minilm", not tight, execution=TIGHT if tight else ROOMY)
        )
    if with_old_rows:  # outcomes stored before contexts were recorded
        for i in range(3):
            store.append(Outcome(100.0 + i, SALT, "salt", "minilm", True))
    return store


@pytest.mark.parametrize("name", ["grounded-knn", "grounded-gp", "grounded-lgbm"])
def test_a_rebuilt_grounded_estimator_tells_the_contexts_apart(tmp_path, name) -> None:
    with _store(tmp_path) as store:
        est = make_estimator(name, seed=0)
        assert is_grounded(est)
        assert rebuild_estimator(est, store, _Embedder()) == 12
    tight, roomy = est.predict(grounded_features(_Embedder().embed([SALT, SALT]), [TIGHT, ROOMY]))
    assert tight < 0.5 < roomy, (tight, roomy)
    # The same outcomes without their contexts teach an ungrounded κ̂ only the average: 6 of 12.
    with ExperienceStore(tmp_path / "exp.sqlite") as store:
        plain = make_estimator("knn", seed=0)
        assert not is_grounded(plain)
        rebuild_estimator(plain, store, _Embedder())
    assert plain.predict(_Embedder().embed([SALT]))[0] == pytest.approx(0.5, abs=0.2)


def test_rows_without_a_context_rebuild_with_nan_imputed(tmp_path) -> None:
    with _store(tmp_path, with_old_rows=True) as store:
        X, y = training_data(store.outcomes(), _Embedder(), grounded=True)
        assert X.shape == (15, 2 + len(CONTEXT_FIELDS)) and np.isnan(X[12:, 2:]).all()
        # stored contexts name the fields known when they were stored: depth and lid fill came later (NaN)
        assert not np.isnan(X[:12, : 2 + 6]).any()
        est = make_estimator("grounded-knn", seed=0)
        assert rebuild_estimator(est, store, _Embedder()) == 15
    tight, roomy = est.predict(grounded_features(_Embedder().embed([SALT, SALT]), [TIGHT, ROOMY]))
    assert np.isfinite([tight, roomy]).all() and tight < roomy


def test_an_empty_store_leaves_a_grounded_estimator_at_its_prior(tmp_path) -> None:
    with ExperienceStore(tmp_path / "empty.sqlite") as store:
        est = make_estimator("grounded-gp", seed=0)
        assert rebuild_estimator(est, store, _Embedder()) == 0
    X = grounded_features(_Embedder().embed([SALT]), [TIGHT])
    assert est.predict(X)[0] == pytest.approx(0.5)
    assert training_data([], _Embedder(), grounded=True)[0].shape == (0, 2 + len(CONTEXT_FIELDS))
