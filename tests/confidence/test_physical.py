"""κ̂ "physical": one wide failure transfers through the width over the gripper opening to another wide product
with another embedding; the width is read relative to the opening; cold predictions are the prior; rows without
the context are refused in one line."""

from __future__ import annotations

import numpy as np
import pytest

from scone_bt.confidence import make_estimator
from scone_bt.confidence.physical import DEFAULT_OPENING_M, PhysicalEstimator, physical_features
from scone_bt.errors import SconeError
from scone_bt.experience.types import FELT_FIELDS

_DIM = 8


def _row(embedding: np.ndarray, width_m: float) -> np.ndarray:
    """ζ followed by a context (tier 1, 10 cm clearance, one neighbour, detected, this width, 12 cm tall, depth
    and lid shape not measured, not probed)."""
    unfelt = [np.nan] * len(FELT_FIELDS)
    return np.concatenate([embedding, [1.0, 0.10, 1.0, 1.0, width_m, 0.12, np.nan, np.nan, *unfelt]]).astype(
        np.float32
    )


def _embeddings(seed: int = 0) -> np.ndarray:
    return np.random.default_rng(seed).normal(size=(6, _DIM)).astype(np.float32)


def test_one_wide_failure_transfers_to_another_wide_product_through_the_width() -> None:
    E = _embeddings()
    kappa = PhysicalEstimator()
    for e in E[:3]:
        kappa.update(_row(e, 0.04), True)  # three narrow products succeed
    kappa.update(_row(E[3], 0.11), False)  # one wide product fails
    # The queries' embeddings are the opposite way round: the new wide product's name is close to a narrow
    # success, the new narrow product's close to the wide failure; only the width can rank them right.
    wide = _row(E[0] + 0.05 * E[4], 0.105)
    narrow = _row(E[3] + 0.05 * E[5], 0.045)
    p_wide, p_narrow = kappa.predict(np.stack([wide, narrow]))
    assert p_wide < 0.5 < p_narrow


def test_the_same_width_is_wide_for_a_6_cm_opening_and_not_for_10_cm() -> None:
    context = np.array([[1.0, 0.10, 1.0, 1.0, 0.08, 0.12, 0.08, 0.78] + [np.nan] * len(FELT_FIELDS)])
    small, large = physical_features(context, 0.06)[0], physical_features(context, 0.10)[0]
    assert small[0] == pytest.approx(0.08 / 0.06) and large[0] == pytest.approx(0.8)
    assert small[1] > 0.0 and large[1] == 0.0  # the hinge past 85 % of the opening

    E = _embeddings(1)
    predictions = {}
    for opening in (0.06, 0.10):
        kappa = make_estimator("physical", gripper_opening_m=opening)
        assert isinstance(kappa, PhysicalEstimator) and kappa.opening_m == opening
        for i, (width, ok) in enumerate([(0.03, True), (0.035, True), (0.04, True), (0.12, False)]):
            kappa.update(_row(E[i], width), ok)
        predictions[opening] = float(kappa.predict(_row(E[4], 0.08)[None])[0])
    # trained on the same widths, an 8 cm product is riskier for the arm with the 6 cm opening
    assert predictions[0.06] < predictions[0.10] - 0.1


@pytest.mark.parametrize("prior", [0.5, 0.3])
def test_cold_predictions_are_the_prior(prior: float) -> None:
    kappa = PhysicalEstimator(prior=prior)
    rows = np.stack(
        [_row(e, w) for e, w in zip(_embeddings(), [0.03, 0.06, 0.09, 0.12, 0.2, 0.01], strict=True)]
    )
    assert kappa.n_observations == 0
    assert kappa.predict(rows) == pytest.approx(np.full(6, prior))
    assert PhysicalEstimator().prior == 0.5
    from scone_bt.config import load_robot

    assert pytest.approx(load_robot("panda").gripper.opening_m) == DEFAULT_OPENING_M  # the shipped arm's


@pytest.mark.parametrize("columns", [3, 12])
def test_rows_without_the_twelve_context_columns_are_refused_in_one_line(columns: int) -> None:
    kappa = PhysicalEstimator()
    with pytest.raises(SconeError) as err:
        kappa.predict(np.zeros((2, columns), dtype=np.float32))
    message = str(err.value)
    assert "\n" not in message and "12 context values" in message and "grounded_features" in message


def test_a_bad_gripper_opening_is_refused_in_one_line() -> None:
    with pytest.raises(SconeError, match=r"^gripper_opening_m must be in \(0, 1\) metres, got 0\.0$"):
        PhysicalEstimator(gripper_opening_m=0.0)


def _probed_row(embedding: np.ndarray, unsteady: float) -> np.ndarray:
    """`_row` (a 5 cm product) after a probe that held it with traction 0.1 and this unsteadiness."""
    row = _row(embedding, 0.05)
    row[-len(FELT_FIELDS) :] = [1.0, 0.1, unsteady, 0.5]
    return row


def test_a_row_not_probed_is_not_read_as_held_fast() -> None:
    """What a probe would feel of an action not probed is unknown: κ̂ reads the average of what its probes felt,
    not the zeros of a product held perfectly steady (the hummus on MuJoCo: after one set-back for a sliding load
    and one steady success, the olive oil, not probed, got κ̂ 0.94, above the probe band, and was dropped)."""
    E = _embeddings(2)
    kappa = PhysicalEstimator()
    kappa.update(_probed_row(E[0], 0.3), False)  # set back: the load slid
    kappa.update(_probed_row(E[1], 0.0), True)  # held fast and carried
    steady, sliding, unprobed = kappa.predict(
        np.stack([_probed_row(E[2], 0.0), _probed_row(E[2], 0.3), _row(E[2], 0.05)])
    )
    assert sliding < unprobed < steady
    assert abs(unprobed - 0.5) < abs(steady - 0.5)  # unknown reads as the probes' average, near the prior
