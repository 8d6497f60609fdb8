"""rerun adapter: logs the static kitchen once and every tick's snapshot on the `tick` and `sim_time` timelines."""

from __future__ import annotations

import atexit
import logging
import math
import shutil
import sys
import threading
import time
import uuid
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import py_trees
import rerun as rr
from scipy.spatial.transform import Rotation

from scone_bt.config.catalogue import Shape
from scone_bt.errors import ConfigError, UnknownNameError
from scone_bt.experience.types import ExecutionContext
from scone_bt.gate.types import Decision, DecisionKind
from scone_bt.perception.camera import intrinsics, world_from_camera
from scone_bt.viz import paths as P
from scone_bt.viz.blueprint import default_blueprint
from scone_bt.viz.connect import check_viewer_address
from scone_bt.viz.render import (
    STATUSES,
    TreeNode,
    affordances_markdown,
    decision_markdown,
    flatten_tree,
    layout_tree,
    rank_affordances,
    recipe_markdown,
    slug,
    tree_text,
)
from scone_bt.viz.save import unfinished_path
from scone_bt.viz.snapshot import AffordanceRow, Pose, RecipeView, TickSnapshot
from scone_bt.viz.urdf_visuals import GEOMETRY_SOURCES, RobotVisuals, read_robot_visuals

if TYPE_CHECKING:
    from scone_bt.config import ObjectSpec
    from scone_bt.motion.types import TimedTrajectory
    from scone_bt.perception.types import Detection, Frame
    from scone_bt.viz.scene import SceneView

__all__ = [
    "Recorder",
    "STREAM_FLUSH_TIMEOUT_S",
    "VIEWER_CHECK_PERIOD_S",
    "VIEWER_STALL_TIMEOUT_S",
    "unfinished_path",
]

APPLICATION_ID = "scone_bt"
STREAM_FLUSH_TIMEOUT_S = 3.0
"""Longest wait for a live viewer to take the buffered data at close (seconds); a gone viewer costs this once."""
VIEWER_CHECK_PERIOD_S = 2.0
"""How often (wall seconds) a live viewer is asked to take what was logged so far."""
VIEWER_STALL_TIMEOUT_S = 5.0
"""A live viewer that has not taken the data logged so far within this many seconds is dropped (the run goes on)."""

_log = logging.getLogger(__name__)


class _Nowhere:
    """A stream that takes everything and keeps nothing (a viewer-only recording whose viewer was dropped)."""

    def log(self, *args: Any, **kwargs: Any) -> None:
        pass

    send_columns = set_time = log

    def flush(self, **kwargs: Any) -> None:
        pass

    def disconnect(self) -> None:
        pass


class _Tee:
    """The file stream and the viewer stream as one: every call goes to both (each has its own sinks, so the
    viewer's can be dropped without touching the file's)."""

    def __init__(self, *streams: Any) -> None:
        self.streams = streams

    def log(self, *args: Any, **kwargs: Any) -> None:
        for stream in self.streams:
            stream.log(*args, **kwargs)

    def send_columns(self, *args: Any, **kwargs: Any) -> None:
        for stream in self.streams:
            stream.send_columns(*args, **kwargs)

    def set_time(self, *args: Any, **kwargs: Any) -> None:
        for stream in self.streams:
            stream.set_time(*args, **kwargs)


_SHUTDOWN_BOUNDED = False


def _bound_rerun_shutdown() -> None:
    """rerun's exit handler flushes every stream without a deadline: with a stalled viewer it would never return.

    It is replaced by one that waits at most STREAM_FLUSH_TIMEOUT_S (files are flushed by `Recorder.close`).
    """
    global _SHUTDOWN_BOUNDED
    if _SHUTDOWN_BOUNDED:
        return
    _SHUTDOWN_BOUNDED = True
    rr.unregister_shutdown()

    def bounded() -> None:
        worker = threading.Thread(target=rr.rerun_shutdown, name="rerun-shutdown", daemon=True)
        worker.start()
        worker.join(STREAM_FLUSH_TIMEOUT_S)

    atexit.register(bounded)


def _set_sinks(stream: Any, sinks: Sequence[Any], blueprint: Any) -> None:
    """``stream.set_sinks(*sinks, default_blueprint=blueprint)`` without rerun 0.41's leak of the blueprint stream.

    rerun builds the blueprint in a stream of its own whose memory sink and stream hold each other: it is never
    freed, and its two threads (batcher and sink) outlived every recording, four a recording with the default
    blueprint (`scone-bench soak --record`). The same steps as `rerun.sinks.set_sinks`, then that stream is
    disconnected once its contents are handed over, which breaks the cycle (the file keeps the blueprint).
    """
    from rerun import bindings
    from rerun.recording_stream import RecordingStream

    blueprint_stream = RecordingStream._from_native(
        bindings.new_blueprint(
            application_id=APPLICATION_ID, make_default=False, make_thread_default=False, default_enabled=True
        )
    )
    blueprint_stream.set_time("blueprint", sequence=0)
    blueprint.to_blueprint()._log_to_stream(blueprint_stream)
    storage = blueprint_stream.memory_recording().storage
    bindings.set_sinks(list(sinks), default_blueprint=storage, recording=stream.to_native())
    blueprint_stream.disconnect()


