"""The rerun recorder end to end: a short synthetic episode is saved and read back with rerun's own API."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import py_trees
import pytest

from scone_bt.errors import ConfigError, UnknownNameError
from scone_bt.gate.types import Decision, DecisionKind
from scone_bt.motion.types import TimedTrajectory
from scone_bt.perception.camera import intrinsics, world_from_camera
from scone_bt.perception.types import Detection, Frame
from scone_bt.viz import NullRecorder, RecipeView, Recorder, TickSnapshot
from scone_bt.viz.readback import body_poses, component_values, summarize_recording

TICKS = 12
FRAME_TICKS = (0, 4, 8)
OBJECTS = ("salt", "black pepper", "flour")


def gate_tree() -> py_trees.behaviour.Behaviour:
    root = py_trees.composites.Sequence("Cook", memory=False)
    gate = py_trees.composites.Selector("Gate", memory=False)
    confident = py_trees.behaviours.SuccessEveryN("Confident?", n=3)
    gate.add_children([confident, py_trees.behaviours.Running("Ask for help")])
    root.add_children(
        [py_trees.behaviours.Success("Perceive"), gate, py_trees.behaviours.Success("Pick and place")]
    )
    return root


def frame_at(kitchen, tick: int) -> Frame:
    cam = kitchen.config.camera
    rng = np.random.default_rng(tick)
    return Frame(
        rgb=rng.integers(0, 255, (cam.height, cam.width, 3), dtype=np.uint8),
        depth=rng.uniform(0.5, 1.5, (cam.height, cam.width)).astype(np.float32),
        intrinsics=intrinsics(cam),
        world_from_camera=world_from_camera(cam),
        sim_time=kitchen.sim_time,
    )


def run_episode(kitchen, recorder) -> None:
    """Move the arm, tick a tree and log a snapshot per tick, the way the integrated tree does."""
    kitchen.spawn([kitchen.config.catalogue.get(n) for n in OBJECTS], np.random.default_rng(0))
    recorder.log_static_scene(kitchen)
    home = np.array(kitchen.robot_config.home)
    tree = gate_tree()
    traj_t = np.linspace(0.0, 0.5, 121)
    trajectory = TimedTrajectory(
        times=traj_t,
        positions=home + np.outer(traj_t, np.full(7, 0.4)),
        velocities=np.tile(np.full(7, 0.4), (len(traj_t), 1)),
        accelerations=np.zeros((len(traj_t), 7)),
    )
    wrapped = py_trees.trees.BehaviourTree(tree)  # the recorder takes either the tree or its root
    for tick in range(TICKS):
        target = home + 0.3 * np.sin(0.5 * tick) * np.eye(7)[0]
        kitchen.hold_arm(target)
        kitchen.advance(0.05)
        tree.tick_once()
        frame = frame_at(kitchen, tick) if tick in FRAME_TICKS else None
        detections = [
            Detection(
                name, i, kitchen.object_state(name).position, 0.0, 0.9, (50 + 60 * i, 80, 100 + 60 * i, 160)
            )
            for i, name in enumerate(OBJECTS)
        ]
        rows = [(f"Put {n} on table", 0.9 - 0.2 * i, 0.3 + 0.2 * i) for i, n in enumerate(OBJECTS)]
        decision = None
        if tick == 4:
            decision = Decision(
                DecisionKind.ASK, "Put salt on table", 0.9, 0.3, "confidence 0.30 below gate 0.50"
            )
        elif tick == 8:
            decision = Decision(DecisionKind.ACT, "Put black pepper on table", 0.7, 0.5, "confident enough")
        snap = TickSnapshot(
            tick=tick,
            sim_time=kitchen.sim_time,
            link_poses=kitchen.link_poses(),
            object_poses={
                n: (s.position, s.orientation) for n in kitchen.objects for s in [kitchen.object_state(n)]
            },
            frame=frame,
            detections=detections if frame is not None else (),
            affordances=rows if frame is not None else None,
            decision=decision,
            ee_path=np.linspace((0.3, 0.0, 0.5), (0.4, 0.3, 0.2), 20) if tick == 8 else None,
            trajectory=trajectory if tick == 8 else None,
            executed_q=kitchen.arm_joint_positions(),
            tree=wrapped if tick % 2 else tree,
            confidences={n: 0.3 + 0.01 * tick for n in OBJECTS} if tick % 4 == 0 else {},
            person_trust={n: 0.7 - 0.01 * tick for n in OBJECTS} if tick % 4 == 0 else {},
            counters={
                "successes": tick // 6,
                "failures": 0,
                "help requests": int(tick >= 4),
                "interventions": 0,
            },
            recipe=RecipeView(
                "Pasta", ("Boil water", "Add salt"), 1 if tick < 10 else None, (True, tick >= 10)
            ),
            log_lines=[f"tick {tick}"],
        )
        recorder.log_tick(snap)


@pytest.fixture(scope="module")
def recording(tmp_path_factory, kitchen_cfg, robot_cfg):
    from scone_bt.world import Kitchen

    path = tmp_path_factory.mktemp("viz") / "episode.rrd"
    with Kitchen(kitchen_cfg, robot_cfg) as kitchen, Recorder(save=path, robot_geometry="collision") as rec:
        run_episode(kitchen, rec)
        assert rec.ticks_logged == TICKS
    return path


def test_recording_holds_every_tick_and_the_expected_entities(recording):
    summary = summarize_recording(recording)
    assert summary.application_id == "scone_bt"
    assert summary.ticks == tuple(range(TICKS))
    assert summary.has_blueprint
    expected = {
        "/world",
        "/world/scene/table",
        "/world/scene/shelf_tier0",
        "/world/scene/shelf_tier2",
        "/world/poses",
        "/world/robot/panda_link0",
        "/world/robot/panda_link0/geometry_0",
        "/world/robot/panda_link7",
        "/world/robot/panda_hand/geometry_0",
        "/world/objects/salt",
        "/world/objects/black_pepper",
        "/world/camera",
        "/world/camera/image",
        "/world/camera/image/rgb",
        "/world/camera/image/depth",
        "/world/camera/image/detections",
        "/world/detections",
        "/world/plan/ee_path",
        "/world/plan/ee_executed",
        "/affordances/table",
        "/affordances/relevance",
        "/affordances/confidence",
        "/gate/decision",
        "/gate/kind",
        "/tree/graph",
        "/tree/text",
        "/tree/status/Cook",
        "/tree/status/Cook/Gate/Ask_for_help",
        "/confidence/black_pepper",
        "/person_trust/black_pepper",
        "/counters/help_requests",
        "/trajectory/planned/position",
        "/trajectory/planned/velocity",
        "/trajectory/executed/position",
        "/recipe",
        "/log",
    }
    assert expected <= summary.entity_paths, sorted(expected - summary.entity_paths)


def test_images_and_trajectories_are_logged_once_per_new_item(recording):
    summary = summarize_recording(recording)
    assert summary.rows["/world/camera/image/rgb"] == len(FRAME_TICKS)
    # one depth image per frame, plus the static unit and colour map
    assert summary.rows["/world/camera/image/depth"] == len(FRAME_TICKS) + 1
    # 121 samples of the planned trajectory plus the static series names
    assert summary.rows["/trajectory/planned/position"] == 121 + 1
    assert summary.rows["/trajectory/executed/position"] == TICKS + 1
    assert summary.rows["/gate/decision"] == 2
    # a tick in which nothing changed is still in the recording: simulated time is logged every tick
    assert summary.rows["/episode/sim_time"] == TICKS + 1
    # help requests went 0 → 1 once: logged on change only (+ static series style)
    assert summary.rows["/counters/help_requests"] == 2 + 1


def test_moving_links_are_reposed_and_the_base_sits_at_its_urdf_frame(recording, kitchen_cfg):
    poses = body_poses(recording)
    assert {"robot/panda_link0", "robot/panda_hand", "object/salt", "object/black pepper"} <= set(poses)
    assert "robot/panda_link8" not in poses  # no geometry, nothing to pose
    shoulder = poses["robot/panda_link2"]
    assert len(shoulder) >= TICKS // 2  # the arm moved on most ticks
    assert len({t for t, _ in shoulder}) == len(shoulder)  # at most one pose per tick
    # PyBullet reports the base at its centre of mass (z = 0.05); the viewer shows the link frame (z = 0)
    assert poses["robot/panda_link0"][0][1] == pytest.approx((0.0, 0.0, 0.0), abs=1e-6)
    camera = component_values(recording, "/world/camera", "Transform3D:translation")
    assert camera[0][1][0] == pytest.approx(list(kitchen_cfg.camera.position))


def test_tree_status_changes_are_logged_per_node(recording):
    confident = component_values(recording, "/tree/status/Cook/Gate/Confident", "StateChange:state")
    states = [v[0] for _, v in confident]
    assert "SUCCESS" in states and "FAILURE" in states
    assert all(a != b for a, b in zip(states, states[1:], strict=False))  # only changes are logged
    gate = component_values(recording, "/gate/kind", "StateChange:state")
    assert [(t, v[0]) for t, v in gate] == [(4, "ask"), (8, "act")]


def test_recorder_needs_a_sink_and_valid_options(tmp_path):
    with pytest.raises(ConfigError, match="needs a sink"):
        Recorder()
    with pytest.raises(UnknownNameError, match="valid: collision, visual"):
        Recorder(save=tmp_path / "x.rrd", robot_geometry="pretty")
    with pytest.raises(ConfigError, match="jpeg_quality"):
        Recorder(save=tmp_path / "x.rrd", jpeg_quality=0)


def test_closed_recorder_refuses_ticks(tmp_path):
    rec = Recorder(save=tmp_path / "x.rrd")
    rec.close()
    rec.close()
    with pytest.raises(ConfigError, match="closed"):
        rec.log_tick(TickSnapshot(tick=0, sim_time=0.0))


def test_null_recorder_counts_and_does_not_import_rerun():
    rec = NullRecorder()
    rec.log_tick(TickSnapshot(tick=0, sim_time=0.0))
    rec.close()
    assert rec.ticks_logged == 1
    code = "import sys; from scone_bt.viz import NullRecorder, TickSnapshot; NullRecorder(); print('rerun' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


def test_tree_text_and_recipe_documents_hold_the_latest_state(recording):
    text = component_values(recording, "/tree/text", "TextDocument:text")
    assert "[✓] Perceive: success" in text[-1][1][0]
    recipe = component_values(recording, "/recipe", "TextDocument:text")
    assert len(recipe) == 2  # logged when it changed, not every tick
    assert recipe[-1][0] == 10 and "✔ ~~Add salt~~" in recipe[-1][1][0]


def test_readback_rejects_missing_and_foreign_files(tmp_path):
    with pytest.raises(ConfigError, match="no recording at"):
        summarize_recording(tmp_path / "missing.rrd")
    junk = tmp_path / "junk.rrd"
    junk.write_bytes(b"not a recording")
    with pytest.raises(ConfigError, match="not a readable .rrd"):
        summarize_recording(junk)


def test_quiet_ticks_are_still_recorded(tmp_path):
    path = tmp_path / "quiet.rrd"
    with Recorder(save=path, robot_geometry="collision") as rec:
        rec.log_tick(TickSnapshot(tick=5, sim_time=1.0))
        rec.log_tick(TickSnapshot(tick=6, sim_time=1.0))  # planning: simulated time stands still
    assert summarize_recording(path).ticks == (5, 6)


def _log_something(rec: Recorder) -> None:
    rec.log_tick(TickSnapshot(tick=0, sim_time=0.0))
    rec.flush()


def test_a_recording_replaces_the_file_only_when_it_is_complete(tmp_path):
    from scone_bt.checks import is_output_kind

    save = tmp_path / "run.rrd"
    save.write_bytes(b"RRF2 the previous run")
    rec = Recorder(save=save, robot_geometry="collision")
    _log_something(rec)
    assert save.read_bytes() == b"RRF2 the previous run"  # written beside it meanwhile
    rec.close()
    assert rec.saved_to == save and is_output_kind(save, "rrd") and save.stat().st_size > 100
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.rrd"]  # no temporary file left


def test_a_run_that_ended_early_never_replaces_a_recording(tmp_path):
    save = tmp_path / "run.rrd"
    save.write_bytes(b"RRF2 the previous run")
    (tmp_path / "run.unfinished.rrd").write_text("my notes, not a recording")
    with pytest.raises(KeyboardInterrupt), Recorder(save=save, robot_geometry="collision") as rec:
        _log_something(rec)
        raise KeyboardInterrupt
    assert save.read_bytes() == b"RRF2 the previous run"
    assert rec.saved_to == tmp_path / "run.unfinished-2.rrd"  # beside both, overwriting neither
    assert (tmp_path / "run.unfinished.rrd").read_text() == "my notes, not a recording"
    assert rec.saved_to.stat().st_size > 100
    # Without a recording there, the unfinished one takes its place (nothing to lose).
    fresh = tmp_path / "fresh.rrd"
    rec = Recorder(save=fresh, robot_geometry="collision")
    _log_something(rec)
    rec.close(complete=False)
    assert rec.saved_to == fresh and fresh.stat().st_size > 100
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]


def test_closed_recorders_leave_no_threads_behind_and_each_file_has_its_blueprint(tmp_path):
    # rerun kept every closed recording's native stream, and its blueprint's, with their batcher and sink
    # threads: four more OS threads per recorded episode of a long-running process (scone-bench soak --record).
    from scone_bt.process_stats import process_sample

    def record(i: int) -> int:
        with Recorder(save=tmp_path / f"{i}.rrd", recording_id=f"r{i}") as rec:
            rec._sinks.rec.log("probe", __import__("rerun").Points3D([[0.0, 0.0, 0.0]]))
        return process_sample()[2]

    first = record(0)
    assert [record(i) for i in range(1, 4)] == [first] * 3
    assert all(summarize_recording(tmp_path / f"{i}.rrd").has_blueprint for i in range(4))


def test_moved_bodies_and_sim_time_go_out_in_batches_with_each_rows_own_tick(monkeypatch) -> None:
    """One send_columns call per BATCH_TICKS ticks (or BATCH_WALL_S), not per tick; a flush sends what is kept, and
    every row keeps the tick and simulated time it was logged at."""
    from types import SimpleNamespace

    from scone_bt.viz import pose_batch, tick_rows
    from scone_bt.viz.draw_timeline import TimelineDrawer

    sent: list[tuple[str, list[int]]] = []

    def send_columns(path, indexes, columns):  # noqa: ANN001 - rerun's own signature
        ticks = indexes[0].as_arrow_array().to_pylist()
        sent.append((str(path), ticks))

    sinks = SimpleNamespace(rec=SimpleNamespace(send_columns=send_columns))
    monkeypatch.setattr(tick_rows.time, "monotonic", lambda: 0.0)  # no wall time passes: batches by ticks
    poses = pose_batch.PoseBatch(sinks)  # type: ignore[arg-type]
    timeline = TimelineDrawer(sinks)  # type: ignore[arg-type]
    pose = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))
    for tick in range(tick_rows.BATCH_TICKS + 3):
        poses.add("tf#/a", pose)
        poses.add("tf#/b", pose)
        poses.send(tick, tick * 0.1)
        timeline.log_sim_time(tick, tick * 0.1)
    first = list(range(tick_rows.BATCH_TICKS))
    assert sent == [("world/poses", [t for t in first for _ in (0, 1)]), ("episode/sim_time", first)]
    poses.send(99, 9.9)  # nothing moved: nothing kept
    poses.flush()
    timeline.flush()
    rest = list(range(tick_rows.BATCH_TICKS, tick_rows.BATCH_TICKS + 3))
    assert sent[2:] == [("world/poses", [t for t in rest for _ in (0, 1)]), ("episode/sim_time", rest)]
    poses.flush()  # nothing left: nothing sent
    assert len(sent) == 4
