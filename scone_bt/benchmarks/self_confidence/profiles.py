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
from typing import Annotated, cast

import numpy as np
from pydantic import Field, field_validator

from scone_bt.config import KitchenConfig, ObjectSpec, RobotConfig
from scone_bt.config.catalogue import Shape
from scone_bt.config.schema import StrictModel, validate
from scone_bt.config.yaml_io import read_yaml
from scone_bt.errors import ConfigError

__all__ = ["INJECTABLE_STAGES", "InjectedFailure", "Profile", "ProfileFile", "load_profile", "load_profiles"]

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


_Positive = Annotated[float, Field(gt=0, allow_inf_nan=False)]
_NonNegative = Annotated[float, Field(ge=0, allow_inf_nan=False)]
_Scale = Annotated[float, Field(gt=0, le=4, allow_inf_nan=False)]
_Text = Annotated[str, Field(min_length=1, max_length=200)]


class _InjectedModel(StrictModel):
    stage: str
    rate: Annotated[float, Field(ge=0, le=1, allow_inf_nan=False)]
    materials: list[_Text] = []
    shapes: list[_Text] = []
    min_mass: _NonNegative = 0.0
    max_width: Annotated[float, Field(gt=0)] = float("inf")

    @field_validator("stage")
    @classmethod
    def _known_stage(cls, stage: str) -> str:
        if stage not in INJECTABLE_STAGES:
            raise ValueError(f"{stage!r} is not one of {', '.join(INJECTABLE_STAGES)}")
        return stage

    @field_validator("shapes")
    @classmethod
    def _known_shapes(cls, shapes: list[str]) -> list[str]:
        # a misspelt shape matched no product, and the injection never fired
        valid = [s.value for s in Shape]
        for shape in shapes:
            if shape not in valid:
                raise ValueError(f"{shape!r} is not a shape; valid: {', '.join(valid)}")
        return shapes


class _GripperSection(StrictModel):
    max_force: _Positive | None = None
    finger_friction: _NonNegative | None = None


class _CameraSection(StrictModel):
    noise_std: Annotated[float, Field(ge=0, le=255, allow_inf_nan=False)] | None = None
    depth_noise_std: Annotated[float, Field(ge=0, le=1, allow_inf_nan=False)] | None = None


class _PlannerSection(StrictModel):
    time_limit_s: Annotated[float, Field(gt=0, le=600, allow_inf_nan=False)] | None = None


class _LimitsSection(StrictModel):
    velocity_scale: _Scale | None = None
    acceleration_scale: _Scale | None = None
    jerk_scale: _Scale | None = None


class ProfileFile(StrictModel):
    """The schema of a profile YAML file (tools/profiles/*.yaml); units as in Profile."""

    name: Annotated[str, Field(min_length=1, max_length=100, pattern=r"^[A-Za-z0-9_.-]+$")]
    description: Annotated[str, Field(min_length=1, max_length=5000)]
    seed: Annotated[int, Field(ge=0, le=42_949)]  # execution seeds seed * 100_000 + i stay 32-bit
    objects_on_shelf: Annotated[int, Field(ge=1, le=15)] = 4
    gripper: _GripperSection = _GripperSection()
    camera: _CameraSection = _CameraSection()
    planner: _PlannerSection = _PlannerSection()
    limits: _LimitsSection = _LimitsSection()
    calibration_offset: Annotated[
        list[Annotated[float, Field(ge=-1, le=1, allow_inf_nan=False)]], Field(min_length=3, max_length=3)
    ] = [0.0, 0.0, 0.0]
    injected: Annotated[list[_InjectedModel], Field(max_length=100)] = []


def load_profile(path: Path | str) -> Profile:
    """Read one profile YAML file; errors name the file, the key and the valid options (one line)."""
    path = Path(path)
    m = validate(ProfileFile, read_yaml(path), str(path))
    return Profile(
        name=m.name,
        description=" ".join(m.description.split()),
        seed=m.seed,
        objects_on_shelf=m.objects_on_shelf,
        gripper_max_force=m.gripper.max_force,
        finger_friction=m.gripper.finger_friction,
        camera_noise_std=m.camera.noise_std,
        depth_noise_std=m.camera.depth_noise_std,
        planner_time_limit_s=m.planner.time_limit_s,
        velocity_scale=m.limits.velocity_scale,
        acceleration_scale=m.limits.acceleration_scale,
        jerk_scale=m.limits.jerk_scale,
        calibration_offset=cast("tuple[float, float, float]", tuple(m.calibration_offset)),
        injected=tuple(
            InjectedFailure(
                stage=i.stage,
                rate=i.rate,
                materials=tuple(i.materials),
                shapes=tuple(i.shapes),
                min_mass=i.min_mass,
                max_width=i.max_width,
            )
            for i in m.injected
        ),
        source=path,
    )


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
