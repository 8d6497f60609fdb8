"""The robot file (robots/<name>.yaml): URDF, frames, gripper, limits and planner settings."""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any, Literal, TypeVar, cast

from pydantic import Field, field_validator, model_validator

from scone_bt.config.grasp import PLANNERS, GraspParams
from scone_bt.config.schema import FiniteFloat, NonNegativeFloat, PositiveFloat, StrictModel, validate
from scone_bt.config.yaml_io import read_yaml
from scone_bt.errors import ConfigError, UnknownNameError
from scone_bt.resources import resolve_file

if TYPE_CHECKING:
    from _typeshed import DataclassInstance

__all__ = [
    "CAMERA_SHAPES",
    "GripperSpec",
    "LimitsSpec",
    "PlannerSpec",
    "ControlSpec",
    "RobotConfig",
    "RobotFile",
    "load_robot",
    "resolve_urdf",
]


@dataclass(frozen=True)
class GripperSpec:
    """Parallel gripper. Positions in metres per finger, force in newtons per finger."""

    joints: tuple[str, ...]
    open_position: float
    closed_position: float
    max_force: float
    finger_friction: float

    @property
    def opening_m(self) -> float:
        """How wide the fingers open in total, metres (from closed to ``open_position``, both fingers)."""
        return 2.0 * (self.open_position - self.closed_position)


@dataclass(frozen=True)
class LimitsSpec:
    """Per-joint limits (rad/s, rad/s², rad/s³) and the scales the robot runs at."""

    velocity: tuple[float, ...]
    acceleration: tuple[float, ...]
    jerk: tuple[float, ...]
    velocity_scale: float = 1.0
    acceleration_scale: float = 1.0
    jerk_scale: float = 1.0


@dataclass(frozen=True)
class PlannerSpec:
    """OMPL planner name, time limit (s), path simplification and seed; `backend`: who plans the free-space
    queries, "ompl" or "vamp" (VAMP, built by `make vamp`, for the arms it has a model of, checked with the mesh
    checker; OMPL where it has no model, is not installed, finds no path or its path fails that check)."""

    name: str = "RRTConnect"
    time_limit_s: float = 1.0
    simplify: bool = True
    rng_seed: int = 0
    backend: str = "ompl"


CAMERA_SHAPES = ("visual", "collision")
"""What the kitchen's cameras render of the robot: its URDF's visual meshes, or its collision shapes."""

DEFAULT_CAMERA_SHAPES: Literal["visual", "collision"] = "visual"

DEFAULT_PHYSICS_HZ = 120.0
"""Physics steps per simulated second when a robot file does not say (the simulator's step is 1 / physics_hz)."""

DEFAULT_SOLVER_RESIDUAL = 1e-7
"""The constraint solver's residual threshold when a robot file does not say: PyBullet's default."""


@dataclass(frozen=True)
class ControlSpec:
    """Position control at rate_hz; gains and forces as PyBullet's POSITION_CONTROL takes them.

    physics_hz is the simulator's step rate for this arm: the coarsest at which its seeded pick-and-places end as
    at 240 Hz (`scone-bench physics`; a grasp's stability depends on the gripper). solver_residual: the constraint
    solver stops iterating once its residual is below this (PyBullet's `solverResidualThreshold`); chosen the
    same way.
    """

    rate_hz: float = 240.0
    position_gain: float = 0.3
    max_joint_force: float = 87.0
    physics_hz: float = DEFAULT_PHYSICS_HZ
    solver_residual: float = DEFAULT_SOLVER_RESIDUAL


@dataclass(frozen=True)
class RobotConfig:
    name: str
    urdf: Path
    base_position: tuple[float, float, float]
    arm_joints: tuple[str, ...]
    end_effector_frame: str
    home: tuple[float, ...]
    gripper: GripperSpec
    limits: LimitsSpec
    planner: PlannerSpec
    control: ControlSpec
    source: Path
    raw: dict[str, Any] = field(default_factory=dict, compare=False, repr=False)
    disabled_collisions: tuple[tuple[str, str], ...] = ()
    """Link pairs never checked for self-collision besides adjacent links (an SRDF's list), from
    `collision.disabled_pairs`."""
    hand_links: tuple[str, ...] = ()
    """Links that count as the hand in collision reports besides the gripper's own (`collision.hand_links`)."""
    grasp: GraspParams | None = None
    """The `grasp:` section, validated at load (None: the motion stage's defaults)."""
    camera_shapes: str = DEFAULT_CAMERA_SHAPES
    """What the simulated cameras render of the robot (one of CAMERA_SHAPES). "collision" renders its collision
    shapes instead of the visual meshes: the physics is the same, only images with the arm in view differ
    (the renderer transforms every triangle of every body on each call, in view or not)."""

    @property
    def dof(self) -> int:
        return len(self.arm_joints)


