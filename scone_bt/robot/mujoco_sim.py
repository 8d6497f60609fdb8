"""The MuJoCo simulation as a backend (``scone-run --robot mujoco``): the same robot, cameras, planner and test rig
as ``--robot sim``, on a `world.mj_kitchen.MjKitchen` instead of PyBullet's `world.Kitchen`.

Nothing above the seam changes: `SimRobot` (perception's detector, the motion system, the outcome sensor) and
`SimWorld` (the test rig) talk to the MuJoCo kitchen through the same methods they use on PyBullet's.
"""

from __future__ import annotations

from scone_bt.errors import ConfigError
from scone_bt.robot.backend import BackendRequest
from scone_bt.robot.sim import SimBackend, SimRobot

__all__ = ["mujoco_backend"]


def mujoco_backend(request: BackendRequest) -> SimBackend:
    """A new MuJoCo kitchen (no products yet) with the arm in it.

    Raises:
        ConfigError: mujoco is not installed (names the extra), headless rendering is unavailable (names the
            Debian packages), the robot's URDF cannot be loaded (names the file), or ``request.gui``.
    """
    from scone_bt.world.mj_camera import check_rendering
    from scone_bt.world.mj_model import import_mujoco

    if request.gui:
        raise ConfigError(
            "--gui opens PyBullet's own window; with --robot mujoco watch the run with --viewer or --save"
        )
    mujoco = import_mujoco()
    check_rendering(mujoco)
    from scone_bt.world.mj_kitchen import MjKitchen

    kitchen = MjKitchen(request.kitchen, request.robot)
    return SimBackend(SimRobot(kitchen, request.kitchen, request.robot, request.perception_rng))  # type: ignore[arg-type]
