"""κ̂, self-confidence: success probability of an action from its embedding, learnt online from outcomes.

    est = make_estimator("eps-knn", seed=0)
    est.update(embedder.embed_one("Put salt on table"), success=False)
    est.predict(embedder.embed(actions))        # (n,) success probabilities in [0, 1]

See base.py for the cold start, epsilon.py for ε-greedy (belief vs. decision), conformal.py for the estimator with
a stated error rate, gp.py for the GP classifier, grounded.py for κ̂ that also sees the execution context,
physical.py for the shipped tree's κ̂ (the context read relative to the arm's gripper), calibration.py for κ̂
whose scores are Platt-scaled on out-of-fold scores ("<name>-cal").
"""

from scone_bt.confidence.base import ConfidenceEstimator
from scone_bt.confidence.calibration import CalibratedEstimator
from scone_bt.confidence.conformal import ConformalKNNEstimator
from scone_bt.confidence.epsilon import EpsilonGreedy
from scone_bt.confidence.gp import GPEstimator
from scone_bt.confidence.grounded import (
    CONTEXT_FIELDS,
    ExecutionContext,
    GroundedEstimator,
    grounded_features,
)
from scone_bt.confidence.models import (
    KNNEstimator,
    LGBMEstimator,
    MLPEstimator,
    RandomForestEstimator,
    SVMEstimator,
    XGBEstimator,
)
from scone_bt.confidence.physical import PhysicalEstimator
from scone_bt.confidence.rebuild import fit_on_outcomes, rebuild_estimator, training_data
from scone_bt.confidence.registry import (
    BASE_ESTIMATORS,
    CALIBRATED_ESTIMATORS,
    ESTIMATORS,
    GROUNDED_ESTIMATORS,
    make_estimator,
)

__all__ = [
    "BASE_ESTIMATORS",
    "CALIBRATED_ESTIMATORS",
    "CONTEXT_FIELDS",
    "ESTIMATORS",
    "CalibratedEstimator",
    "ConfidenceEstimator",
    "ConformalKNNEstimator",
    "EpsilonGreedy",
    "ExecutionContext",
    "GPEstimator",
    "GROUNDED_ESTIMATORS",
    "GroundedEstimator",
    "KNNEstimator",
    "LGBMEstimator",
    "MLPEstimator",
    "PhysicalEstimator",
    "RandomForestEstimator",
    "SVMEstimator",
    "XGBEstimator",
    "grounded_features",
    "make_estimator",
    "fit_on_outcomes",
    "rebuild_estimator",
    "training_data",
]