def _pybullet_data_dir(relative_to: Path) -> Path:
    """pybullet_data's folder, found without importing it (config never imports the simulator's packages)."""
    import importlib.util

    found = importlib.util.find_spec("pybullet_data")
    if found is None or not found.submodule_search_locations:
        raise ConfigError(f"{relative_to}: a pybullet_data:// URDF needs the pybullet package installed")
    return Path(next(iter(found.submodule_search_locations)))


def resolve_urdf(spec: str, relative_to: Path) -> Path:
    """Resolve 'pybullet_data://x', 'example_robot_data://x', absolute or file-relative URDF paths."""
    if spec.startswith("pybullet_data://"):
        path = _pybullet_data_dir(relative_to) / spec.removeprefix("pybullet_data://")
    else:
        path = Path(spec)
        if not path.is_absolute():
            path = (relative_to.parent / path).resolve()
    if not path.is_file():
        raise ConfigError(f"{relative_to}: URDF not found: {spec} (resolved to {path})")
    return path


_Name = Annotated[str, Field(min_length=1)]
_Pair = Annotated[list[_Name], Field(min_length=2, max_length=2)]
_Scale = Annotated[float, Field(gt=0, le=1, allow_inf_nan=False)]


MAX_GRIPPER_OPENING_M = 1.0
"""A gripper's full opening is below this (metres); the robot file and the physical κ̂ check it."""


class _GripperModel(StrictModel):
    joints: Annotated[list[_Name], Field(min_length=1)]
    open_position: NonNegativeFloat
    closed_position: NonNegativeFloat = 0.0
    max_force: PositiveFloat
    finger_friction: NonNegativeFloat = 1.0

    @model_validator(mode="after")
    def _opens(self) -> _GripperModel:
        if len(set(self.joints)) != len(self.joints):
            raise ValueError("joints: a joint is listed twice (each finger's joint once)")
        if self.open_position <= self.closed_position:
            raise ValueError(
                f"open_position ({self.open_position}) must be larger than closed_position ({self.closed_position})"
            )
        opening = 2.0 * (self.open_position - self.closed_position)
        if opening >= MAX_GRIPPER_OPENING_M:  # each finger's travel counts twice: a typo in metres
            raise ValueError(
                f"open_position ({self.open_position}) and closed_position ({self.closed_position}) open the "
                f"gripper {opening:g} m (2 × their difference), not below {MAX_GRIPPER_OPENING_M:g} m"
            )
        return self


class _LimitsModel(StrictModel):
    velocity: list[PositiveFloat]
    acceleration: list[PositiveFloat]
    jerk: list[PositiveFloat]
    velocity_scale: _Scale = 1.0
    acceleration_scale: _Scale = 1.0
    jerk_scale: _Scale = 1.0


class _PlannerModel(StrictModel):
    name: str = PlannerSpec.name
    time_limit_s: Annotated[float, Field(gt=0, le=600, allow_inf_nan=False)] = PlannerSpec.time_limit_s
    simplify: bool = PlannerSpec.simplify
    rng_seed: Annotated[int, Field(ge=0, le=2**32 - 1)] = PlannerSpec.rng_seed
    backend: Literal["ompl", "vamp"] = "ompl"

    @field_validator("name")
    @classmethod
    def _known_planner(cls, name: str) -> str:
        if name not in PLANNERS:
            raise ValueError(f"unknown planner {name!r}; valid: {', '.join(PLANNERS)}")
        return name


class _ControlModel(StrictModel):
    rate_hz: Annotated[float, Field(gt=0, le=10_000, allow_inf_nan=False)] = 240.0
    position_gain: Annotated[float, Field(gt=0, le=1, allow_inf_nan=False)] = 0.3
    max_joint_force: PositiveFloat = 87.0
    physics_hz: Annotated[float, Field(ge=30, le=10_000, allow_inf_nan=False)] = DEFAULT_PHYSICS_HZ
    solver_residual: Annotated[float, Field(gt=0, le=1e-2, allow_inf_nan=False)] = DEFAULT_SOLVER_RESIDUAL


class _CollisionModel(StrictModel):
    disabled_pairs: list[_Pair] = []
    hand_links: list[_Name] = []


