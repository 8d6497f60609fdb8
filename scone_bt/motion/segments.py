"""Checking a joint-space segment the way OMPL's discrete motion validator does: one state every step.

Shared by the planner's direct-segment check (`planner.plan_joint_path`) and the mesh re-check of VAMP's paths
(`vamp_planner.mesh_check`), so both check at the same states.
"""

from __future__ import annotations

import numpy as np

__all__ = ["CARRY_RESOLUTION_SCALE", "MOTION_RESOLUTION", "motion_step", "segment_times"]

MOTION_RESOLUTION = 0.004
"""Default motion-checking step, as a fraction of the joint space's largest extent (L2)."""
CARRY_RESOLUTION_SCALE = 0.25
"""The motion-checking step while the hand holds a product, as a fraction of the default one. A carried product
reaches beyond the fingertips: at the default step (0.054 rad on the Panda) its far end moved 25 to 32 mm between
two checked states of a transit, while its net clearance is a few millimetres, and a transit that ran 3.5 mm into a
standing pepper mill passed every check (MuJoCo, episode 10 of the 50 seeded ones). A quarter of the step keeps the
product's travel between checks under about 8 mm."""


def motion_step(lower: np.ndarray, upper: np.ndarray, resolution: float) -> float:
    """OMPL's discrete motion validator's step (rad, L2): ``resolution`` x the joint space's largest extent."""
    return resolution * float(np.linalg.norm(np.asarray(upper) - np.asarray(lower)))


def segment_times(qa: np.ndarray, qb: np.ndarray, step: float) -> np.ndarray:
    """Interpolation parameters in [0, 1] (both ends included) that check the segment qa → qb every ``step``."""
    n = max(2, int(np.ceil(np.linalg.norm(qb - qa) / step)) + 1)
    return np.linspace(0.0, 1.0, n)
