"""The robot file's `grasp:` section and planner names: the settings `scone_bt.motion` reads from a robot.

They live here, below both `scone_bt.config.robot` (which validates them when a robot file is loaded) and
`scone_bt.motion` (which uses them), so that the dependency points one way: motion imports config, never the
reverse.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace
from typing import TYPE_CHECKING, Any

from scone_bt.errors import ConfigError

if TYPE_CHECKING:
    from scone_bt.config.robot import RobotConfig

__all__ = ["GraspParams", "PLANNERS"]

PLANNERS = ("RRTConnect", "RRT", "RRTstar", "PRM", "KPIECE1", "BKPIECE1", "LBKPIECE1", "BITstar", "AORRTC")
"""OMPL geometric planners selectable by name."""


@dataclass(frozen=True)
class GraspParams:
    """Grasp generation and the distances of a pick, metres and radians.

    The robot file's `grasp:` section sets any of these (angles there in degrees, keys ending in `_deg`).

    Attributes:
        approach: Distance of the pre-grasp pose from the grasp pose, along the approach.
        lift: How far the object is lifted straight up before carrying it, at least.
        max_lift: How far at most: the lift is raised until the object clears its neighbours within
            `clear_radius`, up to this.
        clear_radius: Horizontal distance (m) of the neighbours the lifted object must clear.
        max_depth: Deepest a top grasp point goes below the object's top face.
        min_clearance: Minimum height of a top grasp point above the supporting surface.
        shallow_depth: Depth of the shallow top grasps below the top face (0: none); the finger pads still
            cover this plus their own overhang below the grasp point.
        shallow_cost: Extra cost of a shallow top grasp (less of the pads on the object).
        place_drop: Gap between the object's bottom and the table when it is released.
        retreat: How far the hand backs off upwards after releasing.
        max_carry_tilt: Largest tilt of the carried object from upright, radians.
        yaw_step: Spacing of the closing yaws swept for cylinders, radians.
        tilts: Leans (rad) of the tilted approaches, about the closing axis.
        offsets: Distances (m) a box's top grasp point is also moved off its centre, both ways along the box
            perpendicular to the closing axis (the fingers still close across the same faces).
        offset_margin: Least distance (m) between an off-centre grasp point and the box's end (the finger pads'
            half width and some room).
        offset_weight: Cost of an offset reaching the box's end (the farther from the centre of mass, the more
            the object turns in the grip).
        side_grasps: Generate side grasps at all.
        side_max_angle: Largest angle (rad) between a side approach and the direction from the robot.
        side_depth: How far past the object's near face the side grasp point goes at most.
        side_shallow_depth: A second, shallower side grasp point this far past the near face (0: none), costing
            `shallow_cost` more: the hand stays farther from what stands behind the object.
        side_height_fraction: Height of the side grasp point as a fraction of the object's height.
        side_min_height: Lowest side grasp point above the support (the palm must clear it).
        side_top_margin: Lowest distance of a side grasp point below the object's top.
        opening_margin: Room (m) the fingers need beyond the object's span.
        preshape_margin: Room (m) left beside the object on each side by the fingers pre-shaped for the
            approach (the hand opens only as far as the widest candidate needs, to fit between neighbours).
        family_cost: Cost of the top, tilted and side families (see the module docstring).
        wrist_weight: Cost per quarter turn of the wrist from the preferred yaw.
        tilt_weight: Cost per radian of tilt.
        span_weight: Cost of a span equal to the opening.
        max_goal_grasps: Feasible grasps handed to the planner together as a goal set.
        max_goal_placements: Feasible placements per grasp handed to the planner together.
        ik_alternatives: Other arm postures (IK from random seeds) tried for a grasp whose first IK answer collides
            with the scene or cannot follow the straight descent and lift.
        path_retries: OMPL queries repeated with a fresh seed (same budget) when one runs out of iterations
            before "no path" is the answer: a sampling planner's miss on one seed is not the scene's verdict.
    """

    approach: float = 0.10
    lift: float = 0.10
    max_lift: float = 0.25
    clear_radius: float = 0.25
    max_depth: float = 0.03
    min_clearance: float = 0.015
    shallow_depth: float = 0.012
    shallow_cost: float = 0.45
    place_drop: float = 0.006
    retreat: float = 0.10
    max_carry_tilt: float = 0.35
    yaw_step: float = math.pi / 8
    tilts: tuple[float, ...] = (0.45, 0.8)
    offsets: tuple[float, ...] = ()
    offset_margin: float = 0.015
    offset_weight: float = 0.5
    side_grasps: bool = True
    side_max_angle: float = math.pi / 2
    side_depth: float = 0.03
    side_shallow_depth: float = 0.0
    side_height_fraction: float = 0.6
    side_min_height: float = 0.045
    side_top_margin: float = 0.015
    opening_margin: float = 0.004
    preshape_margin: float = 0.01
    family_cost: tuple[float, float, float] = (0.0, 0.6, 0.9)
    wrist_weight: float = 0.3
    tilt_weight: float = 0.2
    span_weight: float = 0.1
    max_goal_grasps: int = 4
    max_goal_placements: int = 4
    ik_alternatives: int = 0
    path_retries: int = 1

    @classmethod
    def of(cls, robot: RobotConfig) -> GraspParams:
        """The robot file's grasp settings (validated when the file was loaded), or the defaults."""
        return robot.grasp if robot.grasp is not None else cls()

    @classmethod
    def from_section(cls, section: dict[str, Any] | None, where: str) -> GraspParams:
        """Parameters from a robot file's `grasp:` section (angles in degrees under `<name>_deg` keys).

        Raises:
            ConfigError: an unknown key or a value of the wrong type or sign, naming the key and the valid keys.
        """
        if not section:
            return cls()
        if not isinstance(section, dict):
            raise ConfigError(f"{where}: grasp must be a mapping of settings")
        valid = {f.name: f for f in fields(cls)}
        angles = {"max_carry_tilt", "yaw_step", "tilts", "side_max_angle"}
        names = sorted([*(n for n in valid if n not in angles), *(f"{n}_deg" for n in angles)])
        values: dict[str, Any] = {}
        for key, raw in section.items():
            name = key[: -len("_deg")] if key.endswith("_deg") and key[: -len("_deg")] in angles else key
            if name not in valid or (name in angles) != key.endswith("_deg"):
                shown = key if str(key).isprintable() else repr(key)  # a key with a line break stays one line
                raise ConfigError(f"{where}: grasp.{shown} is not a grasp setting; valid: {', '.join(names)}")
            default = getattr(cls(), name)
            try:
                if isinstance(default, bool):
                    if not isinstance(raw, bool):
                        raise TypeError
                    value: Any = raw
                elif isinstance(default, tuple):
                    value = tuple(float(v) for v in raw)
                    if name == "family_cost" and len(value) != 3:
                        raise TypeError
                elif isinstance(default, int):
                    if isinstance(raw, bool) or int(raw) != raw:
                        raise TypeError
                    value = int(raw)
                else:
                    value = float(raw)
            except (TypeError, ValueError):
                raise ConfigError(
                    f"{where}: grasp.{key} must be {type(default).__name__} like {default!r}, got {raw!r}"
                ) from None
            numbers = value if isinstance(value, tuple) else (value,)
            if not isinstance(value, bool) and any(not math.isfinite(v) or v < 0 for v in numbers):
                raise ConfigError(f"{where}: grasp.{key} must be non-negative and finite, got {raw!r}")
            if name in angles:
                value = (
                    tuple(math.radians(v) for v in value) if isinstance(value, tuple) else math.radians(value)
                )
            values[name] = value
        params = replace(cls(), **values)
        if params.yaw_step <= 0 or params.max_goal_grasps < 1 or params.max_goal_placements < 1:
            raise ConfigError(f"{where}: grasp.yaw_step_deg and grasp.max_goal_* must be positive")
        return params
