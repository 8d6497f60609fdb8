"""rerun adapter: logs the static kitchen once and every tick's snapshot on the `tick` and `sim_time` timelines.

`Recorder` composes one drawer per thing the recording shows, each in its own module: the kitchen and its
products (`draw_kitchen`), the arm (`draw_arm`), what the robot perceives (`draw_perception`), its decisions and
κ̂ (`draw_decisions`), the person's trust (`draw_trust`), the behaviour tree (`draw_tree`) and the episode's
course (`draw_timeline`). Where the recording goes (a file, a live viewer) is `sinks`.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from scone_bt.errors import ConfigError, UnknownNameError
from scone_bt.viz.draw_arm import ArmDrawer
from scone_bt.viz.draw_decisions import DecisionDrawer
from scone_bt.viz.draw_kitchen import KitchenDrawer
from scone_bt.viz.draw_perception import PerceptionDrawer
from scone_bt.viz.draw_timeline import TimelineDrawer
from scone_bt.viz.draw_tree import TreeDrawer
from scone_bt.viz.draw_trust import TrustDrawer
from scone_bt.viz.pose_batch import PoseBatch
from scone_bt.viz.sinks import Sinks
from scone_bt.viz.snapshot import TickSnapshot
from scone_bt.viz.urdf_visuals import GEOMETRY_SOURCES

if TYPE_CHECKING:
    from scone_bt.viz.scene import SceneView

__all__ = ["Recorder"]


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
        self.robot_geometry = robot_geometry
        self.jpeg_quality = jpeg_quality
        self._sinks = Sinks(save, spawn_viewer, connect, recording_id, spawn_port)
        self._poses = PoseBatch(self._sinks)
        self._kitchen = KitchenDrawer(self._sinks, self._poses)
        self._arm = ArmDrawer(self._sinks, self._poses, robot_geometry)
        self._perception = PerceptionDrawer(self._sinks, jpeg_quality)
        self._decisions = DecisionDrawer(self._sinks)
        self._trust = TrustDrawer(self._sinks)
        self._tree = TreeDrawer(self._sinks)
        self._timeline = TimelineDrawer(self._sinks)
        self._closed = False
        self.ticks_logged = 0

    @property
    def recording_id(self) -> str:
        return self._sinks.recording_id

    @property
    def save_path(self) -> Path | None:
        return self._sinks.save_path

    @property
    def saved_to(self) -> Path | None:
        """Where the recording is once closed (`save`, or `unfinished_path(save)` after a run ended early)."""
        return self._sinks.saved_to

    @property
    def stream_error(self) -> str | None:
        """Why the live viewer stopped taking data (None while it does, or without one)."""
        return self._sinks.stream_error

    @property
    def viewer_attached(self) -> bool:
        """Whether a live viewer is still being streamed to (False without one, or once it was dropped)."""
        return self._sinks.viewer_attached

    def log_static_scene(self, kitchen: SceneView) -> None:
        """Log the kitchen once: scene boxes, robot geometry, object geometry, camera; then its current state."""
        self._kitchen.log_static(kitchen)
        self._arm.log_static(kitchen)
        self._kitchen.follow_specs(kitchen.specs)
        self._decisions.log_static()
        self._timeline.log_static()
        self._perception.log_static()
        # The initial state, so the scene is complete before the first tick.
        self._sinks.set_time(0, kitchen.sim_time)
        self._perception.log_configured_camera(kitchen.config.camera)
        self._arm.log_links(kitchen.link_poses())
        self._kitchen.log_objects(
            {n: (s.position, s.orientation) for n in kitchen.objects for s in [kitchen.object_state(n)]}
        )
        self._poses.send(0, kitchen.sim_time)

    def log_tick(self, snap: TickSnapshot) -> None:
        """Log everything of one tick; fields that are None or empty log nothing."""
        if self._closed:
            raise ConfigError("Recorder is closed; create a new one to log more ticks")
        self._sinks.set_time(snap.tick, snap.sim_time)
        self._timeline.log_sim_time(snap.tick, snap.sim_time)
        if snap.link_poses:
            self._arm.log_links(snap.link_poses)
        if snap.object_poses:
            self._kitchen.log_objects(snap.object_poses)
        self._poses.send(snap.tick, snap.sim_time)
        if snap.frame is not None:
            self._perception.log_frame(snap.frame, snap.detections)
        if snap.affordances is not None or snap.decision is not None:
            self._decisions.log_gate(snap.affordances, snap.decision, snap.contexts)
        if snap.ee_path is not None:
            self._arm.log_ee_path(np.asarray(snap.ee_path, dtype=float))
        if snap.trajectory is not None:
            self._arm.log_trajectory(snap.trajectory, snap.sim_time)
        if snap.executed_q is not None:
            self._arm.log_executed_q(snap.executed_q)
        if snap.tree is not None:
            self._tree.log_tree(snap.tree)
        self._decisions.log_confidences(snap.confidences)
        self._trust.log_trust(snap.person_trust)
        self._timeline.log_counters(snap.counters)
        if snap.recipe is not None:
            self._timeline.log_recipe(snap.recipe)
        self._timeline.log_lines(snap.log_lines)
        self.ticks_logged += 1
        self._sinks.check_viewer_now_and_then()

    def flush(self, timeout_s: float | None = None) -> bool:
        """Push everything logged so far to the sinks; False if a viewer did not take it within timeout_s.

        With a live viewer the wait is bounded (STREAM_FLUSH_TIMEOUT_S by default): a viewer that does not take
        the data in time is dropped (one warning line) and the recording goes on without it. A file-only
        recording waits until written.
        """
        self._poses.flush()
        self._arm.flush()
        self._timeline.flush()
        return self._sinks.flush(timeout_s)

    def close(self, complete: bool = True) -> None:
        """Flush everything to the sinks and finish the `.rrd` (closing twice is harmless).

        Args:
            complete: The run ended as it should; False (an interrupt, an error): the recording replaces no
                existing file at `save` and goes to `unfinished_path(save)` instead.
        """
        if self._closed:
            return
        self._closed = True
        self._arm.log_trace()  # at the last tick's time
        self._poses.flush()
        self._arm.flush()
        self._timeline.flush()
        self._sinks.close(complete)

    def __enter__(self) -> Recorder:
        return self

    def __exit__(self, exc_type: object, *exc: object) -> None:
        self.close(complete=exc_type is None)
