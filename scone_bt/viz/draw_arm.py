"""Draws the arm: its links' geometry from the URDF, their poses, the planned and executed end-effector paths and
the joints' planned and executed positions."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
import rerun as rr

from scone_bt.errors import ConfigError
from scone_bt.geometry import quat_inverse, quat_multiply, quat_rotate
from scone_bt.viz import paths as P
from scone_bt.viz.colours import rgba255
from scone_bt.viz.pose_batch import MovedFilter, PoseBatch
from scone_bt.viz.render import slug
from scone_bt.viz.sinks import Sinks
from scone_bt.viz.snapshot import Pose
from scone_bt.viz.tick_rows import TickRows, sim_time_column
from scone_bt.viz.urdf_visuals import LinkVisual, RobotVisuals, read_robot_visuals

if TYPE_CHECKING:
    from scone_bt.motion.types import TimedTrajectory
    from scone_bt.viz.scene import SceneView

__all__ = ["EXECUTED", "PLANNED", "ROBOT_FRAME", "ArmDrawer"]

ROBOT_FRAME = "robot"
"""Links' transform frame ids are robot/<link>, their geometry's robot/<link>/geometry_<i>."""
_TRACE_STEP = 0.005  # metres between points of the executed end-effector trace
_TRACE_MAX = 4000
_TRACE_PERIOD = 0.5  # simulated seconds between updates of the executed trace
PLANNED = (230, 120, 20)
"""The planned end-effector path's colour (RGB)."""
EXECUTED = (30, 120, 230)
"""The executed end-effector trace's colour (RGB)."""
_SERIES_SUFFIX = {
    P.PLANNED_POSITION: " planned",
    P.PLANNED_VELOCITY: " velocity",
    P.EXECUTED_POSITION: " executed",
}