class RobotFile(StrictModel):
    """The schema of robots/<name>.yaml (units: metres, radians, seconds, newtons)."""

    name: _Name
    urdf: _Name
    base_position: Annotated[list[FiniteFloat], Field(min_length=3, max_length=3)] = [0.0, 0.0, 0.0]
    arm_joints: Annotated[list[_Name], Field(min_length=1, max_length=32)]
    end_effector_frame: _Name
    home: list[FiniteFloat]
    gripper: _GripperModel
    limits: _LimitsModel
    planner: _PlannerModel = _PlannerModel()
    control: _ControlModel = _ControlModel()
    collision: _CollisionModel = _CollisionModel()
    camera_shapes: Literal["visual", "collision"] = DEFAULT_CAMERA_SHAPES
    grasp: dict[str, Any] = {}  # checked by scone_bt.config.grasp.GraspParams.from_section in load_robot

    @model_validator(mode="after")
    def _one_value_per_joint(self) -> RobotFile:
        n = len(self.arm_joints)
        if len(set(self.arm_joints)) != n:
            raise ValueError("arm_joints: a joint is listed twice")
        for key, values in (
            ("home", self.home),
            ("limits.velocity", self.limits.velocity),
            ("limits.acceleration", self.limits.acceleration),
            ("limits.jerk", self.limits.jerk),
        ):
            if len(values) != n:
                # The lists agree with one another and not with arm_joints: then arm_joints is the odd one out.
                lists = (self.home, self.limits.velocity, self.limits.acceleration, self.limits.jerk)
                if len({len(v) for v in lists}) == 1:
                    raise ValueError(
                        f"arm_joints: {n} joints listed, but home and limits give {len(values)} values each; "
                        f"list one joint per value"
                    )
                raise ValueError(f"{key}: expected {n} numbers (one per arm joint), got {len(values)}")
        for i, (joint, q) in enumerate(zip(self.arm_joints, self.home, strict=True)):
            if abs(q) > MAX_HOME_RAD:
                raise ValueError(
                    f"home[{i}] ({joint}): {q:g} rad is outside [-{MAX_HOME_RAD:.4f}, {MAX_HOME_RAD:.4f}]"
                )
        return self


MAX_HOME_RAD = 2 * math.pi
"""Largest home angle (rad) of any arm joint; the URDF's own limits are checked at load (`_check_home`)."""


def _urdf_root(urdf: Path, where: str) -> Any:
    """The URDF's XML root element, read once for the checks below; ConfigError (one line, naming the robot file
    and the URDF) if it is not a ``<robot>`` XML document: the simulators' own errors for it come with lines of
    their parsers' output."""
    import xml.etree.ElementTree as ET

    try:
        root = ET.parse(urdf).getroot()  # noqa: S314 - the user's own robot description
    except ET.ParseError as exc:
        raise ConfigError(f"{where}: urdf: {urdf} is not valid XML ({exc})") from None
    except OSError as exc:
        raise ConfigError(f"{where}: urdf: cannot read {urdf} ({exc.strerror or exc})") from None
    for (
        element
    ) in root.iter():  # a default namespace (<robot xmlns="...">, as Drake writes) names nothing here
        if isinstance(element.tag, str):
            element.tag = element.tag.rpartition("}")[2]
    if root.tag != "robot":
        raise ConfigError(
            f"{where}: urdf: {urdf} is not a URDF (its root element is <{root.tag}>, not <robot>)"
        )
    return root


def _urdf_limits(root: Any) -> dict[str, tuple[float, float]]:
    """(lower, upper) of each limited revolute or prismatic joint of a URDF's root element."""
    out: dict[str, tuple[float, float]] = {}
    for joint in root.iter("joint"):
        limit = joint.find("limit")
        if joint.get("type") not in ("revolute", "prismatic") or limit is None:
            continue
        try:
            out[str(joint.get("name"))] = (float(limit.get("lower", "0")), float(limit.get("upper", "0")))
        except ValueError:
            continue
    return out


def _urdf_names(root: Any) -> tuple[list[str], list[str]]:
    """(movable joints, links) of a URDF's root element, in file order."""
    joints = [str(j.get("name")) for j in root.iter("joint") if j.get("type") not in (None, "fixed")]
    links = [str(link.get("name")) for link in root.iter("link")]
    return joints, links


def _check_names(m: RobotFile, urdf: Path, root: Any, where: str) -> None:
    """Every joint and link the robot file names is one of the URDF's, or a one-line ConfigError naming the file,
    the key and the valid names (before the simulator or the motion model loads the URDF)."""
    joints, links = _urdf_names(root)
    keys: list[tuple[str, str, str, list[str]]] = [
        *((f"arm_joints[{i}]", j, "movable joint", joints) for i, j in enumerate(m.arm_joints)),
        *((f"gripper.joints[{i}]", j, "movable joint", joints) for i, j in enumerate(m.gripper.joints)),
        ("end_effector_frame", m.end_effector_frame, "link", links),
        *((f"collision.hand_links[{i}]", n, "link", links) for i, n in enumerate(m.collision.hand_links)),
        *(
            (f"collision.disabled_pairs[{i}][{k}]", n, "link", links)
            for i, pair in enumerate(m.collision.disabled_pairs)
            for k, n in enumerate(pair)
        ),
    ]
    for key, name, kind, valid in keys:
        if name not in valid:
            raise UnknownURDFNameError(where, key, name, f"{kind} of {urdf.name}", valid)
    for i, joint in enumerate(m.gripper.joints):
        if joint in m.arm_joints:  # else the arm's chain comes out a joint short, blamed on arm_joints
            fingers = [j for j in joints if j not in m.arm_joints]
            raise ConfigError(
                f"{where}: gripper.joints[{i}]: {joint!r} is one of arm_joints; a gripper joint moves a finger "
                f"(joints of {urdf.name} not in arm_joints: {', '.join(fingers) or '(none)'})"
            )


