"""The paper's κ̂ classifiers: KNN, LGBM, random forest, SVM, MLP and XGBoost over action embeddings.

Each is refitted on all outcomes after every update (tens to hundreds of rows, so a refit takes milliseconds to
tens of milliseconds) and sized for cheap prediction of a 20-odd action scene: single-threaded, small ensembles.
scikit-learn, LightGBM and XGBoost are imported when a model is first fitted.
"""

from __future__ import annotations

import warnings
from typing import Any

import numpy as np

from scone_bt.confidence.base import ConfidenceEstimator
from scone_bt.errors import SconeError

__all__ = [
    "KNNEstimator",
    "LGBMEstimator",
    "MLPEstimator",
    "RandomForestEstimator",
    "SVMEstimator",
    "XGBEstimator",
]


def _unit(X: np.ndarray) -> np.ndarray:
    norms = np.linalg.norm(X, axis=1, keepdims=True)
    return X / np.where(norms > 0, norms, 1.0)


def _success_column(model: Any, X: np.ndarray) -> np.ndarray:
    proba = model.predict_proba(X)
    classes = list(model.classes_)
    return proba[:, classes.index(True)]  # classes are bools or 0/1; True == 1 finds either


class KNNEstimator(ConfidenceEstimator):
    """Fraction of successes among the k most cosine-similar past actions (scikit-learn's uniform KNN).

    Implemented in NumPy: a (n_query, n_seen) dot product and a partial sort, so prediction needs no library
    call overhead.
    """

    def __init__(self, name: str = "knn", seed: int = 0, k: int = 5, prior: float = 0.5) -> None:
        super().__init__(name, seed, prior)
        self.k = k
        self._unit_X = np.zeros((0, 0), dtype=np.float32)
        self._labels = np.zeros(0)

    def _fit_model(self, X: np.ndarray, y: np.ndarray) -> None:
        self._unit_X = _unit(X)
        self._labels = y.astype(np.float64)

    def _predict_model(self, X: np.ndarray) -> np.ndarray:
        sims = _unit(X) @ self._unit_X.T
        k = min(self.k, sims.shape[1])
        nearest = np.argpartition(-sims, k - 1, axis=1)[:, :k]
        return self._labels[nearest].mean(axis=1)


_FOREST_CLASS: list[type] = []


def _forest_class() -> type:
    """RandomForestClassifier that makes each tree from the forest's parameters instead of cloning a template.

    scikit-learn clones its template tree and sets its parameters through `get_params` for every tree, which
    costs about a quarter of fitting 50 trees on tens of rows. The trees are the same: the same parameters and
    the same per-tree seed, drawn from the forest's random state as `_set_random_states` draws it (a tree has
    one random_state). tests/confidence/test_estimators.py checks the probabilities against the stock forest.
    """
    if not _FOREST_CLASS:
        from sklearn.ensemble import RandomForestClassifier
        from sklearn.tree import DecisionTreeClassifier

        class _Forest(RandomForestClassifier):
            def _make_estimator(self, append: bool = True, random_state: Any = None) -> Any:
                tree = DecisionTreeClassifier(**{p: getattr(self, p) for p in self.estimator_params})
                if random_state is not None:
                    tree.random_state = random_state.randint(np.iinfo(np.int32).max)
                if append:
                    self.estimators_.append(tree)
                return tree

        _FOREST_CLASS.append(_Forest)
    return _FOREST_CLASS[0]