def _release_closed_streams() -> None:
    """Free the native side of recording streams no Python object holds any more (their threads with it).

    rerun drops a stream's native half only in this sweep (`rerun.init` runs it too); without it the batcher and
    sink threads of every closed recording stayed. It flushes what it frees without a deadline, so it runs only
    for recorders that never streamed to a viewer (a stalled viewer's stream would hold it forever).
    """
    from rerun import bindings

    bindings.flush_and_cleanup_orphaned_recordings()


_STATUS_COLOURS = {
    "SUCCESS": (46, 160, 67, 255),
    "FAILURE": (218, 54, 51, 255),
    "RUNNING": (230, 165, 20, 255),
    "INVALID": (140, 140, 140, 255),
}
_GATE_COLOURS = {"act": (46, 160, 67, 255), "ask": (230, 120, 20, 255), "idle": (140, 140, 140, 255)}
_SCENE_COLOURS = {"pedestal": (77, 77, 77, 255), "table": (140, 102, 64, 255), "floor": (225, 225, 225, 255)}
_SHELF_COLOUR = (191, 184, 166, 255)
_PALETTE = [
    (31, 119, 180),
    (255, 127, 14),
    (44, 160, 44),
    (214, 39, 40),
    (148, 103, 189),
    (140, 86, 75),
    (227, 119, 194),
    (23, 190, 207),
]
_ROBOT_FRAME = "robot"  # transform frame ids: robot/<link>, robot/<link>/geometry_<i>, object/<name>
_OBJECT_FRAME = "object"
_POSE_EPS = 1e-5  # metres / quaternion units: below this a link or object has not moved and is not re-logged
_TRACE_STEP = 0.005  # metres between points of the executed end-effector trace
_TRACE_MAX = 4000
_TRACE_PERIOD = 0.25  # simulated seconds between updates of the executed trace


def _moved(a: Pose | None, b: Pose) -> bool:
    # Plain Python: numpy's per-call overhead dominates for 3- and 4-vectors.
    if a is None:
        return True
    return any(abs(x - y) > _POSE_EPS for x, y in zip(a[0], b[0], strict=True)) or any(
        abs(x - y) > _POSE_EPS for x, y in zip(a[1], b[1], strict=True)
    )


def _tree_signature(root: Any) -> tuple[tuple[int, Any, str, int], ...]:
    """Identity, status, feedback and child count of every behaviour: equal signatures, nothing to log."""
    out = []
    stack = [root]
    while stack:
        behaviour = stack.pop()
        children = getattr(behaviour, "children", None) or ()
        out.append(
            (id(behaviour), behaviour.status, getattr(behaviour, "feedback_message", ""), len(children))
        )
        stack.extend(reversed(children))
    return tuple(out)


def _rgba255(rgba: Sequence[float]) -> tuple[int, int, int, int]:
    return tuple(int(round(255 * max(0.0, min(1.0, float(c))))) for c in rgba)