class UnknownURDFNameError(UnknownNameError, ConfigError):
    """A joint or link name in a robot file that its URDF does not have: one line naming the file and the key."""

    def __init__(self, where: str, key: str, name: str, kind: str, valid: list[str]) -> None:
        super().__init__(kind, name, valid)
        self.args = (f"{where}: {key}: {name!r} is not a {kind}; valid: {', '.join(valid) or '(none)'}",)


def _check_home(m: RobotFile, urdf: Path, root: Any, where: str) -> None:
    """The home pose within the URDF's joint limits, or a one-line ConfigError naming the index and the joint."""
    limits = _urdf_limits(root)
    for i, (joint, q) in enumerate(zip(m.arm_joints, m.home, strict=True)):
        if joint not in limits:
            continue
        lo, hi = limits[joint]
        if lo < hi and not lo - 1e-6 <= q <= hi + 1e-6:
            raise ConfigError(
                f"{where}: home[{i}] ({joint}): {q:g} is outside the joint's limits [{lo:g}, {hi:g}] in {urdf.name}"
            )


def _check_fingers(m: RobotFile, urdf: Path, root: Any, where: str) -> None:
    """The gripper's open and closed positions within its finger joints' URDF limits (a finger told to open past
    its limit stops there, so the opening the gate believes in would be wrong), or one line naming the key."""
    limits = _urdf_limits(root)
    for joint in m.gripper.joints:
        if joint not in limits or not limits[joint][0] < limits[joint][1]:
            continue
        lo, hi = limits[joint]
        for key in ("open_position", "closed_position"):
            q = getattr(m.gripper, key)
            if not lo - 1e-6 <= q <= hi + 1e-6:
                raise ConfigError(
                    f"{where}: gripper.{key}: {q:g} is outside {joint}'s limits [{lo:g}, {hi:g}] in {urdf.name}"
                )


_Spec = TypeVar("_Spec", bound="DataclassInstance")


def _spec_of(spec: type[_Spec], section: StrictModel) -> _Spec:
    """The frozen ``spec`` dataclass from the validated file section with the same field names (lists as tuples):
    the section's keys are the spec's fields, so nothing is copied by hand."""
    values = {f.name: getattr(section, f.name) for f in fields(spec)}
    return spec(**{name: tuple(v) if isinstance(v, list) else v for name, v in values.items()})


def load_robot(name_or_path: str | Path = "panda") -> RobotConfig:
    """Load a robot by name (robots/<name>.yaml) or path; every key is validated before anything runs.

    Raises:
        ConfigError: one line naming the file, the key and what is allowed (unknown planner, `rate_hz: 0`,
            negative gripper force or friction, wrong types, unknown keys, wrong encoding, ...).
    """
    path = resolve_file("robots", name_or_path, (".yaml", ".yml"))
    raw = read_yaml(path)
    m = validate(RobotFile, raw, str(path))
    grasp = GraspParams.from_section(m.grasp, str(path))
    urdf = resolve_urdf(m.urdf, path)
    root = _urdf_root(urdf, str(path))
    _check_names(m, urdf, root, str(path))
    _check_home(m, urdf, root, str(path))
    _check_fingers(m, urdf, root, str(path))
    return RobotConfig(
        name=m.name,
        urdf=urdf,
        base_position=cast("tuple[float, float, float]", tuple(m.base_position)),
        arm_joints=tuple(m.arm_joints),
        end_effector_frame=m.end_effector_frame,
        home=tuple(m.home),
        gripper=_spec_of(GripperSpec, m.gripper),
        limits=_spec_of(LimitsSpec, m.limits),
        planner=_spec_of(PlannerSpec, m.planner),
        control=_spec_of(ControlSpec, m.control),
        source=path,
        raw=raw,
        disabled_collisions=tuple((a, b) for a, b in m.collision.disabled_pairs),
        hand_links=tuple(m.collision.hand_links),
        grasp=grasp,
        camera_shapes=m.camera_shapes,
    )