class ArmDrawer:
    """The arm's geometry once, then each tick what moved: links, the executed trace, plans, joint positions.

    Args:
        sinks: The recording's streams.
        poses: The tick's batch of moved bodies (shared with the products).
        geometry: "visual" (detailed meshes) or "collision" (coarse) geometry from the URDF.
    """

    def __init__(self, sinks: Sinks, poses: PoseBatch, geometry: str) -> None:
        self._sinks = sinks
        self._poses = poses
        self._geometry = geometry
        self._robot: RobotVisuals | None = None
        self._link_frame: dict[str, str] = {}  # link_poses key → transform frame id
        self._ee_link: str | None = None
        self._moved = MovedFilter()
        self._trace: list[np.ndarray] = []
        self._trace_logged_at = -np.inf
        self._trace_logged_len = 0
        self._last_q: np.ndarray | None = None
        # Logged every tick the arm moves: kept and sent in batches, like the moved bodies.
        self._executed_q: TickRows[np.ndarray] = TickRows(
            sinks, P.EXECUTED_POSITION, lambda rows: rr.Scalars.columns(scalars=np.array(rows))
        )

    def log_static(self, kitchen: SceneView) -> None:
        """The links' geometry and the joint series' names (static)."""
        self._log_robot_geometry(kitchen)
        # The paths' colours and widths never change: sent once, not with every strip.
        self._sinks.rec.log(
            P.EE_PATH, rr.LineStrips3D.from_fields(colors=[PLANNED], radii=[0.004]), static=True
        )
        self._sinks.rec.log(
            P.EE_EXECUTED, rr.LineStrips3D.from_fields(colors=[EXECUTED], radii=[0.003]), static=True
        )
        joints = list(kitchen.robot_config.arm_joints)
        for entity, suffix in _SERIES_SUFFIX.items():
            self._sinks.rec.log(entity, rr.SeriesLines(names=[f"{j}{suffix}" for j in joints]), static=True)

    def log_links(self, link_poses: Mapping[str, Pose]) -> None:
        """The links that moved (into the tick's batch); the end effector extends the executed trace."""
        ee = link_poses.get(self._ee_link) if self._ee_link is not None else None
        if ee is not None:
            self._extend_trace(np.asarray(ee[0], dtype=float))
        for name in self._moved.moved(link_poses):
            frame = self._link_frame.get(name)
            if frame is None:
                continue
            pose = link_poses[name]
            if name == "base" and self._robot is not None:
                pose = self._root_link_frame(pose)
            self._poses.add(frame, pose)

    def log_ee_path(self, path: np.ndarray) -> None:
        """A new plan's end-effector path (N, 3 metres); the executed trace starts again with it."""
        if path.ndim != 2 or path.shape[1] != 3:
            raise ConfigError(f"ee_path must be an (N, 3) array of metres, got shape {path.shape}")
        self._sinks.rec.log(P.EE_PATH, rr.LineStrips3D([path]))
        self.log_trace()  # finish the previous motion's trace, then start a new one with the new plan
        self._trace, self._trace_logged_len = [], 0

    def log_trajectory(self, traj: TimedTrajectory, start: float) -> None:
        """The planned joint positions and velocities, on the simulated time from ``start`` (seconds)."""
        if len(traj.times) == 0:
            return
        index = [sim_time_column(start + np.asarray(traj.times, dtype=float))]
        self._sinks.rec.send_columns(
            P.PLANNED_POSITION,
            indexes=index,
            columns=rr.Scalars.columns(scalars=np.asarray(traj.positions, dtype=float)),
        )
        self._sinks.rec.send_columns(
            P.PLANNED_VELOCITY,
            indexes=index,
            columns=rr.Scalars.columns(scalars=np.asarray(traj.velocities, dtype=float)),
        )

    def log_executed_q(self, executed_q: np.ndarray | Sequence[float]) -> None:
        """The executed joint positions (radians), when they changed."""
        q, last = np.asarray(executed_q, dtype=float), self._last_q
        if last is not None and q.shape != last.shape:
            self._executed_q.flush()  # a batch's rows are one array: another joint count starts a new batch
        changed = last is None or q.shape != last.shape or np.max(np.abs(q - last)) > 1e-6
        if changed:
            self._last_q = q
        # Kept every tick, with no row when nothing changed: what is kept still goes out in time.
        self._executed_q.keep(self._sinks.tick, self._sinks.now, [q] if changed else [])

    def flush(self) -> None:
        """Send the kept executed joint positions now (the recorder's flush and close call it)."""
        self._executed_q.flush()

    def log_trace(self) -> None:
        """The executed end-effector trace, if it grew since it was last logged."""
        if len(self._trace) >= 2 and len(self._trace) != self._trace_logged_len:
            self._trace_logged_at, self._trace_logged_len = self._sinks.now, len(self._trace)
            self._sinks.rec.log(P.EE_EXECUTED, rr.LineStrips3D([np.array(self._trace)]))

    def _extend_trace(self, position: np.ndarray) -> None:
        if self._trace and np.linalg.norm(position - self._trace[-1]) < _TRACE_STEP:
            return
        self._trace.append(position)
        if len(self._trace) > _TRACE_MAX:
            self._trace = self._trace[::2]  # keep the whole shape at half resolution
        # The whole strip is re-sent when it is logged, so it is logged a few times a second, not every tick.
        if self._sinks.now - self._trace_logged_at >= _TRACE_PERIOD:
            self.log_trace()

    def _log_robot_geometry(self, kitchen: SceneView) -> None:
        cfg = kitchen.robot_config
        robot = read_robot_visuals(cfg.urdf, self._geometry)
        self._robot = robot
        self._ee_link = cfg.end_effector_frame
        counts: dict[str, int] = {}
        for vis in robot.visuals:
            i = counts.get(vis.link, 0)
            counts[vis.link] = i + 1
            link_frame = f"{ROBOT_FRAME}/{vis.link}"
            link_entity = f"{P.ROBOT}/{slug(vis.link)}"
            if i == 0:
                self._link_frame["base" if vis.link == robot.root_link else vis.link] = link_frame
                self._sinks.rec.log(link_entity, rr.CoordinateFrame(link_frame), static=True)
            # Each piece sits in its own frame, fixed to the link frame by the URDF's visual origin.
            piece_frame = f"{link_frame}/geometry_{i}"
            self._sinks.rec.log(
                f"{link_entity}/geometry_{i}",
                rr.Transform3D(
                    translation=vis.position,
                    quaternion=rr.Quaternion(xyzw=vis.quaternion),
                    scale=vis.scale if vis.kind == "mesh" else None,
                    parent_frame=link_frame,
                    child_frame=piece_frame,
                ),
                rr.CoordinateFrame(piece_frame),
                _piece_geometry(vis),
                static=True,
            )
        for note in robot.skipped:
            self._sinks.rec.log(P.LOG, rr.TextLog(f"robot geometry: {note}", level=rr.TextLogLevel.WARN))

    def _root_link_frame(self, com_pose: Pose) -> Pose:
        """PyBullet gives the base at its centre of mass; shift it back to the URDF link frame."""
        assert self._robot is not None
        pos = np.asarray(com_pose[0], dtype=float)
        ip, iq = self._robot.root_inertial_position, self._robot.root_inertial_quaternion
        link = quat_multiply(com_pose[1], quat_inverse(iq))  # quaternions (x, y, z, w)
        link_pos = pos - quat_rotate(link, ip)
        return (tuple(map(float, link_pos)), tuple(map(float, link)))


def _piece_geometry(vis: LinkVisual) -> Any:
    """One URDF visual as a rerun archetype: its mesh, or a solid box, cylinder or ellipsoid."""
    colour = rgba255(vis.rgba)
    if vis.kind == "mesh":
        assert vis.mesh is not None
        return rr.Asset3D(path=vis.mesh, albedo_factor=colour)
    if vis.kind == "box":
        return rr.Boxes3D(sizes=[vis.size], colors=[colour], fill_mode="solid")
    if vis.kind == "cylinder":
        return rr.Cylinders3D(lengths=[vis.size[2]], radii=[vis.size[0]], colors=[colour], fill_mode="solid")
    return rr.Ellipsoids3D(half_sizes=[vis.size], colors=[colour], fill_mode="solid")
