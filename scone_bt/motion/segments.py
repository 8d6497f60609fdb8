"""Checking a joint-space segment the way OMPL's discrete motion validator does: one state every step.

Shared by the planner's direct-segment check (`planner.plan_joint_path`) and the mesh re-check of VAMP's paths
(`vamp_planner.mesh_check`), so both check at the same states.
"""

from __future__ import annotations

import numpy as np

__all__ = ["MOTION_RESOLUTION", "motion_step", "segment_times"]

MOTION_RESOLUTION = 0.004
"""Default motion-checking step, as a fraction of the joint space's largest extent (L2)."""


def motion_step(lower: np.ndarray, upper: np.ndarray, resolution: float) -> float:
    """OMPL's discrete motion validator's step (rad, L2): ``resolution`` x the joint space's largest extent."""
    return resolution * float(np.linalg.norm(np.asarray(upper) - np.asarray(lower)))


def segment_times(qa: np.ndarray, qb: np.ndarray, step: float) -> np.ndarray:
    """Interpolation parameters in [0, 1] (both ends included) that check the segment qa → qb every ``step``."""
    n = max(2, int(np.ceil(np.linalg.norm(qb - qa) / step)) + 1)
    return np.linspace(0.0, 1.0, n)
