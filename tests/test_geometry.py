"""wrap_angle: the one angle wrap of the stages, at its boundaries and bit for bit the formulas it replaced."""

from __future__ import annotations

import math

import numpy as np
import pytest

from scone_bt.geometry import wrap_angle


@pytest.mark.parametrize(
    ("angle", "wrapped"),
    [
        (0.0, 0.0),
        (math.pi, -math.pi),  # the interval is half open: +pi becomes -pi
        (-math.pi, -math.pi),
        (3 * math.pi, -math.pi),
        (math.pi / 2, math.pi / 2),
        (-math.pi / 2, -math.pi / 2),
        (2 * math.pi, 0.0),
        (-2 * math.pi, 0.0),
    ],
)
def test_full_turn_boundaries(angle, wrapped):
    assert wrap_angle(angle) == pytest.approx(wrapped, abs=1e-12)


@pytest.mark.parametrize(
    ("angle", "wrapped"),
    [
        (0.0, 0.0),
        (math.pi / 2, -math.pi / 2),
        (-math.pi / 2, -math.pi / 2),
        (math.pi, 0.0),
        (0.75 * math.pi, -0.25 * math.pi),
    ],
)
def test_half_turn_boundaries(angle, wrapped):
    assert wrap_angle(angle, np.pi) == pytest.approx(wrapped, abs=1e-12)


def test_the_result_lies_in_the_half_open_interval():
    angles = np.random.default_rng(0).uniform(-50.0, 50.0, 10_000)
    for period in (2 * np.pi, np.pi):
        out = wrap_angle(angles, period)
        assert np.all(out >= -period / 2) and np.all(out < period / 2)
        np.testing.assert_allclose(
            np.cos(out * 2 * np.pi / period), np.cos(angles * 2 * np.pi / period), atol=1e-9
        )


def test_identical_to_the_formulas_it_replaced():
    angles = np.random.default_rng(1).uniform(-20.0, 20.0, 1_000)
    assert np.array_equal(wrap_angle(angles), (angles + np.pi) % (2 * np.pi) - np.pi)
    assert np.array_equal(wrap_angle(angles, np.pi), (angles + np.pi / 2) % np.pi - np.pi / 2)
    for a in angles[:100].tolist():  # plain floats stay plain floats, same bits
        assert wrap_angle(a) == (a + np.pi) % (2 * np.pi) - np.pi
        assert type(wrap_angle(a)) is float


def test_the_quaternion_helpers_agree_with_scipy() -> None:
    import numpy as np
    from scipy.spatial.transform import Rotation

    from scone_bt.geometry import quat_inverse, quat_multiply, quat_rotate

    rng = np.random.default_rng(0)
    for _ in range(50):
        a, b = Rotation.random(random_state=rng), Rotation.random(random_state=rng)
        v = rng.normal(size=3)
        product = Rotation.from_quat(quat_multiply(a.as_quat(), b.as_quat()))
        np.testing.assert_allclose(product.as_matrix(), (a * b).as_matrix(), atol=1e-12)
        np.testing.assert_allclose(quat_rotate(a.as_quat(), v), a.apply(v), atol=1e-12)
        np.testing.assert_allclose(quat_rotate(quat_inverse(a.as_quat()), a.apply(v)), v, atol=1e-12)
