"""What executing a plan needs of the arm's body (`ArmExecutor`), and what planning needs of its cell (`Workcell`).

Execution (`motion.execution.PickPlaceController`) is a controller the body calls before every control step; it
commands the arm and the gripper and reads the body's own sensors (joints, finger contacts, the outcome sensor).
The simulated kitchen (`world.Kitchen`, PyBullet) is the implementation behind ``--robot sim``; a real arm's
backend implements the same few methods over its joint controller and gripper, so motion never imports a
simulator.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Protocol, runtime_checkable

import numpy as np

if TYPE_CHECKING:
    from scone_bt.config import KitchenConfig, RobotConfig
    from scone_bt.motion.collision import Obstacle

__all__ = ["ArmExecutor", "Controller", "SceneBox", "Workcell"]

Controller = Callable[["ArmExecutor"], None]
"""Called with the executor before every control step (a physics step in simulation) while it is registered."""


@runtime_checkable
class ArmExecutor(Protocol):
    """The arm and its gripper as execution drives them, one control step at a time.

    Attributes:
        robot_config: The arm in the cell (its gripper's force and friction may change during a run).
        sim_time: The executor's clock, seconds (simulated time in simulation).
        time_step: Seconds between two control steps.
    """

    robot_config: RobotConfig
    sim_time: float
    time_step: float

    def add_controller(self, controller: Controller) -> None:
        """Call `controller` before every control step from now on."""
        ...

    def remove_controller(self, controller: Controller) -> None: ...

    def arm_joint_positions(self) -> np.ndarray:
        """(dof,) measured arm joint positions, radians."""
        ...

    def gripper_positions(self) -> np.ndarray:
        """Measured finger joint positions, metres (one per finger)."""
        ...

    def command_arm(self, q: np.ndarray, qd: np.ndarray | None = None) -> None:
        """Position control towards ``q`` with velocity feed-forward ``qd`` (zero when None), the robot file's
        gains and force limits."""
        ...

    def set_gripper_target(self, position: float, force: float | None = None) -> None:
        """Drive every finger to ``position`` (metres) with at most ``force`` newtons (None: the gripper's own)."""
        ...

    def couple_fingers(self) -> None:
        """Keep the fingers symmetric, as a parallel gripper's gearing does (idempotent)."""
        ...

    def held_object(self, min_force: float) -> str | None:
        """What every finger touches with at least ``min_force`` newtons (its name), else None."""
        ...

    def unexpected_contact(self, allow_gripper: bool, held: str | None, min_force: float) -> str | None:
        """'<link> hit <what>' for the first arm link pushing on something it should not touch, else None.

        The gripper may touch anything when ``allow_gripper``, and the held object (``held``) always.
        """
        ...

    def is_on_table(self, name: str) -> bool:
        """The outcome sensor: the object rests upright on the table."""
        ...

    def standing_position(self, name: str) -> tuple[float, float, float] | None:
        """The outcome sensor's look at one product: where it stands upright (its centre, metres), None when it
        lies or leans (a heft test whose fingers missed it asks whether it still stands where it stood)."""
        ...

    def objects_on_table(self) -> frozenset[str]:
        """The outcome sensor over every product: those resting upright on the table."""
        ...

    def products_touched(self, held: str | None) -> frozenset[str]:
        """Products (other than ``held``) that an arm link or the held product ``held`` touches now."""
        ...

    def products_at(self, spot: Obstacle, margin: float) -> tuple[Obstacle, ...]:
        """A look at a spot on the table: the products standing on the table within ``margin`` (m) of where
        ``spot`` (a shape standing upright there) would stand, each as its shape where it stands."""
        ...

    def table_products(self) -> tuple[Obstacle, ...]:
        """A look at the whole table: every product standing on it, each as its shape where it stands."""
        ...


class SceneBox(Protocol):
    """An immovable box of the cell (centre and full size in metres, world frame)."""

    @property
    def name(self) -> str: ...

    @property
    def center(self) -> tuple[float, float, float]: ...

    @property
    def size(self) -> tuple[float, float, float]: ...


@runtime_checkable
class Workcell(ArmExecutor, Protocol):
    """The executor with the cell it stands in: the kitchen's description and the fixed boxes planning avoids."""

    config: KitchenConfig

    @property
    def static_boxes(self) -> Sequence[SceneBox]: ...  # read-only here: a list of any SceneBox type fits