class Recorder:
    """Streams a SCONE-BT run to rerun: a `.rrd` file, a spawned viewer and/or a running viewer.

    Args:
        save: Write the recording to this `.rrd` file. It is written beside it and renamed into place when the
            recorder closes, so a recording already there stays whole until then; a run that ends early (an
            interrupt, an error) never replaces one: its recording goes beside it (`unfinished_path`).
        spawn_viewer: Start a native viewer and stream to it live.
        connect: Stream to a running viewer at this gRPC address (e.g. rerun+http://127.0.0.1:9876/proxy or
            host:port).
        recording_id: Id shared by everything logged in one run (several processes may log into one recording).
        robot_geometry: "visual" (detailed meshes, ~10 MB per recording for the Panda) or "collision" (coarse).
        jpeg_quality: RGB images are stored as JPEG of this quality (1-100); None stores raw pixels.
        spawn_port: Port of the spawned viewer.
    """

    def __init__(
        self,
        save: Path | str | None = None,
        spawn_viewer: bool = False,
        connect: str | None = None,
        recording_id: str | None = None,
        *,
        robot_geometry: str = "visual",
        jpeg_quality: int | None = 85,
        spawn_port: int = 9876,
    ) -> None:
        if save is None and not spawn_viewer and connect is None:
            raise ConfigError(
                "Recorder needs a sink: save=FILE.rrd, spawn_viewer=True or connect=ADDR (or use NullRecorder)"
            )
        if robot_geometry not in GEOMETRY_SOURCES:
            raise UnknownNameError("robot geometry source", robot_geometry, GEOMETRY_SOURCES)
        if jpeg_quality is not None and not 1 <= jpeg_quality <= 100:
            raise ConfigError(f"jpeg_quality must be in 1..100 or None, got {jpeg_quality}")
        self.save_path = Path(save) if save is not None else None
        self.robot_geometry = robot_geometry
        self.jpeg_quality = jpeg_quality
        # One stream per kind of sink, under one recording id: a stalled viewer is dropped without touching the
        # file (rerun can only replace a stream's sinks all at once, which would start the file again).
        self._recording_id = recording_id or str(uuid.uuid4())
        # Checked first: a bad, unreachable or silent address fails here, within seconds, before a file is begun.
        connect_url = check_viewer_address(connect) if connect is not None else None
        self._file_rec: Any = None
        self._view_rec: Any = None
        blueprint = default_blueprint()
        urls: list[str] = []
        if spawn_viewer or connect is not None:
            self._view_rec = self._stream()
        if spawn_viewer:
            rr.spawn(
                port=spawn_port, connect=False, executable_path=_viewer_executable(), recording=self._view_rec
            )
            urls.append(f"rerun+http://127.0.0.1:{spawn_port}/proxy")
        if connect_url is not None and connect_url not in urls:  # rerun refuses two sinks to one address
            urls.append(connect_url)
        self._viewer_urls = tuple(urls)
        if self._view_rec is not None:  # the viewer first: if it fails, no file was begun
            self._attach_viewer(blueprint)
        self._sink_path: Path | None = None
        self.saved_to: Path | None = None
        """Where the recording is once closed (`save`, or `unfinished_path(save)` after a run ended early)."""
        if self.save_path is not None:
            from scone_bt.files import temporary_beside

            self.save_path.parent.mkdir(parents=True, exist_ok=True)
            self._sink_path = temporary_beside(self.save_path, ".rrd")
            self._file_rec = self._stream()
            _set_sinks(self._file_rec, [rr.FileSink(str(self._sink_path))], blueprint)
        self._rec: Any = self._routing()
        self._viewer_checked_at = time.monotonic()
        self._closed = False
        self.stream_error: str | None = None
        """Why the live viewer stopped taking data (None while it does, or without one)."""
        self._robot: RobotVisuals | None = None
        self._link_frame: dict[str, str] = {}  # link_poses key → transform frame id
        self._pending: list[tuple[str, Pose]] = []  # moved bodies of this tick, sent together
        self._ee_link: str | None = None
        self._joint_names: list[str] = []
        self._specs: Mapping[str, ObjectSpec] = {}
        self._last_link: dict[str, Pose] = {}
        self._last_object: dict[str, Pose] = {}
        self._objects_drawn: set[str] = set()
        self._camera_pose: np.ndarray | None = None
        self._camera_k: np.ndarray | None = None
        self._camera_res: tuple[int, int] | None = None
        self._tree_shape: tuple[str, ...] = ()
        self._tree_signature: tuple[tuple[int, Any, str, int], ...] = ()
        self._tree_state: dict[str, tuple[str, str]] = {}
        self._tree_layout: dict[str, tuple[float, float]] = {}
        self._rows: list[AffordanceRow] = []
        self._contexts: dict[str, ExecutionContext] = {}
        self._decision: Decision | None = None
        self._recipe: RecipeView | None = None
        self._counters: dict[str, int] = {}
        self._named_series: set[str] = set()
        self._trace: list[np.ndarray] = []
        self._last_q: np.ndarray | None = None
        self._now = 0.0  # sim_time of the tick being logged
        self._trace_logged_at = -math.inf
        self._trace_logged_len = 0
        self.ticks_logged = 0

    # ------------------------------------------------------------------------------------------ public API
    @property
    def recording_id(self) -> str:
        return self._recording_id

    @property
    def viewer_attached(self) -> bool:
        """Whether a live viewer is still being streamed to (False without one, or once it was dropped)."""
        return self._view_rec is not None

    def log_static_scene(self, kitchen: SceneView) -> None:
        """Log the kitchen once: scene boxes, robot geometry, object geometry, camera; then its current state."""
        rec = self._rec
        rec.log(P.WORLD, rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
        for box in kitchen.static_boxes:
            colour = _SCENE_COLOURS.get(box.name, _SHELF_COLOUR)
            rec.log(
                f"{P.SCENE}/{slug(box.name)}",
                rr.Boxes3D(centers=[box.center], sizes=[box.size], colors=[colour], fill_mode="solid"),
                static=True,
            )
        scene = kitchen.config.scene
        rec.log(
            f"{P.SCENE}/floor",
            rr.Boxes3D(
                centers=[(0.3, 0.0, scene.floor_z - 0.005)],
                sizes=[(2.0, 2.0, 0.01)],
                colors=[_SCENE_COLOURS["floor"]],
                fill_mode="solid",
            ),
            static=True,
        )
        self._log_robot_geometry(kitchen)
        self._specs = kitchen.specs  # a live reference: objects spawned later are drawn when first seen

        cam = kitchen.config.camera
        self._joint_names = list(kitchen.robot_config.arm_joints)
        for entity in (P.PLANNED_POSITION, P.PLANNED_VELOCITY, P.EXECUTED_POSITION):
            suffix = {
                P.PLANNED_POSITION: " planned",
                P.PLANNED_VELOCITY: " velocity",
                P.EXECUTED_POSITION: " executed",
            }[entity]
            rec.log(entity, rr.SeriesLines(names=[f"{j}{suffix}" for j in self._joint_names]), static=True)
        rec.log(
            P.GATE_KIND,
            rr.StateConfiguration(values=list(_GATE_COLOURS), colors=list(_GATE_COLOURS.values())),
            static=True,
        )
        rec.log(P.EPISODE_SIM_TIME, rr.SeriesLines(names=["simulated time (s)"]), static=True)
        rec.log(P.GATE_CONFIDENCE, rr.SeriesLines(names=["chosen action κ̂"]), static=True)
        rec.log(P.GATE_RELEVANCE, rr.SeriesLines(names=["chosen action relevance"]), static=True)

        # The initial state, so the scene is complete before the first tick.
        self._set_time(0, kitchen.sim_time)
        self._log_camera(world_from_camera(cam), intrinsics(cam), (cam.width, cam.height))
        self._log_links(kitchen.link_poses())
        self._log_objects(
            {n: (s.position, s.orientation) for n in kitchen.objects for s in [kitchen.object_state(n)]}
        )
        self._send_poses(0, kitchen.sim_time)

    def log_tick(self, snap: TickSnapshot) -> None:
        """Log everything of one tick; fields that are None or empty log nothing."""
        if self._closed:
            raise ConfigError("Recorder is closed; create a new one to log more ticks")
        self._set_time(snap.tick, snap.sim_time)
        self._rec.log(P.EPISODE_SIM_TIME, rr.Scalars(float(snap.sim_time)))
        if snap.link_poses:
            self._log_links(snap.link_poses)
        if snap.object_poses:
            self._log_objects(snap.object_poses)
        self._send_poses(snap.tick, snap.sim_time)
        if snap.frame is not None:
            self._log_frame(snap.frame, snap.detections)
        if snap.affordances is not None or snap.decision is not None:
            self._log_gate(snap.affordances, snap.decision, snap.contexts)
        if snap.ee_path is not None:
            self._log_ee_path(np.asarray(snap.ee_path, dtype=float))
        if snap.trajectory is not None:
            self._log_trajectory(snap.trajectory, snap.sim_time)
        if snap.executed_q is not None:
            q = np.asarray(snap.executed_q, dtype=float)
            if (
                self._last_q is None
                or q.shape != self._last_q.shape
                or np.max(np.abs(q - self._last_q)) > 1e-6
            ):
                self._last_q = q
                self._rec.log(P.EXECUTED_POSITION, rr.Scalars(q))
        if snap.tree is not None:
            # a py_trees BehaviourTree is accepted as well as its root behaviour
            self._log_tree(
                snap.tree.root if isinstance(snap.tree, py_trees.trees.BehaviourTree) else snap.tree
            )
        for name, value in snap.confidences.items():
            if math.isfinite(value):
                self._log_scalar(P.CONFIDENCE, name, float(value))
        for name, value in snap.person_trust.items():
            if math.isfinite(value):
                self._log_scalar(P.PERSON_TRUST, name, float(value))
        for name, value in snap.counters.items():
            if self._counters.get(name) != value:
                self._counters[name] = int(value)
                self._log_scalar(P.COUNTERS, name, float(value), step=True)
        if snap.recipe is not None and snap.recipe != self._recipe:
            self._recipe = snap.recipe
            self._rec.log(
                P.RECIPE, rr.TextDocument(recipe_markdown(snap.recipe), media_type=rr.MediaType.MARKDOWN)
            )
        for line in snap.log_lines:
            self._rec.log(P.LOG, rr.TextLog(line, level=_log_level(line)))
        self.ticks_logged += 1
        if self._view_rec is not None and time.monotonic() - self._viewer_checked_at >= VIEWER_CHECK_PERIOD_S:
            self._check_viewer(VIEWER_STALL_TIMEOUT_S)

    def flush(self, timeout_s: float | None = None) -> bool:
        """Push everything logged so far to the sinks; False if a viewer did not take it within timeout_s.

        With a live viewer the wait is bounded (STREAM_FLUSH_TIMEOUT_S by default): a viewer that does not take
        the data in time is dropped (one warning line) and the recording goes on without it. A file-only
        recording waits until written.
        """
        ok = self._check_viewer(STREAM_FLUSH_TIMEOUT_S if timeout_s is None else timeout_s)
        if self._file_rec is not None:
            self._file_rec.flush(timeout_sec=1e38)
        return ok

    def close(self, complete: bool = True) -> None:
        """Flush everything to the sinks and finish the `.rrd` (closing twice is harmless).

        Args:
            complete: The run ended as it should; False (an interrupt, an error): the recording replaces no
                existing file at `save` and goes to `unfinished_path(save)` instead.
        """
        if self._closed:
            return
        self._closed = True
        self._log_trace()  # at the last tick's time
        self.flush()
        if self._view_rec is not None:
            # Disconnecting waits for the viewer without a deadline of its own: bounded here, on a worker thread.
            view = self._view_rec
            worker = threading.Thread(target=view.disconnect, name="rerun-viewer-close", daemon=True)
            worker.start()
            worker.join(STREAM_FLUSH_TIMEOUT_S)
            if worker.is_alive():
                self._view_rec = view  # reported (and left to the bounded exit) by _drop_viewer
                self._drop_viewer("disconnecting timed out", STREAM_FLUSH_TIMEOUT_S, disconnect=False)
            self._view_rec = None
        if self._file_rec is not None:
            self._file_rec.disconnect()
            self.saved_to = self._put_in_place(complete)
        self._rec = _Nowhere()
        self._file_rec = None  # the last reference: the stream is an orphan rerun can free
        if not self._viewer_urls:
            _release_closed_streams()

    def _put_in_place(self, complete: bool) -> Path:
        """Rename the finished file to `save` (or, for a run that ended early, beside an existing one)."""
        from scone_bt.files import replace_with

        assert self.save_path is not None and self._sink_path is not None
        target = self.save_path
        if not complete and target.exists():
            target = unfinished_path(target)
        replace_with(target, self._sink_path)
        return target

    def __enter__(self) -> Recorder:
        return self

    def __exit__(self, exc_type: object, *exc: object) -> None:
        self.close(complete=exc_type is None)

    # ------------------------------------------------------------------------------------------ pieces
    def _stream(self) -> Any:
        rec = rr.RecordingStream(APPLICATION_ID, recording_id=self._recording_id)
        rec.set_log_tick_enabled(False)  # our own `tick` timeline is the one that matters
        return rec

    def _routing(self) -> Any:
        """Where log calls go: the file and/or the viewer stream."""
        streams = [r for r in (self._file_rec, self._view_rec) if r is not None]
        if not streams:
            return _Nowhere()
        return streams[0] if len(streams) == 1 else _Tee(*streams)

    def _attach_viewer(self, blueprint: Any) -> None:
        """Give the viewer stream its gRPC sinks and the blueprint, within VIEWER_STALL_TIMEOUT_S.

        Sending the blueprint waits until the viewer took it, without a deadline: a peer that answers the
        handshake and then reads nothing would hold the robot before its first decision. So it runs on a
        worker thread, and a viewer that has not taken it in time is refused (ConfigError, one line).
        """
        sinks = [rr.GrpcSink(url) for url in self._viewer_urls]
        failed: list[BaseException] = []

        def attach() -> None:
            try:
                _set_sinks(self._view_rec, sinks, blueprint)
            except Exception as exc:  # noqa: BLE001 - re-raised on the caller's thread
                failed.append(exc)

        worker = threading.Thread(target=attach, name="rerun-viewer-attach", daemon=True)
        worker.start()
        worker.join(VIEWER_STALL_TIMEOUT_S)
        if worker.is_alive():
            self._view_rec = None
            _bound_rerun_shutdown()  # the stuck stream must not hold the process at exit either
            raise ConfigError(
                f"--connect {', '.join(self._viewer_urls)}: the viewer accepted the connection but did not take "
                f"the recording's first data within {VIEWER_STALL_TIMEOUT_S:g} s; is it a rerun viewer that "
                "responds? Record with --save and open the file later"
            )
        if failed:
            raise ConfigError(f"rerun viewer: {' '.join(str(failed[0]).split())}") from None

    def _check_viewer(self, timeout_s: float) -> bool:
        """Whether the live viewer took everything within timeout_s; if not it is dropped (True without one)."""
        self._viewer_checked_at = time.monotonic()
        if self._view_rec is None:
            return True
        try:
            self._view_rec.flush(timeout_sec=timeout_s)
        except RuntimeError as exc:  # rerun reports a gRPC sink that did not take the data this way
            self._drop_viewer(" ".join(str(exc).split()) or "flush timed out", timeout_s)
            return False
        return True

    def _drop_viewer(self, why: str, timeout_s: float, disconnect: bool = True) -> None:
        """Stop streaming to a viewer that stalled or went away; the recording file (if any) goes on."""
        view, self._view_rec = self._view_rec, None
        self.stream_error = why
        self._rec = self._routing()
        _bound_rerun_shutdown()
        if disconnect:  # it flushes without a deadline: a stalled viewer would hold it forever, so not here
            threading.Thread(target=view.disconnect, name="rerun-viewer-drop", daemon=True).start()
        _log.warning(
            "the live viewer at %s did not take the data within %g s (%s); it was dropped and the episode goes "
            "on%s",
            ", ".join(self._viewer_urls),
            timeout_s,
            why,
            f" (still recording to {self.save_path})" if self.save_path is not None else "",
        )

    def _set_time(self, tick: int, sim_time: float) -> None:
        self._now = float(sim_time)
        self._rec.set_time(P.TICK, sequence=int(tick))
        self._rec.set_time(P.SIM_TIME, duration=float(sim_time))

    def _log_robot_geometry(self, kitchen: SceneView) -> None:
        cfg = kitchen.robot_config
        robot = read_robot_visuals(cfg.urdf, self.robot_geometry)
        self._robot = robot
        self._ee_link = cfg.end_effector_frame
        counts: dict[str, int] = {}
        for vis in robot.visuals:
            i = counts.get(vis.link, 0)
            counts[vis.link] = i + 1
            link_frame = f"{_ROBOT_FRAME}/{vis.link}"
            link_entity = f"{P.ROBOT}/{slug(vis.link)}"
            if i == 0:
                self._link_frame["base" if vis.link == robot.root_link else vis.link] = link_frame
                self._rec.log(link_entity, rr.CoordinateFrame(link_frame), static=True)
            # Each piece sits in its own frame, fixed to the link frame by the URDF's visual origin.
            piece_frame = f"{link_frame}/geometry_{i}"
            scale = vis.scale if vis.kind == "mesh" else None
            colour = _rgba255(vis.rgba)
            if vis.kind == "mesh":
                assert vis.mesh is not None
                geometry: Any = rr.Asset3D(path=vis.mesh, albedo_factor=colour)
            elif vis.kind == "box":
                geometry = rr.Boxes3D(sizes=[vis.size], colors=[colour], fill_mode="solid")
            elif vis.kind == "cylinder":
                geometry = rr.Cylinders3D(
                    lengths=[vis.size[2]], radii=[vis.size[0]], colors=[colour], fill_mode="solid"
                )
            else:
                geometry = rr.Ellipsoids3D(half_sizes=[vis.size], colors=[colour], fill_mode="solid")
            self._rec.log(
                f"{link_entity}/geometry_{i}",
                rr.Transform3D(
                    translation=vis.position,
                    quaternion=vis.quaternion,
                    scale=scale,
                    parent_frame=link_frame,
                    child_frame=piece_frame,
                ),
                rr.CoordinateFrame(piece_frame),
                geometry,
                static=True,
            )
        for note in robot.skipped:
            self._rec.log(P.LOG, rr.TextLog(f"robot geometry: {note}", level=rr.TextLogLevel.WARN))

    def _root_link_frame(self, com_pose: Pose) -> Pose:
        """PyBullet gives the base at its centre of mass; shift it back to the URDF link frame."""
        assert self._robot is not None
        pos = np.asarray(com_pose[0], dtype=float)
        ip, iq = self._robot.root_inertial_position, self._robot.root_inertial_quaternion
        link = Rotation.from_quat(com_pose[1]) * Rotation.from_quat(iq).inv()  # quaternions (x, y, z, w)
        link_pos = pos - link.apply(ip)
        return (tuple(map(float, link_pos)), tuple(map(float, link.as_quat())))

    def _log_links(self, link_poses: Mapping[str, Pose]) -> None:
        for name, pose in link_poses.items():
            if name == self._ee_link:
                self._extend_trace(np.asarray(pose[0], dtype=float))
            frame = self._link_frame.get(name)
            if frame is None or not _moved(self._last_link.get(name), pose):
                continue
            self._last_link[name] = pose
            if name == "base" and self._robot is not None:
                pose = self._root_link_frame(pose)
            self._pending.append((frame, pose))

    def _send_poses(self, tick: int, sim_time: float) -> None:
        """All moved links and objects of this tick in one row batch: one call instead of one per body."""
        if not self._pending:
            return
        n = len(self._pending)
        frames = [f for f, _ in self._pending]
        translations = np.array([p[0] for _, p in self._pending], dtype=float)
        quaternions = np.array([p[1] for _, p in self._pending], dtype=float)
        self._pending = []
        self._rec.send_columns(
            P.POSES,
            indexes=[
                rr.TimeColumn(P.TICK, sequence=[tick] * n),
                rr.TimeColumn(P.SIM_TIME, duration=[sim_time] * n),
            ],
            columns=rr.Transform3D.columns(
                translation=translations,
                quaternion=quaternions,
                parent_frame=[f"tf#/{P.WORLD}"] * n,
                child_frame=frames,
            ),
        )

    def _extend_trace(self, position: np.ndarray) -> None:
        if self._trace and np.linalg.norm(position - self._trace[-1]) < _TRACE_STEP:
            return
        self._trace.append(position)
        if len(self._trace) > _TRACE_MAX:
            self._trace = self._trace[::2]  # keep the whole shape at half resolution
        # The whole strip is re-sent when it is logged, so it is logged a few times a second, not every tick.
        if self._now - self._trace_logged_at >= _TRACE_PERIOD:
            self._log_trace()

    def _log_trace(self) -> None:
        if len(self._trace) >= 2 and len(self._trace) != self._trace_logged_len:
            self._trace_logged_at, self._trace_logged_len = self._now, len(self._trace)
            self._rec.log(
                P.EE_EXECUTED,
                rr.LineStrips3D([np.array(self._trace)], colors=[(30, 120, 230)], radii=[0.003]),
            )

    def _log_objects(self, poses: Mapping[str, Pose]) -> None:
        for name, pose in poses.items():
            frame = f"{_OBJECT_FRAME}/{name}"
            if name not in self._objects_drawn:
                self._objects_drawn.add(name)
                self._log_object_geometry(name, f"{P.OBJECTS}/{slug(name)}", frame)
            if not _moved(self._last_object.get(name), pose):
                continue
            self._last_object[name] = pose
            self._pending.append((frame, pose))

    def _log_object_geometry(self, name: str, entity: str, frame: str) -> None:
        spec = self._specs.get(name)
        if spec is None:  # not from the catalogue: a marker-sized cube keeps it visible
            geometry: Any = rr.Boxes3D(
                sizes=[(0.05, 0.05, 0.05)], labels=[name], colors=[(200, 200, 200)], fill_mode="solid"
            )
        elif spec.shape == Shape.BOX:
            geometry = rr.Boxes3D(
                sizes=[spec.size], colors=[_rgba255(spec.rgba)], labels=[name], fill_mode="solid"
            )
        else:
            geometry = rr.Cylinders3D(
                lengths=[spec.size[2]],
                radii=[spec.size[0] / 2],
                colors=[_rgba255(spec.rgba)],
                labels=[name],
                fill_mode="solid",
            )
        self._rec.log(entity, rr.CoordinateFrame(frame), geometry, static=True)

    def _log_camera(self, world_from_camera: np.ndarray, k: np.ndarray, resolution: tuple[int, int]) -> None:
        if self._camera_pose is None or not np.allclose(self._camera_pose, world_from_camera, atol=1e-6):
            self._camera_pose = np.array(world_from_camera, dtype=float)
            rot = self._camera_pose[:3, :3]
            self._rec.log(
                P.CAMERA,
                rr.Transform3D(
                    translation=self._camera_pose[:3, 3], quaternion=Rotation.from_matrix(rot).as_quat()
                ),
            )
        if self._camera_k is None or not np.allclose(self._camera_k, k) or self._camera_res != resolution:
            self._camera_k, self._camera_res = np.array(k, dtype=float), resolution
            self._rec.log(
                P.IMAGE,
                rr.Pinhole(
                    image_from_camera=self._camera_k,
                    resolution=resolution,
                    camera_xyz=rr.ViewCoordinates.RDF,
                    image_plane_distance=0.25,
                ),
            )

    def _log_frame(self, frame: Frame, detections: Sequence[Detection]) -> None:
        h, w = frame.rgb.shape[:2]
        self._log_camera(frame.world_from_camera, frame.intrinsics, (w, h))
        self._rec.log(P.RGB, self._rgb_image(frame.rgb))
        # Millimetres in uint16: a quarter of the bytes of float32 metres, and cheaper to log.
        depth_mm = np.asarray(frame.depth, dtype=np.float32) * np.float32(1000.0)
        np.nan_to_num(depth_mm, copy=False, nan=0.0, posinf=0.0, neginf=0.0)
        np.clip(depth_mm, 0, 65535, out=depth_mm)
        self._rec.log(P.DEPTH, rr.DepthImage(depth_mm.astype(np.uint16), meter=1000.0, colormap="turbo"))
        if detections:
            boxes = np.array([d.bbox for d in detections], dtype=float)
            colours = [_PALETTE[d.track_id % len(_PALETTE)] for d in detections]
            labels = [
                f"{d.name} #{d.track_id} ({d.confidence:.2f})"
                if d.track_id >= 0
                else f"{d.name} ({d.confidence:.2f})"
                for d in detections
            ]
            self._rec.log(
                P.DETECTIONS_2D,
                rr.Boxes2D(array=boxes, array_format=rr.Box2DFormat.XYXY, labels=labels, colors=colours),
            )
            self._rec.log(
                P.DETECTIONS_3D,
                rr.Points3D(
                    [d.position for d in detections],
                    labels=[d.name for d in detections],
                    colors=colours,
                    radii=[0.01],
                ),
            )
        else:
            self._rec.log(P.DETECTIONS_2D, rr.Boxes2D.cleared())
            self._rec.log(P.DETECTIONS_3D, rr.Points3D.cleared())

    def _rgb_image(self, rgb: np.ndarray) -> Any:
        if self.jpeg_quality is None:
            return rr.Image(rgb, color_model="RGB")
        import cv2

        ok, buf = cv2.imencode(
            ".jpg", np.ascontiguousarray(rgb[..., ::-1]), [cv2.IMWRITE_JPEG_QUALITY, self.jpeg_quality]
        )
        if not ok:  # pragma: no cover - OpenCV refuses only malformed arrays
            return rr.Image(rgb, color_model="RGB")
        return rr.EncodedImage(contents=buf.tobytes(), media_type="image/jpeg")

    def _log_gate(
        self,
        rows: Sequence[AffordanceRow] | None,
        decision: Decision | None,
        contexts: Mapping[str, ExecutionContext] | None = None,
    ) -> None:
        if rows is not None:
            self._rows = rank_affordances(rows)
            self._contexts = dict(contexts or {})
            relevance = np.nan_to_num(np.array([r[1] for r in self._rows], dtype=float))
            confidence = np.nan_to_num(np.array([r[2] for r in self._rows], dtype=float))
            self._rec.log(P.AFFORDANCE_RELEVANCE, rr.BarChart(relevance, color=(31, 119, 180)))
            self._rec.log(P.AFFORDANCE_CONFIDENCE, rr.BarChart(confidence, color=(44, 160, 44)))
        if decision is not None:
            self._decision = decision
            self._rec.log(
                P.GATE_DECISION,
                rr.TextDocument(decision_markdown(decision), media_type=rr.MediaType.MARKDOWN),
            )
            self._rec.log(P.GATE_KIND, rr.StateChange(state=[decision.kind.value]))
            if decision.kind is not DecisionKind.IDLE and math.isfinite(decision.confidence):
                self._rec.log(P.GATE_CONFIDENCE, rr.Scalars(float(decision.confidence)))
                self._rec.log(P.GATE_RELEVANCE, rr.Scalars(float(decision.relevance)))
            level = rr.TextLogLevel.WARN if decision.kind is DecisionKind.ASK else rr.TextLogLevel.INFO
            self._rec.log(
                P.LOG,
                rr.TextLog(
                    f"gate: {decision.kind.value} {decision.action or ''} — {decision.reason}", level=level
                ),
            )
        self._rec.log(
            P.AFFORDANCE_TABLE,
            rr.TextDocument(
                affordances_markdown(self._rows, self._decision, self._contexts),
                media_type=rr.MediaType.MARKDOWN,
            ),
        )

    def _log_ee_path(self, path: np.ndarray) -> None:
        if path.ndim != 2 or path.shape[1] != 3:
            raise ConfigError(f"ee_path must be an (N, 3) array of metres, got shape {path.shape}")
        self._rec.log(P.EE_PATH, rr.LineStrips3D([path], colors=[(230, 120, 20)], radii=[0.004]))
        self._log_trace()  # finish the previous motion's trace, then start a new one with the new plan
        self._trace, self._trace_logged_len = [], 0

    def _log_trajectory(self, traj: TimedTrajectory, start: float) -> None:
        if len(traj.times) == 0:
            return
        index = [rr.TimeColumn(P.SIM_TIME, duration=start + np.asarray(traj.times, dtype=float))]
        self._rec.send_columns(
            P.PLANNED_POSITION,
            indexes=index,
            columns=rr.Scalars.columns(scalars=np.asarray(traj.positions, dtype=float)),
        )
        self._rec.send_columns(
            P.PLANNED_VELOCITY,
            indexes=index,
            columns=rr.Scalars.columns(scalars=np.asarray(traj.velocities, dtype=float)),
        )

    def _log_tree(self, root: Any) -> None:
        signature = _tree_signature(root)
        if signature == self._tree_signature:
            return
        self._tree_signature = signature
        nodes = flatten_tree(root)
        shape = tuple(n.node_id for n in nodes)
        if shape != self._tree_shape:
            self._tree_shape = shape
            self._tree_state = {}
            self._tree_layout = layout_tree(nodes)
            edges = [(n.parent, n.node_id) for n in nodes if n.parent is not None]
            self._rec.log(P.TREE_GRAPH, rr.GraphEdges(edges, graph_type="directed"))
            for node in nodes:
                self._rec.log(
                    f"{P.TREE_STATUS}/{node.node_id}",
                    rr.StateConfiguration(
                        values=list(STATUSES), colors=[_STATUS_COLOURS[s] for s in STATUSES]
                    ),
                    static=True,
                )
        changed = False
        for node in nodes:
            state = (node.status, node.feedback)
            previous = self._tree_state.get(node.node_id)
            if previous == state:
                continue
            changed = True
            if previous is None or previous[0] != node.status:
                self._rec.log(f"{P.TREE_STATUS}/{node.node_id}", rr.StateChange(state=[node.status]))
            self._tree_state[node.node_id] = state
        if changed:
            self._log_tree_views(nodes)

    def _log_tree_views(self, nodes: list[TreeNode]) -> None:
        self._rec.log(
            P.TREE_GRAPH,
            rr.GraphNodes(
                [n.node_id for n in nodes],
                positions=[self._tree_layout[n.node_id] for n in nodes],
                labels=[f"{n.name}: {n.status.lower()}" for n in nodes],
                colors=[_STATUS_COLOURS.get(n.status, _STATUS_COLOURS["INVALID"]) for n in nodes],
                radii=[10.0 if n.is_leaf else 14.0 for n in nodes],
            ),
        )
        self._rec.log(P.TREE_TEXT, rr.TextDocument(tree_text(nodes)))

    def _log_scalar(self, root: str, name: str, value: float, step: bool = False) -> None:
        entity = f"{root}/{slug(name)}"
        if entity not in self._named_series:
            self._named_series.add(entity)
            mode = rr.components.InterpolationMode.StepAfter if step else None
            self._rec.log(entity, rr.SeriesLines(names=[name], interpolation_mode=mode), static=True)
        self._rec.log(entity, rr.Scalars(value))


def _viewer_executable() -> str:
    """The `rerun` viewer beside this interpreter (a venv's scripts need not be on PATH), else from PATH."""
    beside = Path(sys.executable).parent / "rerun"
    found = str(beside) if beside.is_file() else shutil.which("rerun")
    if found is None:
        raise ConfigError(
            "cannot spawn the rerun viewer: no 'rerun' executable beside Python or on PATH (pip install rerun-sdk)"
        )
    return found


def _log_level(line: str) -> str:
    head = line.lstrip().lower()
    if head.startswith(("error", "failed", "failure")):
        return rr.TextLogLevel.ERROR
    if head.startswith(("warn", "ask", "help")):
        return rr.TextLogLevel.WARN
    return rr.TextLogLevel.INFO
