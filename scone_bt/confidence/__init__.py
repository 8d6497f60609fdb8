"""κ̂, self-confidence: success probability of an action from its embedding, learnt online from outcomes.

    est = make_estimator("eps-knn", seed=0)
    est.update(embedder.embed_one("Put salt on table"), success=False)
    est.predict(embedder.embed(actions))        # (n,) success probabilities in [0, 1]

See base.py for the cold start, epsilon.py for ε-greedy, conformal.py for the estimator with a stated error rate.
"""

from scone_bt.confidence.base import ConfidenceEstimator
from scone_bt.confidence.conformal import ConformalKNNEstimator
from scone_bt.confidence.epsilon import EpsilonGreedy
from scone_bt.confidence.models import (
    KNNEstimator,
    LGBMEstimator,
    MLPEstimator,
    RandomForestEstimator,
    SVMEstimator,
    XGBEstimator,
)
from scone_bt.confidence.rebuild import rebuild_estimator, training_data
from scone_bt.confidence.registry import BASE_ESTIMATORS, ESTIMATORS, make_estimator

__all__ = [
    "BASE_ESTIMATORS",
    "ESTIMATORS",
    "ConfidenceEstimator",
    "ConformalKNNEstimator",
    "EpsilonGreedy",
    "KNNEstimator",
    "LGBMEstimator",
    "MLPEstimator",
    "RandomForestEstimator",
    "SVMEstimator",
    "XGBEstimator",
    "make_estimator",
    "rebuild_estimator",
    "training_data",
]