class RandomForestEstimator(ConfidenceEstimator):
    """scikit-learn random forest (50 trees, one thread).

    Fitting builds the trees without scikit-learn's per-tree cloning (_forest_class); prediction calls each
    fitted tree's compiled `tree_.predict` directly and averages the class fractions, which is what
    `predict_proba` computes, without its per-call thread-pool set-up (several ms for 21 rows).
    """

    def __init__(self, name: str = "rf", seed: int = 0, n_estimators: int = 50, prior: float = 0.5) -> None:
        super().__init__(name, seed, prior)
        self.n_estimators = n_estimators
        self._model: Any = None

    def _fit_model(self, X: np.ndarray, y: np.ndarray) -> None:
        self._model = _forest_class()(n_estimators=self.n_estimators, random_state=self.seed, n_jobs=1)
        self._model.fit(X, y)

    def _predict_model(self, X: np.ndarray) -> np.ndarray:
        X = np.ascontiguousarray(X, dtype=np.float32)
        column = list(self._model.classes_).index(True)
        total = np.zeros(len(X))
        for tree in self._model.estimators_:
            fractions = tree.tree_.predict(X).reshape(len(X), -1)  # (n, n_classes) for one output
            total += fractions[:, column] / fractions.sum(axis=1)
        return total / len(self._model.estimators_)


class SVMEstimator(ConfidenceEstimator):
    """RBF support-vector machine with sigmoid (Platt) calibration.

    Platt scaling needs held-out folds: with at least 3 outcomes of each class the sigmoid is fitted by
    cross-validation (CalibratedClassifierCV, up to 5 folds); below that, where cross-validated Platt scaling is
    known to invert probabilities, the probability is sigmoid(2 · decision value) (±1 at the margin ↦ 0.12/0.88).
    """

    def __init__(self, name: str = "svm", seed: int = 0, C: float = 1.0, prior: float = 0.5) -> None:
        super().__init__(name, seed, prior)
        self.C = C
        self._model: Any = None
        self._calibrated = False

    def _fit_model(self, X: np.ndarray, y: np.ndarray) -> None:
        from sklearn.calibration import CalibratedClassifierCV
        from sklearn.svm import SVC

        smallest = int(min(y.sum(), (~y).sum()))
        svc = SVC(C=self.C, kernel="rbf", gamma="scale", random_state=self.seed)
        self._calibrated = smallest >= 3
        if self._calibrated:
            self._model = CalibratedClassifierCV(svc, method="sigmoid", cv=min(5, smallest), ensemble=False)
        else:
            self._model = svc
        self._model.fit(X, y)

    def _predict_model(self, X: np.ndarray) -> np.ndarray:
        if self._calibrated:
            return _success_column(self._model, X)
        f = self._model.decision_function(X)
        return 1.0 / (1.0 + np.exp(-2.0 * f))


_MLP_BATCH = 200
"""scikit-learn's automatic MLP batch size, min(200, n_samples)."""


_MLP_EPOCHS = 100
"""Adam epochs per fit (at most; scikit-learn stops earlier when the loss stops falling)."""
_MLP_LEARNING_RATE = 3e-3
"""Adam's step size: with _MLP_EPOCHS, the step budget of scikit-learn's default (1e-3 over 300 epochs)."""


class MLPEstimator(ConfidenceEstimator):
    """scikit-learn multi-layer perceptron (one hidden layer of 64, Adam, L2 1e-3, full batch up to 200 rows).

    On tens of outcomes the loss is still falling when the epochs run out (nearly every benchmark fit ran all
    300 of scikit-learn's default), so the epochs set the cost. An Adam step moves each weight by about the step
    size whatever the gradient's scale, so 100 epochs at 3e-3 travel as far as 300 at 1e-3, for a third of the
    cost. Over the 11 self-confidence datasets Algorithm 1 AUC moved by at most 0.002 (GloVe 0.701 -> 0.703,
    MiniLM 0.674 -> 0.677), novel products likewise, leave-family-out by at most 0.01.
    """

    def __init__(self, name: str = "mlp", seed: int = 0, hidden: int = 64, prior: float = 0.5) -> None:
        super().__init__(name, seed, prior)
        self.hidden = hidden
        self._model: Any = None

    def _fit_model(self, X: np.ndarray, y: np.ndarray) -> None:
        from sklearn.exceptions import ConvergenceWarning
        from sklearn.neural_network import MLPClassifier

        # Up to 200 rows Adam's batch is the whole set, whose gradient does not depend on row order: shuffling
        # it every epoch only costs time (a third of the fit) and changes results by float rounding alone.
        self._model = MLPClassifier(
            hidden_layer_sizes=(self.hidden,),
            alpha=1e-3,
            learning_rate_init=_MLP_LEARNING_RATE,
            max_iter=_MLP_EPOCHS,
            random_state=self.seed,
            shuffle=len(X) > _MLP_BATCH,
        )
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ConvergenceWarning)  # tiny data sets stop early; still useful
            self._model.fit(X, y)

    def _predict_model(self, X: np.ndarray) -> np.ndarray:
        return _success_column(self._model, X)


