"""The robot backends ``scone-run --robot`` accepts, by name: the one place that says which code builds which.

A new backend is a module with a `BackendFactory` and one line here; the factory is imported only when its name is
chosen, so a simulator's dependencies (PyBullet, or MuJoCo) load only for its own name.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from scone_bt.errors import UnknownNameError

if TYPE_CHECKING:
    from scone_bt.robot.backend import Backend, BackendFactory, BackendRequest

__all__ = ["BACKENDS", "DEFAULT_BACKEND", "backend_factory"]


def _sim(request: BackendRequest) -> Backend:
    from scone_bt.robot.sim import sim_backend

    return sim_backend(request)


def _mujoco(request: BackendRequest) -> Backend:
    from scone_bt.robot.mujoco_sim import mujoco_backend

    return mujoco_backend(request)


BACKENDS: dict[str, BackendFactory] = {
    "sim": _sim,  # PyBullet: scone_bt/robot/sim.py
    "mujoco": _mujoco,  # MuJoCo: scone_bt/robot/mujoco_sim.py (the mujoco extra)
}
"""Backend name → its factory."""

DEFAULT_BACKEND = "sim"
"""The backend an episode runs on when none is named."""


def backend_factory(name: str) -> BackendFactory:
    """The factory of the backend called ``name``."""
    if name not in BACKENDS:
        raise UnknownNameError("robot backend", name, BACKENDS)
    return BACKENDS[name]
