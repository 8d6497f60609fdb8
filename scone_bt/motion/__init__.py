"""Motion stage: Pinocchio arm model, OMPL planning, ruckig timing and pick-and-place through an arm executor.

Heavy backends (pinocchio, coal, ompl, ruckig) are imported inside the adapter functions only. Execution drives the
arm through `ArmExecutor` (`Workcell` with the cell's fixed boxes); the simulated kitchen implements it, so motion
never imports the simulator.
"""

from scone_bt.motion.collision import CollisionWorld, HandModel, Obstacle
from scone_bt.motion.execution import ExecutionSettings
from scone_bt.motion.executor import ArmExecutor, Workcell
from scone_bt.motion.grasp import GraspCandidate, GraspFamily, grasp_candidates, place_pose
from scone_bt.motion.model import ArmModel, IKOptions, IKSolution
from scone_bt.motion.pick_place import PickPlaceFailure, PickPlacePlan, PickPlaceRequest, plan_pick_and_place
from scone_bt.motion.placement import (
    Footprint,
    PlacementOptions,
    PlacementSet,
    PlacementSpot,
    TableRegion,
    sample_placements,
)
from scone_bt.motion.planner import PlannerOptions, plan_joint_path
from scone_bt.motion.system import MotionSystem, PickAndPlaceTask
from scone_bt.motion.timing import KinematicLimits, limits_of, time_path
from scone_bt.motion.types import (
    FailureStage,
    MotionOutcome,
    MotionPhase,
    MotionProgress,
    PlanFailureReason,
    PlanResult,
    PlanStatus,
    TimedTrajectory,
)

__all__ = [
    "ArmExecutor",
    "ArmModel",
    "CollisionWorld",
    "ExecutionSettings",
    "FailureStage",
    "Footprint",
    "GraspCandidate",
    "GraspFamily",
    "HandModel",
    "IKOptions",
    "IKSolution",
    "KinematicLimits",
    "MotionOutcome",
    "MotionPhase",
    "MotionProgress",
    "MotionSystem",
    "Obstacle",
    "PickAndPlaceTask",
    "PickPlaceFailure",
    "PickPlacePlan",
    "PickPlaceRequest",
    "PlacementOptions",
    "PlacementSet",
    "PlacementSpot",
    "PlanFailureReason",
    "PlanResult",
    "PlanStatus",
    "PlannerOptions",
    "TableRegion",
    "TimedTrajectory",
    "Workcell",
    "grasp_candidates",
    "limits_of",
    "place_pose",
    "plan_joint_path",
    "plan_pick_and_place",
    "sample_placements",
    "time_path",
]
