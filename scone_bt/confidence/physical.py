"""κ̂ from what the robot perceives, relative to its own hardware, plus what the action's name says.

A grounded estimator (it reads `grounded_features` rows: ζ(action) followed by the ExecutionContext). Instead of
standardising the raw context, it expresses it relative to the arm that acts, so that outcomes carry over between
arms through a fleet store:

- the perceived width over the gripper's opening, and how far it is past 85 % of the opening (a hinge: a product
  near or over the opening slips or cannot be grasped at all; docs/results/gate.md shows the step in the data);
- the perceived height (m), whether the target's marker was detected at all, the lowest and the top tier, the
  clearance to the nearest neighbour (capped at 15 cm: beyond that the fingers are free) and the neighbour count;
- the perceived depth (the lid's longer extent, m) and whether its lid is round (a cylinder: its fill below
  ROUND_FILL_BELOW; unknown counts as neither);
- what the heft test felt, where the action was probed (experience.felt): that the fingers lost it, the traction
  (load over grip, capped at 1, × 3) and how unsteady the load was (on a log scale: 0 at 0.1 % or less, which a
  product held fast never exceeds, 3 at 100 %; × 3).

An action not probed has felt nothing: its felt features are the mean of those of the probed rows κ̂ learnt from
(0 before any). Zeros would read it as a product held perfectly steady: after one steady success every unprobed
action rose above the probe band (the hummus on MuJoCo: the olive oil, κ̂ 0.94, was not hefted and slipped).

The unsteadiness weighs as much as the traction. A probe the hard judge set back for a sliding load teaches κ̂ a
failure; at weight 1 the L2 penalty left most of that failure to the intercept, so every product the robot then
hefted, held fast or not, looked as risky. Weights 1, 2, 3 and 5 on the development streams (tools/data/sc_probe,
docs/results/probe.md): help 0.3852, 0.3830, 0.3807, 0.3784 at α = 0.15, with failures within α + 0.02 at every
α; 3, as the traction. Also chosen there: no indicator that a probe happened, and the felt mass
(``felt_mass_kg``) stored but not read: each cost help at α = 0.15 (probed rows are the unsure ones, so the
indicator learns "probed, so risky" rather than what the fingers felt).

The action's embedding enters as its first 16 principal components, computed without labels over every action
κ̂ has been asked about (what the name tells of mass, fragility and packaging). A logistic regression (L2, C=1;
`confidence.logistic`) is refitted after every outcome on everything learnt. An action seen before gets its own
record mixed in: the prediction is (s + m·p) / (n + m) for s successes in n attempts of the identical action and m = 2.

Cold start: 0.5 with no outcome, the Laplace rate while only one class was seen (the base class).
"""

from __future__ import annotations

import numpy as np

from scone_bt.confidence.base import ConfidenceEstimator, row_key
from scone_bt.confidence.logistic import LogisticModel, fit_logistic
from scone_bt.config.grasp import DEFAULT_OPENING_M
from scone_bt.errors import SconeError
from scone_bt.experience.types import CONTEXT_FIELDS, ROUND_FILL_BELOW

__all__ = ["PhysicalEstimator", "DEFAULT_OPENING_M", "felt_features", "physical_features"]


_N_CONTEXT = len(CONTEXT_FIELDS)
_COMPONENTS = 16
_PC_WEIGHT = 0.5  # the principal components' scale beside the context features (unit-ish each)
_MEMORY = 2.0  # weight of the model's prediction against an action's own record, in attempts
_HINGE_AT = 0.85  # share of the opening from which the hinge grows
_CLEARANCE_CAP_M = 0.15
_UNSTEADY_FROM = 1e-3
"""The felt load's change (share) from which unsteadiness counts."""
_TRACTION_WEIGHT = 3.0
_UNSTEADY_WEIGHT = 3.0


def _probed(C: np.ndarray) -> np.ndarray:
    """(n,) whether each context row (CONTEXT_FIELDS order) was probed: it has what the fingers felt."""
    return np.isfinite(C[:, CONTEXT_FIELDS.index("felt_held")])


def felt_features(C: np.ndarray) -> np.ndarray:
    """(n, 3) what the heft test felt, from context rows in CONTEXT_FIELDS order (all 0 where not probed)."""

    def col(name: str) -> np.ndarray:
        return C[:, CONTEXT_FIELDS.index(name)]

    held = col("felt_held")
    probed = _probed(C)
    unsteady = np.nan_to_num(col("felt_unsteady"), nan=0.0)
    # a product held fast varies by under 0.1 %; one sliding by a percent or more (tools/data/sc_probe)
    steadiness = np.clip(np.log10(np.maximum(unsteady, 1e-9) / _UNSTEADY_FROM), 0.0, 3.0)
    return np.column_stack(
        [
            (probed & (held < 0.5)).astype(float),
            np.where(
                probed, _TRACTION_WEIGHT * np.minimum(np.nan_to_num(col("felt_traction"), nan=0.0), 1.0), 0.0
            ),
            np.where(probed, _UNSTEADY_WEIGHT * steadiness, 0.0),
        ]
    )


