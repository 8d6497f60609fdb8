"""The robot file's `grasp:` section and planner names: the settings `scone_bt.motion` reads from a robot.

They live here, below both `scone_bt.config.robot` (which validates them when a robot file is loaded) and
`scone_bt.motion` (which uses them), so that the dependency points one way: motion imports config, never the
reverse.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Mapping
from dataclasses import Field as Field_
from dataclasses import dataclass, fields, replace
from typing import Annotated, Any, Protocol

from pydantic import BaseModel, ConfigDict, Field, ValidationError, create_model

from scone_bt.config.schema import format_validation_error
from scone_bt.errors import ConfigError

__all__ = ["DEFAULT_OPENING_M", "FLAT_PACK_MAX_HEIGHT_M", "GraspParams", "PLANNERS", "flat_pack"]

DEFAULT_OPENING_M = 0.08
"""The Panda's gripper opening (robots/panda.yaml: 2 × open_position), metres: what a product's span is measured
against where no arm's own opening is given (the grasp's cost, the physical κ̂)."""

FLAT_PACK_MAX_HEIGHT_M = 0.07
"""The tallest product, metres, that the slide-and-pinch skill takes (`flat_pack`, `motion.slide`): a pack the
gripper cannot span either way is slid towards the robot and pinched by the edge that then sticks out, the fingers
closing across its thickness."""


def flat_pack(width_m: float | None, height_m: float | None, opening_m: float | None) -> bool:
    """A flat pack wider than the gripper opens (``width_m``: its narrower horizontal extent) and at most
    `FLAT_PACK_MAX_HEIGHT_M` tall: what the slide-and-pinch skill takes where it stands on a lowest tier. False
    where a size is unknown (None or NaN)."""
    if width_m is None or height_m is None or opening_m is None:
        return False
    if math.isnan(width_m) or math.isnan(height_m):
        return False
    return width_m > opening_m and height_m <= FLAT_PACK_MAX_HEIGHT_M


PLANNERS = ("RRTConnect", "RRT", "RRTstar", "PRM", "KPIECE1", "BKPIECE1", "LBKPIECE1", "BITstar", "AORRTC")
"""OMPL geometric planners selectable by name."""


class _WithGrasp(Protocol):
    """A robot configuration as `GraspParams.of` reads it (`config.robot.RobotConfig`, which imports this module)."""

    @property
    def grasp(self) -> GraspParams | None: ...


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
        slide_pinch: A flat pack wider than the gripper on a lowest tier (`flat_pack`) is slid towards the robot
            and pinched by its front edge (`motion.slide`) instead of grasped; the gate lets κ̂ decide on it
            instead of asking because it is too wide. Off unless a robot file turns it on (robots/panda.yaml does;
            the iiwa7's is not measured).
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
    tilts: tuple[float, ...] = (math.radians(25.0), math.radians(45.0))  # the robot files' tilts_deg
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
    slide_pinch: bool = False

    @classmethod
    def of(cls, robot: _WithGrasp) -> GraspParams:
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
        try:
            checked = _GraspSection.model_validate(section)
        except ValidationError as exc:
            words = functools.partial(_section_words, section=section)
            raise ConfigError(format_validation_error(exc, where, words=words)) from None
        values: dict[str, Any] = {}
        for key in checked.model_fields_set:
            value = getattr(checked, key)
            if key.endswith("_deg"):
                key = key.removesuffix("_deg")
                value = tuple(map(math.radians, value)) if isinstance(value, tuple) else math.radians(value)
            values[key] = value
        params = replace(cls(), **values)
        if (
            params.lift > params.max_lift
        ):  # the lift is clipped to [lift, max_lift]: max_lift would win silently
            raise ConfigError(
                f"{where}: grasp.lift: {params.lift:g} m is above grasp.max_lift ({params.max_lift:g} m); "
                "give a lift at most max_lift"
            )
        return params


_ANGLES = frozenset({"max_carry_tilt", "yaw_step", "tilts", "side_max_angle"})
"""Settings the file gives in degrees, under `<name>_deg`."""
_POSITIVE = frozenset({"yaw_step_deg", "max_goal_grasps", "max_goal_placements"})
"""Settings that must be above zero (a zero yaw step never ends; a goal set needs one member)."""

_BOUNDS: dict[str, tuple[float, float]] = {
    "yaw_step_deg": (1.0, 180.0),  # pi / yaw_step closing yaws are swept: 1e-9 degrees never ends
    "side_max_angle_deg": (0.0, 180.0),  # side_max_angle / yaw_step side approaches, each way
    "max_carry_tilt_deg": (0.0, 180.0),
    "tilts_deg": (0.0, 90.0),
    "max_goal_grasps": (1, 64),
    "max_goal_placements": (1, 64),
    "ik_alternatives": (0, 16),
    "path_retries": (0, 16),
    # Distances (m) and a fraction: a value beyond these is a typo (a lift of 50 m, an approach of 100 m), which
    # the planner would otherwise clip silently or turn into a false reason ("… is in the way").
    "approach": (0.0, 0.5),
    "lift": (0.0, 0.5),
    "max_lift": (0.0, 0.5),
    "retreat": (0.0, 0.5),
    "clear_radius": (0.0, 1.0),
    "max_depth": (0.0, 0.2),
    "min_clearance": (0.0, 0.2),
    "shallow_depth": (0.0, 0.2),
    "place_drop": (0.0, 0.1),
    "offsets": (0.0, 0.2),
    "offset_margin": (0.0, 0.2),
    "side_depth": (0.0, 0.2),
    "side_shallow_depth": (0.0, 0.2),
    "side_height_fraction": (0.0, 1.0),
    "side_min_height": (0.0, 0.5),
    "side_top_margin": (0.0, 0.5),
    "opening_margin": (0.0, 0.1),
    "preshape_margin": (0.0, 0.1),
}
"""Least and largest value of the settings that drive loops or are distances (for a list, of each of its values)."""
MAX_LIST_LENGTH = 16
"""Most values a list setting (tilts, offsets) takes: each one multiplies the grasp candidates."""

# strict per value (no "yes" for true, no true for 1, no "0.3" for 0.3) but a YAML list is fine for a tuple
_Number = Annotated[float, Field(strict=True, ge=0, allow_inf_nan=False)]


def _bounds(key: str) -> Any:
    """The constraints of one number of the `grasp:` key `key` (``Annotated[float, _bounds(key)]``); `Field`
    returns Any."""
    if key in _BOUNDS:
        lo, hi = _BOUNDS[key]
        return Field(strict=True, ge=lo, le=hi, allow_inf_nan=False)
    if key in _POSITIVE:
        return Field(strict=True, gt=0, allow_inf_nan=False)
    return Field(strict=True, ge=0, allow_inf_nan=False)


def _section_field(f: Field_) -> tuple[str, tuple[Any, Any]]:
    """The `grasp:` key and the pydantic type of one GraspParams field."""
    key = f"{f.name}_deg" if f.name in _ANGLES else f.name
    default = getattr(GraspParams(), f.name)
    kind: Any
    if isinstance(default, bool):
        kind = Annotated[bool, Field(strict=True)]
    elif isinstance(default, int):
        lo, hi = _BOUNDS.get(key, (1 if key in _POSITIVE else 0, None))
        kind = Annotated[int, Field(strict=True, ge=lo, le=hi)]
    elif f.name == "family_cost":
        kind = tuple[_Number, _Number, _Number]
    elif isinstance(default, tuple):
        kind = Annotated[tuple[Annotated[float, _bounds(key)], ...], Field(max_length=MAX_LIST_LENGTH)]
    else:
        kind = Annotated[float, _bounds(key)]
    return key, (kind, None)


# Any: the field types are built at run time from GraspParams, and mypy checks a **-unpacked mapping's values
# against every keyword of create_model (__config__, __base__, ...), not only against the field definitions.
_SECTION_FIELDS: dict[str, Any] = dict(_section_field(f) for f in fields(GraspParams))
_GraspSection: type[BaseModel] = create_model(
    "GraspSection", __config__=ConfigDict(extra="forbid", frozen=True), **_SECTION_FIELDS
)
"""The `grasp:` section as a pydantic model: every key optional, unknown keys refused."""


def _section_words(error: Mapping[str, Any], section: dict[str, Any]) -> str:
    """A grasp-section problem in the words the robot file's author reads: the key, what it takes, valid keys
    (`format_validation_error` puts the file before it)."""
    key = error["loc"][0] if error["loc"] else ""
    shown = key if str(key).isprintable() else repr(key)  # a key with a line break stays one line
    if error["type"] in ("extra_forbidden", "invalid_key"):  # a key that is not text is unknown too
        return f"grasp.{shown} is not a grasp setting; valid: {', '.join(sorted(_GraspSection.model_fields))}"
    raw = section[key]
    kind, value = error["type"], error.get("input")
    below_zero = isinstance(value, int | float) and value < 0
    if (
        key in _POSITIVE
        and kind in ("greater_than", "greater_than_equal")
        and isinstance(value, int | float)
        and value <= 0
    ):
        return f"grasp.{key} must be positive, got {raw!r}"
    if kind == "finite_number" or (kind == "greater_than_equal" and below_zero):
        return f"grasp.{key} must be non-negative and finite, got {raw!r}"
    if kind in ("greater_than", "greater_than_equal", "less_than_equal") and key in _BOUNDS:
        lo, hi = _BOUNDS[key]
        each = " each" if isinstance(raw, list | tuple) else ""
        return f"grasp.{key} must{each} be between {lo:g} and {hi:g}, got {raw!r}"
    if kind == "too_long":
        return f"grasp.{key} takes at most {MAX_LIST_LENGTH} values, got {len(raw)}"
    name = key.removesuffix("_deg") if key.endswith("_deg") else key
    default = getattr(GraspParams(), name)
    if key.endswith("_deg"):  # the default as the file writes it
        default = (
            tuple(round(math.degrees(v), 6) for v in default)
            if isinstance(default, tuple)
            else round(math.degrees(default), 6)
        )
    return f"grasp.{key} must be {_file_words(default)}, got {raw!r}"


def _file_words(default: object) -> str:
    """What a value of the default's type is called in a YAML file, with the default as the file writes it:
    "true or false (default true)", "a list of numbers, e.g. [25, 45]", "a number, e.g. 0.02"."""
    if isinstance(default, bool):
        return f"true or false (default {str(default).lower()})"
    if isinstance(default, tuple):
        return f"a list of numbers, e.g. [{', '.join(f'{v:.3g}' for v in default)}]"
    if isinstance(default, int):
        return f"a whole number, e.g. {default}"
    if isinstance(default, float):
        return f"a number, e.g. {default:g}"
    return f"like {default!r}"
