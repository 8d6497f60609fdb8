"""Proficiency profiles: the robot and world parameters that make one simulated robot better or worse.

A profile is a YAML file (tools/profiles/*.yaml). Every parameter is optional; a missing one keeps the value of
robots/<robot>.yaml or perception/kitchen.yaml. Example:

    name: weak_gripper
    description: A worn gripper that holds light objects only.
    seed: 3
    gripper: {max_force: 8.0, finger_friction: 0.6}
    camera: {noise_std: 4.0}
    planner: {time_limit_s: 0.5}
    limits: {velocity_scale: 0.8, acceleration_scale: 0.6}
    calibration_offset: [0.01, 0.0, 0.0]
    injected:
      - {stage: perception, rate: 0.5, materials: [glass]}
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from scone_bt.config import KitchenConfig, ObjectSpec, RobotConfig
from scone_bt.config.yaml_io import Fields, read_yaml, require
from scone_bt.errors import ConfigError

__all__ = ["INJECTABLE_STAGES", "InjectedFailure", "Profile", "load_profile", "load_profiles"]

INJECTABLE_STAGES = ("perception", "planning", "grasp")
"""Stages a profile can inject failures into.

perception: the target's detection is dropped (a miss). planning: the planner gets a time budget too small to
find a path. grasp: the gripper closes with a tenth of its force, so the object slips in the real simulation.
"""


@dataclass(frozen=True)
class InjectedFailure:
    """A per-execution chance that one stage is sabotaged, optionally only for some objects.

    Attributes:
        stage: One of INJECTABLE_STAGES.
        rate: Probability in [0, 1] per matching execution.
        materials: Only objects of these materials (empty: all).
        shapes: Only objects of these shapes (empty: all).
        min_mass: Only objects at least this heavy, kilograms.
        max_width: Only objects whose grasp width is at most this, metres.
    """

    stage: str
    rate: float
    materials: tuple[str, ...] = ()
    shapes: tuple[str, ...] = ()
    min_mass: float = 0.0
    max_width: float = float("inf")

    def applies_to(self, spec: ObjectSpec) -> bool:
        """Whether this injection concerns the object."""
        return (
            (not self.materials or spec.material in self.materials)
            and (not self.shapes or spec.shape in self.shapes)
            and spec.mass >= self.min_mass
            and spec.grasp_width <= self.max_width
        )


@dataclass(frozen=True)
class Profile:
    """One simulated robot's proficiency. None keeps the robot's or kitchen's own value.

    Attributes:
        name: Identifier; the dataset file is <name>.csv.
        description: What kind of robot this models and which objects it should fail on.
        seed: Base seed; execution i uses seed * 100_000 + i.
        objects_on_shelf: Objects spawned per execution (the target and distractors).
        gripper_max_force: Newtons per finger.
        finger_friction: Lateral friction coefficient of the finger pads.
        camera_noise_std: Gaussian pixel noise, 0-255 scale.
        depth_noise_std: Gaussian depth noise, metres.
        planner_time_limit_s: OMPL time budget per planning query, seconds.
        velocity_scale: Fraction of the datasheet joint velocity limits.
        acceleration_scale: Fraction of the datasheet joint acceleration limits.
        jerk_scale: Fraction of the datasheet joint jerk limits.
        calibration_offset: Systematic camera-to-robot error added to every perceived position, metres (x, y, z).
        injected: Optional injected failures.
        source: The YAML file it was read from.
    """

    name: str
    description: str
    seed: int
    objects_on_shelf: int = 4
    gripper_max_force: float | None = None
    finger_friction: float | None = None
    camera_noise_std: float | None = None
    depth_noise_std: float | None = None
    planner_time_limit_s: float | None = None
    velocity_scale: float | None = None
    acceleration_scale: float | None = None
    jerk_scale: float | None = None
    calibration_offset: tuple[float, float, float] = (0.0, 0.0, 0.0)
    injected: tuple[InjectedFailure, ...] = ()
    source: Path = dataclasses.field(default=Path("."), compare=False)

    def execution_seed(self, index: int) -> int:
        """Seed of execution `index` (0-based)."""
        return self.seed * 100_000 + index

    def apply(self, kitchen: KitchenConfig, robot: RobotConfig) -> tuple[KitchenConfig, RobotConfig]:
        """The kitchen and robot configs with this profile's overrides."""

        def keep(value: float | None, default: float) -> float:
            return default if value is None else value

        g, lim, pl, cam = robot.gripper, robot.limits, robot.planner, kitchen.camera
        robot = dataclasses.replace(
            robot,
            gripper=dataclasses.replace(
                g,
                max_force=keep(self.gripper_max_force, g.max_force),
                finger_friction=keep(self.finger_friction, g.finger_friction),
            ),
            limits=dataclasses.replace(
                lim,
                velocity_scale=keep(self.velocity_scale, lim.velocity_scale),
                acceleration_scale=keep(self.acceleration_scale, lim.acceleration_scale),
                jerk_scale=keep(self.jerk_scale, lim.jerk_scale),
            ),
            planner=dataclasses.replace(pl, time_limit_s=keep(self.planner_time_limit_s, pl.time_limit_s)),
        )
        kitchen = dataclasses.replace(
            kitchen,
            camera=dataclasses.replace(
                cam,
                noise_std=keep(self.camera_noise_std, cam.noise_std),
                depth_noise_std=keep(self.depth_noise_std, cam.depth_noise_std),
            ),
        )
        return kitchen, robot

    def draw_injections(self, spec: ObjectSpec, rng: np.random.Generator) -> frozenset[str]:
        """Stages sabotaged in one execution on `spec`. Draws one number per injection, matching or not."""
        hits = set()
        for inj in self.injected:
            u = rng.random()
            if inj.applies_to(spec) and u < inj.rate:
                hits.add(inj.stage)
        return frozenset(hits)


