"""A backend: the robot and the world it works in, built together from the episode's configuration.

`run_episode` asks a `BackendFactory` (`scone_bt.robot.registry.BACKENDS`, by the name ``scone-run --robot`` takes)
for a `Backend` and from then on talks to its `Robot` (what the behaviours may ask) and its `World` (what only a
simulator or a lab rig can do: let time pass, stock the shelf, fetch a product by hand); nothing else of the
episode knows which backend runs.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Protocol

if TYPE_CHECKING:  # the episode imports this module; it must not load a backend's dependencies
    import numpy as np

    from scone_bt.config import KitchenConfig, RobotConfig
    from scone_bt.robot.interface import Robot
    from scone_bt.robot.rig import World
    from scone_bt.viz.scene import SceneView

__all__ = ["Backend", "BackendFactory", "BackendRequest", "BackendStats"]


@dataclass(frozen=True)
class BackendRequest:
    """What a backend is built from.

    Attributes:
        kitchen: The kitchen's configuration (scene, cameras, catalogue).
        robot: The arm's configuration.
        perception_rng: Seeds the cameras' noise (a simulator's; a real camera has its own).
        gui: Open the backend's own debugging window, where it has one.
    """

    kitchen: KitchenConfig
    robot: RobotConfig
    perception_rng: np.random.Generator
    gui: bool = False


@dataclass(frozen=True)
class BackendStats:
    """What the backend measured of itself, for the episode's summary (zeros where it measures nothing).

    Attributes:
        perception_wall_s: Wall seconds spent capturing and detecting.
        perception_cpu_s: CPU seconds of the same (the episode's thread).
        renders: Camera images captured.
        physics_steps: Physics steps of the simulation (taken or skipped).
        physics_steps_skipped: Of them, the steps a sleeping scene did not need.
        bodies: Bodies in the world now (PyBullet's: the scene, the arm and the products; 0 where none are counted).
        constraints: Constraints in the world now (a grasp's, PyBullet's).
    """

    perception_wall_s: float = 0.0
    perception_cpu_s: float = 0.0
    renders: int = 0
    physics_steps: int = 0
    physics_steps_skipped: int = 0
    bodies: int = 0
    constraints: int = 0


class Backend(Protocol):
    """The robot and its world, as one episode sees them."""

    @property
    def robot(self) -> Robot:
        """The robot the behaviours talk to (closing it releases the whole backend)."""
        ...

    @property
    def world(self) -> World:
        """The world around the robot: the episode loop's clock and the test rig."""
        ...

    @property
    def scene(self) -> SceneView | None:
        """What a recording draws (poses of the arm and the products); None: this backend cannot be recorded."""
        ...

    def setup(self) -> None:
        """Get ready before the first tick (connect, load models), so the first tick does not pay for it."""
        ...

    def stats(self) -> BackendStats:
        """What it measured of itself so far."""
        ...


BackendFactory = Callable[[BackendRequest], Backend]
"""Builds a backend (the registry's values; a test passes its own to `run_episode`)."""
