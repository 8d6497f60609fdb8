"""The robot file (robots/<name>.yaml): URDF, frames, gripper, limits and planner settings."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from scone_bt.config.yaml_io import Fields, read_yaml, require
from scone_bt.errors import ConfigError
from scone_bt.resources import resolve_file

__all__ = [
    "GripperSpec",
    "LimitsSpec",
    "PlannerSpec",
    "ControlSpec",
    "RobotConfig",
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
    """OMPL planner name, time limit (s), path simplification and seed."""

    name: str = "RRTConnect"
    time_limit_s: float = 1.0
    simplify: bool = True
    rng_seed: int = 0


@dataclass(frozen=True)
class ControlSpec:
    """Position control at rate_hz; gains and forces as PyBullet's POSITION_CONTROL takes them."""

    rate_hz: float = 240.0
    position_gain: float = 0.3
    max_joint_force: float = 87.0


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

    @property
    def dof(self) -> int:
        return len(self.arm_joints)


def resolve_urdf(spec: str, relative_to: Path) -> Path:
    """Resolve 'pybullet_data://x', 'example_robot_data://x', absolute or file-relative URDF paths."""
    if spec.startswith("pybullet_data://"):
        import pybullet_data  # adapter-only dependency, used here just to locate files

        path = Path(pybullet_data.getDataPath()) / spec.removeprefix("pybullet_data://")
    else:
        path = Path(spec)
        if not path.is_absolute():
            path = (relative_to.parent / path).resolve()
    if not path.is_file():
        raise ConfigError(f"{relative_to}: URDF not found: {spec} (resolved to {path})")
    return path


def _disabled_pairs(raw: dict[str, Any], path: Path) -> tuple[tuple[str, str], ...]:
    section = raw.get("collision") or {}
    require(isinstance(section, dict), f"{path}.collision: expected a mapping")
    pairs = section.get("disabled_pairs") or []
    require(
        isinstance(pairs, list), f"{path}.collision.disabled_pairs: expected a list of [link, link] pairs"
    )
    out = []
    for i, pair in enumerate(pairs):
        ok = isinstance(pair, list) and len(pair) == 2 and all(isinstance(x, str) for x in pair)
        require(ok, f"{path}.collision.disabled_pairs[{i}]: expected two link names, got {pair!r}")
        out.append((pair[0], pair[1]))
    return tuple(out)


def load_robot(name_or_path: str | Path = "panda") -> RobotConfig:
    """Load a robot by name (robots/<name>.yaml) or path."""
    path = resolve_file("robots", name_or_path, (".yaml", ".yml"))
    raw = read_yaml(path)
    f = Fields(raw, str(path))
    arm = tuple(str(j) for j in f.get("arm_joints", list))
    home = f.vector("home", len(arm))
    g = f.sub("gripper")
    lim = f.sub("limits")
    limits = LimitsSpec(
        velocity=lim.vector("velocity", len(arm)),
        acceleration=lim.vector("acceleration", len(arm)),
        jerk=lim.vector("jerk", len(arm)),
        velocity_scale=lim.get("velocity_scale", float, 1.0),
        acceleration_scale=lim.get("acceleration_scale", float, 1.0),
        jerk_scale=lim.get("jerk_scale", float, 1.0),
    )
    p = f.sub("planner") if "planner" in raw else Fields({}, f"{path}.planner")
    c = f.sub("control") if "control" in raw else Fields({}, f"{path}.control")
    cfg = RobotConfig(
        name=f.get("name", str),
        urdf=resolve_urdf(f.get("urdf", str), path),
        base_position=f.vector("base_position", 3, (0.0, 0.0, 0.0)),  # type: ignore[arg-type]
        arm_joints=arm,
        end_effector_frame=f.get("end_effector_frame", str),
        home=home,
        gripper=GripperSpec(
            joints=tuple(str(j) for j in g.get("joints", list)),
            open_position=g.get("open_position", float),
            closed_position=g.get("closed_position", float, 0.0),
            max_force=g.get("max_force", float),
            finger_friction=g.get("finger_friction", float, 1.0),
        ),
        limits=limits,
        planner=PlannerSpec(
            name=p.get("name", str, "RRTConnect"),
            time_limit_s=p.get("time_limit_s", float, 1.0),
            simplify=p.get("simplify", bool, True),
            rng_seed=p.get("rng_seed", int, 0),
        ),
        control=ControlSpec(
            rate_hz=c.get("rate_hz", float, 240.0),
            position_gain=c.get("position_gain", float, 0.3),
            max_joint_force=c.get("max_joint_force", float, 87.0),
        ),
        source=path,
        raw=raw,
        disabled_collisions=_disabled_pairs(raw, path),
    )
    require(cfg.limits.velocity_scale > 0, f"{path}: limits.velocity_scale must be positive")
    return cfg
