"""What one pick-and-place is asked to do (`PickPlaceRequest`), and its scene as the planner sees it."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from scone_bt.config import ObjectSpec
from scone_bt.config.grasp import GraspParams
from scone_bt.motion.collision import Obstacle
from scone_bt.motion.grasp import object_pose
from scone_bt.motion.ledge import Ledge
from scone_bt.motion.model import ArmModel
from scone_bt.motion.placement import PlacementOptions, TableRegion
from scone_bt.perception.types import Detection

__all__ = ["PickPlaceRequest", "PickScene", "detected_obstacle"]


@dataclass(frozen=True, eq=False)
class PickPlaceRequest:
    """Inputs of one pick-and-place plan (all from perception, the catalogue and known scene geometry).

    Attributes:
        q_start: (dof,) current arm joints, radians.
        target: Detection of the object to move.
        spec: Its catalogue model.
        obstacles: Other detected objects (on the shelf) with their catalogue models.
        static: Known scene boxes (world-frame obstacles).
        home: (dof,) joints to return to.
        rng_seed: Seeds IK restarts, placement sampling and OMPL.
        table: The table's rectangle, for placement sampling (None: only `place_spots`).
        table_obstacles: What stands on the table (seen there, or remembered by the robot), world frame.
        place_spots: Explicit (x, y, table top z) spots tried in order instead of sampling.
        params: Grasp generation and approach, lift and place distances.
        placement: Placement sampling settings (its rng_seed is replaced by `rng_seed`).
        preferred_yaw: Closing-axis yaw (rad) of the home pose; grasps nearest to it cost least.
        opening: The gripper's full opening, metres (None: no span filter, no pre-shaping).
        finger_closed: Each finger's joint position when closed, metres (the opening counts from it).
        pinch: The ledge a slid flat pack sticks out over: only pinches of its front edge are planned
            (`motion.slide.pinch_candidates`); None: the usual grasps.
    """

    q_start: np.ndarray
    target: Detection
    spec: ObjectSpec
    obstacles: tuple[tuple[Detection, ObjectSpec], ...]
    static: tuple[Obstacle, ...]
    home: np.ndarray
    rng_seed: int
    table: TableRegion | None = None
    table_obstacles: tuple[Obstacle, ...] = ()
    place_spots: tuple[tuple[float, float, float], ...] = ()
    params: GraspParams = field(default_factory=GraspParams)
    placement: PlacementOptions = field(default_factory=PlacementOptions)
    preferred_yaw: float = -np.pi / 2
    opening: float | None = None
    finger_closed: float = 0.0
    pinch: Ledge | None = None


def detected_obstacle(det: Detection, spec: ObjectSpec) -> Obstacle:
    """The collision shape of a detected object (its catalogue model at the detected pose)."""
    return Obstacle(det.name, spec.shape, spec.size, object_pose(det, spec))


@dataclass(frozen=True, eq=False)
class PickScene:
    """A request's objects as collision shapes, and where the target lies seen from the arm's base.

    Attributes:
        request: The request.
        target: The target's collision shape.
        others: The other detected objects' shapes (the target left out if detected twice).
        table_objects: What stands on the table (the target left out).
        fixed: Everything but the target: scene boxes, then other objects, then the table's objects.
        base: (3,) the arm's base position, metres.
        target_dir: Direction (rad about world z) from the base to the target.
    """

    request: PickPlaceRequest
    target: Obstacle
    others: tuple[Obstacle, ...]
    table_objects: tuple[Obstacle, ...]
    fixed: tuple[Obstacle, ...]
    base: np.ndarray
    target_dir: float

    @property
    def name(self) -> str:
        """The target's name."""
        return self.request.target.name

    @classmethod
    def of(cls, request: PickPlaceRequest, arm: ArmModel) -> PickScene:
        """The scene of `request` for `arm`."""
        name = request.target.name
        others = tuple(detected_obstacle(d, s) for d, s in request.obstacles if d.name != name)
        table_objects = tuple(o for o in request.table_obstacles if o.name != name)
        base = np.asarray(arm.config.base_position, dtype=float)
        x, y = request.target.position[0] - base[0], request.target.position[1] - base[1]
        return cls(
            request=request,
            target=detected_obstacle(request.target, request.spec),
            others=others,
            table_objects=table_objects,
            fixed=(*request.static, *others, *table_objects),
            base=base,
            target_dir=float(np.arctan2(y, x)),
        )
