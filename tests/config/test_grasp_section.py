"""The robot file's `grasp:` section, checked by a pydantic model: one line naming the file, key and what it takes."""

from __future__ import annotations

import math

import pytest

from scone_bt.config.grasp import GraspParams
from scone_bt.errors import ConfigError


def test_angles_are_given_in_degrees_and_only_the_keys_given_change():
    params = GraspParams.from_section(
        {"yaw_step_deg": 45, "tilts_deg": [10, 20], "max_goal_grasps": 2}, "r.yaml"
    )
    assert params.yaw_step == pytest.approx(math.pi / 4)
    assert params.tilts == pytest.approx((math.radians(10), math.radians(20)))
    assert params.max_goal_grasps == 2 and isinstance(params.approach, float)
    assert params.approach == GraspParams().approach
    retreat = GraspParams.from_section({"retreat": 0}, "r.yaml").retreat
    assert retreat == 0.0 and isinstance(retreat, float)  # an int is a number of metres


@pytest.mark.parametrize(
    ("section", "message"),
    [
        ({"yaw_step": 0.3}, "r.yaml: grasp.yaw_step is not a grasp setting; valid: approach, clear_radius, "),
        ({7: 1}, "r.yaml: grasp.7 is not a grasp setting; valid: "),
        ({"a\nb": 1}, "r.yaml: grasp.'a\\nb' is not a grasp setting"),
        ({"approach": -0.1}, "r.yaml: grasp.approach must be non-negative and finite, got -0.1"),
        ({"approach": float("inf")}, "r.yaml: grasp.approach must be non-negative and finite, got inf"),
        ({"tilts_deg": [10, -5]}, "r.yaml: grasp.tilts_deg must be non-negative and finite, got [10, -5]"),
        ({"side_grasps": "yes"}, "r.yaml: grasp.side_grasps must be true or false (default true), got 'yes'"),
        ({"approach": "0.1"}, "r.yaml: grasp.approach must be a number, e.g. 0.1, got '0.1'"),
        ({"ik_alternatives": True}, "r.yaml: grasp.ik_alternatives must be a whole number, e.g. 0, got True"),
        (
            {"family_cost": [0, 1]},
            "r.yaml: grasp.family_cost must be a list of numbers, e.g. [0, 0.6, 0.9], got [0, 1]",
        ),
        ({"yaw_step_deg": "x"}, "r.yaml: grasp.yaw_step_deg must be a number, e.g. 22.5, got 'x'"),
        ({"yaw_step_deg": 0}, "r.yaml: grasp.yaw_step_deg must be positive, got 0"),
        ({"max_goal_placements": 0}, "r.yaml: grasp.max_goal_placements must be positive, got 0"),
        # distances beyond any kitchen arm's straight moves: typos, clipped silently or misreported before
        ({"approach": 100}, "r.yaml: grasp.approach must be between 0 and 0.5, got 100"),
        ({"lift": 50}, "r.yaml: grasp.lift must be between 0 and 0.5, got 50"),
        ({"offsets": [0.02, 35]}, "r.yaml: grasp.offsets must each be between 0 and 0.2, got [0.02, 35]"),
        (
            {"lift": 0.3},
            "r.yaml: grasp.lift: 0.3 m is above grasp.max_lift (0.25 m); give a lift at most max_lift",
        ),
    ],
)
def test_a_bad_setting_is_one_line_naming_the_key(section, message):
    with pytest.raises(ConfigError) as err:
        GraspParams.from_section(section, "r.yaml")
    assert str(err.value).startswith(message) and "\n" not in str(err.value)


def test_an_empty_or_missing_section_is_the_defaults_and_a_list_is_refused():
    assert GraspParams.from_section(None, "r.yaml") == GraspParams() == GraspParams.from_section({}, "r.yaml")
    with pytest.raises(ConfigError, match="r.yaml: grasp must be a mapping of settings"):
        GraspParams.from_section([1], "r.yaml")  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("section", "message"),
    [
        ({"yaw_step_deg": 1.0e-9}, "r.yaml: grasp.yaw_step_deg must be between 1 and 180, got 1e-09"),
        (
            {"side_max_angle_deg": 1e9},
            "r.yaml: grasp.side_max_angle_deg must be between 0 and 180, got 1000000000.0",
        ),
        ({"tilts_deg": [10, 95]}, "r.yaml: grasp.tilts_deg must each be between 0 and 90, got [10, 95]"),
        ({"max_goal_grasps": 1000}, "r.yaml: grasp.max_goal_grasps must be between 1 and 64, got 1000"),
        ({"offsets": [0.01] * 17}, "r.yaml: grasp.offsets takes at most 16 values, got 17"),
    ],
)
def test_loop_driving_settings_are_bounded(section: dict, message: str):
    with pytest.raises(ConfigError) as err:
        GraspParams.from_section(section, "r.yaml")
    assert str(err.value) == message