_LGBM_COLSAMPLE = 0.5
"""Fraction of the input columns each LightGBM tree may split on (seeded)."""


class LGBMEstimator(ConfidenceEstimator):
    """LightGBM gradient-boosted trees (50 rounds, 7 leaves), with leaf sizes small enough for a few outcomes.

    Each tree sees a seeded half of the columns (`colsample`). With tens of rows and hundreds of embedding
    dimensions a tree finds some column that splits the few outcomes perfectly by chance; drawing the columns per
    tree is the usual regulariser for such wide data, and it halves the split search, which is nearly all of a
    fit's cost at 384-768 dimensions. Against all columns, over the 11 self-confidence datasets (Algorithm 1 AUC;
    docs/results/self_confidence.md): GloVe 0.650 -> 0.680, MiniLM 0.624 -> 0.648, one-hot 0.655 -> 0.660; the
    grounded variant within ±0.015 and its ECE 0.10-0.16 -> 0.07-0.10.

    Args:
        name: Registry name.
        seed: Seeds the booster and its column draws.
        n_estimators: Boosting rounds.
        prior: Prediction before any outcome.
        colsample: Fraction of the columns each tree may use, in (0, 1] (1: every column).
    """

    def __init__(
        self,
        name: str = "lgbm",
        seed: int = 0,
        n_estimators: int = 50,
        prior: float = 0.5,
        colsample: float = _LGBM_COLSAMPLE,
    ) -> None:
        super().__init__(name, seed, prior)
        if not 0.0 < colsample <= 1.0:
            raise SconeError(f"{name}: colsample must be in (0, 1], got {colsample}")
        self.n_estimators = n_estimators
        self.colsample = colsample
        self._model: Any = None

    def _fit_model(self, X: np.ndarray, y: np.ndarray) -> None:
        from lightgbm import LGBMClassifier

        self._model = LGBMClassifier(
            n_estimators=self.n_estimators,
            num_leaves=7,
            learning_rate=0.1,
            min_child_samples=1,
            min_data_in_bin=1,
            colsample_bytree=self.colsample,
            random_state=self.seed,
            n_jobs=1,
            verbose=-1,
        )
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)  # feature-name notices
            self._model.fit(X, y.astype(int))

    def _predict_model(self, X: np.ndarray) -> np.ndarray:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)
            return _success_column(self._model, X)


class XGBEstimator(ConfidenceEstimator):
    """XGBoost (package xgboost-cpu) gradient-boosted trees (50 rounds, depth 3, one thread)."""

    def __init__(self, name: str = "xgb", seed: int = 0, n_estimators: int = 50, prior: float = 0.5) -> None:
        super().__init__(name, seed, prior)
        self.n_estimators = n_estimators
        self._booster: Any = None

    def _fit_model(self, X: np.ndarray, y: np.ndarray) -> None:
        from xgboost import XGBClassifier

        self._booster = XGBClassifier(
            n_estimators=self.n_estimators,
            max_depth=3,
            learning_rate=0.3,
            tree_method="hist",
            n_jobs=1,
            random_state=self.seed,
            verbosity=0,
        )
        self._booster.fit(X, y.astype(int))

    def _predict_model(self, X: np.ndarray) -> np.ndarray:
        return self._booster.predict_proba(X)[:, 1]