def physical_features(context: np.ndarray, opening_m: float) -> np.ndarray:
    """(n, 13) hardware-relative features of context rows in CONTEXT_FIELDS order (NaN: unknown): what the camera
    perceived, then what the heft test felt (`felt_features`)."""
    C = np.atleast_2d(np.asarray(context, dtype=np.float64))

    def col(name: str) -> np.ndarray:
        return C[:, CONTEXT_FIELDS.index(name)]

    tier, clearance, neighbours, detected = (
        col(n) for n in ("shelf_tier", "clearance_m", "neighbours", "detected")
    )
    width, height = col("detected_width_m"), col("detected_height_m")
    depth, fill = col("detected_depth_m"), col("detected_fill")
    ratio = np.nan_to_num(width / opening_m, nan=0.0)
    return np.column_stack(
        [
            ratio,
            10.0 * np.maximum(0.0, ratio - _HINGE_AT),
            5.0 * np.nan_to_num(height, nan=0.0),
            np.nan_to_num(detected, nan=0.0),
            (tier == 0).astype(float),
            (tier == 2).astype(float),
            10.0 * np.minimum(np.nan_to_num(clearance, nan=_CLEARANCE_CAP_M), _CLEARANCE_CAP_M),
            np.nan_to_num(neighbours, nan=0.0) / 3.0,
            5.0 * np.nan_to_num(depth, nan=0.0),
            (np.nan_to_num(fill, nan=1.0) < ROUND_FILL_BELOW).astype(float),
            felt_features(C),
        ]
    )


class PhysicalEstimator(ConfidenceEstimator):
    """Logistic κ̂ over hardware-relative context and the embedding's principal components (module docstring).

    Args:
        name: Registry name.
        seed: Seeds the solver (it is deterministic; kept for a uniform constructor).
        prior: Prediction before any outcome.
        gripper_opening_m: The acting arm's gripper opening, metres.
        C: Inverse L2 strength of the logistic regression.
    """

    grounded = True  # callers pass grounded_features rows (see grounded.is_grounded)

    def __init__(
        self,
        name: str = "physical",
        seed: int = 0,
        prior: float = 0.5,
        gripper_opening_m: float = DEFAULT_OPENING_M,
        C: float = 1.0,
    ) -> None:
        from scone_bt.config.robot import MAX_GRIPPER_OPENING_M

        if not 0.0 < gripper_opening_m < MAX_GRIPPER_OPENING_M:
            raise SconeError(
                f"gripper_opening_m must be in (0, {MAX_GRIPPER_OPENING_M:g}) metres, got {gripper_opening_m}"
            )
        super().__init__(name, seed, prior)
        self.opening_m = float(gripper_opening_m)
        self.C = float(C)
        self._asked: dict[bytes, np.ndarray] = {}  # every embedding κ̂ was asked about (no labels)
        self._mean = np.zeros(0)
        self._axes = np.zeros((0, 0))
        self._scale = 1.0
        self._model: LogisticModel | None = None
        self._record: dict[bytes, tuple[int, int]] = {}
        # the mean of felt_features over the probed rows learnt from (None: none yet), read for unprobed rows
        self._felt_mean: np.ndarray | None = None

    # ----------------------------------------------------------------------------------------- features
    def _split(self, X: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        if X.shape[1] <= _N_CONTEXT:
            raise SconeError(
                f"{self.name}: rows need an embedding plus {_N_CONTEXT} context values, got {X.shape[1]} "
                "columns (build them with grounded_features)"
            )
        return X[:, :-_N_CONTEXT].astype(np.float64), X[:, -_N_CONTEXT:].astype(np.float64)

    def _remember(self, E: np.ndarray) -> None:
        for e in E:
            self._asked.setdefault(row_key(e), e)

    def _fit_components(self) -> None:
        """Principal axes of every embedding asked about or learnt from (unsupervised)."""
        pool = np.stack(list(self._asked.values()))
        self._mean = pool.mean(axis=0)
        k = min(_COMPONENTS, len(pool) - 1, pool.shape[1])
        if k < 1:
            self._axes = np.zeros((0, pool.shape[1]))
            return
        _, _, vt = np.linalg.svd(pool - self._mean, full_matrices=False)
        self._axes = vt[:k]
        first = (pool - self._mean) @ self._axes[0]
        self._scale = float(first.std()) or 1.0

    def transform(self, X: np.ndarray) -> np.ndarray:
        """Model inputs: the hardware-relative context features, then the weighted principal components."""
        E, C = self._split(np.atleast_2d(X))
        pcs = np.zeros((len(E), _COMPONENTS))
        if len(self._axes):
            pcs[:, : len(self._axes)] = (E - self._mean) @ self._axes.T / self._scale
        P = physical_features(C, self.opening_m)
        if self._felt_mean is not None:  # unprobed: what a probe would feel is unknown, not "held fast"
            P[~_probed(C), -len(self._felt_mean) :] = self._felt_mean
        return np.hstack([P, _PC_WEIGHT * pcs])

    # ----------------------------------------------------------------------------------------- model
    def predict(self, X: np.ndarray) -> np.ndarray:
        X = np.atleast_2d(np.asarray(X, dtype=np.float32))
        if len(X):
            self._remember(self._split(X)[0].astype(np.float32))
        return super().predict(X)

    def _fit_model(self, X: np.ndarray, y: np.ndarray) -> None:
        E, C = self._split(X)
        self._remember(E.astype(np.float32))
        self._fit_components()
        record: dict[bytes, tuple[int, int]] = {}
        for e, ok in zip(E.astype(np.float32), y, strict=True):
            s, n = record.get(row_key(e), (0, 0))
            record[row_key(e)] = (s + int(ok), n + 1)
        self._record = record
        probed = _probed(C)
        self._felt_mean = felt_features(C[probed]).mean(axis=0) if probed.any() else None
        self._model = fit_logistic(self.transform(X), y, C=self.C)

    def _predict_model(self, X: np.ndarray) -> np.ndarray:
        assert self._model is not None
        p = self._model.predict_proba(self.transform(X))
        E, _ = self._split(X)
        for i, e in enumerate(E.astype(np.float32)):
            s, n = self._record.get(row_key(e), (0, 0))
            if n:
                p[i] = (s + _MEMORY * p[i]) / (n + _MEMORY)
        return p