def _injection(raw: object, where: str) -> InjectedFailure:
    f = Fields(raw, where)  # type: ignore[arg-type]
    stage = f.get("stage", str)
    require(
        stage in INJECTABLE_STAGES, f"{where}.stage: {stage!r} is not one of {', '.join(INJECTABLE_STAGES)}"
    )
    rate = f.get("rate", float)
    require(0.0 <= rate <= 1.0, f"{where}.rate must be in [0, 1], got {rate}")
    return InjectedFailure(
        stage=stage,
        rate=rate,
        materials=tuple(str(m) for m in f.get("materials", list, [])),
        shapes=tuple(str(s) for s in f.get("shapes", list, [])),
        min_mass=f.get("min_mass", float, 0.0),
        max_width=f.get("max_width", float, float("inf")),
    )


_TOP_KEYS = (
    "name",
    "description",
    "seed",
    "objects_on_shelf",
    "gripper",
    "camera",
    "planner",
    "limits",
    "calibration_offset",
    "injected",
)


def load_profile(path: Path | str) -> Profile:
    """Read one profile YAML file; errors name the file, the key and the valid options."""
    path = Path(path)
    raw = read_yaml(path)
    unknown = sorted(set(raw) - set(_TOP_KEYS))
    if unknown:
        raise ConfigError(f"{path}: unknown key {unknown[0]!r}; valid: {', '.join(_TOP_KEYS)}")
    f = Fields(raw, str(path))

    def section(key: str, allowed: Sequence[str]) -> Fields:
        sub = f.sub(key) if key in raw else Fields({}, f"{path}.{key}")
        bad = sorted(set(sub.data) - set(allowed))
        if bad:
            raise ConfigError(f"{path}.{key}: unknown key {bad[0]!r}; valid: {', '.join(allowed)}")
        return sub

    g = section("gripper", ("max_force", "finger_friction"))
    c = section("camera", ("noise_std", "depth_noise_std"))
    p = section("planner", ("time_limit_s",))
    lim = section("limits", ("velocity_scale", "acceleration_scale", "jerk_scale"))
    profile = Profile(
        name=f.get("name", str),
        description=" ".join(f.get("description", str).split()),
        seed=f.get("seed", int),
        objects_on_shelf=f.get("objects_on_shelf", int, 4),
        gripper_max_force=g.get("max_force", float, None),
        finger_friction=g.get("finger_friction", float, None),
        camera_noise_std=c.get("noise_std", float, None),
        depth_noise_std=c.get("depth_noise_std", float, None),
        planner_time_limit_s=p.get("time_limit_s", float, None),
        velocity_scale=lim.get("velocity_scale", float, None),
        acceleration_scale=lim.get("acceleration_scale", float, None),
        jerk_scale=lim.get("jerk_scale", float, None),
        calibration_offset=f.vector("calibration_offset", 3, (0.0, 0.0, 0.0)),  # type: ignore[arg-type]
        injected=tuple(
            _injection(item, f"{path}.injected[{i}]") for i, item in enumerate(f.get("injected", list, []))
        ),
        source=path,
    )
    require(1 <= profile.objects_on_shelf <= 15, f"{path}.objects_on_shelf must be in 1..15")
    for key, value in (
        ("gripper.max_force", profile.gripper_max_force),
        ("planner.time_limit_s", profile.planner_time_limit_s),
        ("limits.velocity_scale", profile.velocity_scale),
        ("limits.acceleration_scale", profile.acceleration_scale),
        ("limits.jerk_scale", profile.jerk_scale),
    ):
        require(value is None or value > 0, f"{path}.{key} must be positive")
    return profile


def load_profiles(directory: Path | str, names: Sequence[str] | None = None) -> list[Profile]:
    """Every profile in `directory` (sorted by file name), or only those named."""
    directory = Path(directory)
    files = sorted(directory.glob("*.yaml"))
    if not files:
        raise ConfigError(f"{directory}: no profile files (*.yaml)")
    profiles = [load_profile(p) for p in files]
    seen: dict[str, Path] = {}
    for prof in profiles:
        if prof.name in seen:
            raise ConfigError(
                f"profile name {prof.name!r} is used by both {seen[prof.name]} and {prof.source}"
            )
        seen[prof.name] = prof.source
    if names:
        missing = [n for n in names if n not in seen]
        if missing:
            raise ConfigError(f"unknown profile {missing[0]!r}; valid: {', '.join(sorted(seen))}")
        profiles = [p for p in profiles if p.name in names]
    return profiles
