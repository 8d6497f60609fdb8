"""The recorder's per-tick helpers: which bodies moved, the simulated-time column, the depth image's units and the
tree drawn from its last walk."""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

import numpy as np
import py_trees
import pytest
from rerun.time import to_nanos

from scone_bt.viz import paths as P
from scone_bt.viz import tick_rows
from scone_bt.viz.draw_arm import ArmDrawer
from scone_bt.viz.draw_perception import depth_millimetres
from scone_bt.viz.draw_tree import TreeDrawer
from scone_bt.viz.pose_batch import POSE_EPS, MovedFilter
from scone_bt.viz.render import flatten_tree
from scone_bt.viz.tick_rows import TickRows, sim_time_column

ORIGIN = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))


def at(x: float) -> tuple[tuple[float, float, float], tuple[float, float, float, float]]:
    return ((x, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))


def test_a_body_moved_when_a_coordinate_changed_by_more_than_eps_since_it_was_last_reported() -> None:
    f = MovedFilter()
    assert f.moved({"a": ORIGIN, "b": ORIGIN}) == ["a", "b"]  # first seen: moved
    assert f.moved({"a": ORIGIN, "b": ORIGIN}) == []
    half = 0.6 * POSE_EPS
    assert f.moved({"a": at(half), "b": ORIGIN}) == []
    # drift adds up against the last reported pose, not the last tick's
    assert f.moved({"a": at(2 * half), "b": ORIGIN}) == ["a"]
    assert f.moved({"a": at(2 * half), "b": ((0.0, 0.0, 0.0), (0.0, 0.0, 1e-3, 1.0))}) == ["b"]


def test_a_new_set_of_bodies_keeps_what_was_known_of_each() -> None:
    f = MovedFilter()
    f.moved({"a": ORIGIN, "b": at(1.0)})
    # "c" appears, "a" is gone: "b" keeps its last pose, "c" is new
    assert f.moved({"b": at(1.0), "c": ORIGIN}) == ["c"]
    assert f.moved({"a": ORIGIN, "b": at(1.0), "c": ORIGIN}) == ["a"]  # "a" was forgotten with its absence


def test_the_sim_time_column_rounds_as_rerun_set_time_does() -> None:
    # 0.49999999999999994 s (what adding 0.05 ten times gives) truncates to a nanosecond short of 0.5 s
    seconds = [0.0, 0.1, 0.3, 1 / 3, 66.2, 1234.5678901234, 0.49999999999999994, sum([0.05] * 10)]
    column = sim_time_column(seconds)
    nanos = [int(v) for v in column.as_arrow_array().cast("int64").to_pylist()]
    assert nanos == [to_nanos(s) for s in seconds]


def test_depth_is_logged_in_millimetres_with_no_reading_as_zero() -> None:
    depth = np.array([[np.nan, np.inf, -np.inf, -0.5, 0.0, 1.2345, 70.0]], dtype=np.float32)
    assert depth_millimetres(depth).tolist() == [[0, 0, 0, 0, 0, 1234, 65535]]
    assert depth_millimetres(depth).dtype == np.uint16


class _Sinks:
    def __init__(self) -> None:
        self.logged: list[tuple[str, Any]] = []
        self.rec = SimpleNamespace(log=lambda path, *a, **k: self.logged.append((path, a)))


def _texts(sinks: _Sinks) -> list[str]:
    return [str(a[0].text.as_arrow_array().to_pylist()[0]) for p, a in sinks.logged if p == P.TREE_TEXT]


def test_the_tree_is_drawn_from_its_last_walk_until_its_behaviours_change() -> None:
    """Most ticks change a feedback message only: the nodes are the last walk's with this tick's state, the
    same as a fresh walk; a behaviour added is walked again."""
    root = py_trees.composites.Sequence("Root", memory=False)
    leaf = py_trees.behaviours.Success("Leaf")
    root.add_children([leaf])
    sinks = _Sinks()
    drawer = TreeDrawer(sinks)  # type: ignore[arg-type]
    root.tick_once()
    drawer.log_tree(root)
    leaf.feedback_message = "holding the jar"
    drawer.log_tree(root)
    assert drawer._nodes == flatten_tree(root)
    assert "holding the jar" in _texts(sinks)[-1]
    logged = len(sinks.logged)
    drawer.log_tree(root)  # nothing changed: nothing logged
    assert len(sinks.logged) == logged
    root.add_children([py_trees.behaviours.Failure("Other")])
    root.tick_once()
    drawer.log_tree(root)
    assert drawer._nodes == flatten_tree(root)
    assert "Other" in _texts(sinks)[-1]


@pytest.mark.parametrize("status", ["SUCCESS", "FAILURE"])
def test_a_status_change_alone_redraws_the_node(status: str) -> None:
    root = py_trees.behaviours.Dummy("Only")
    sinks = _Sinks()
    drawer = TreeDrawer(sinks)  # type: ignore[arg-type]
    drawer.log_tree(root)
    root.status = py_trees.common.Status[status]
    drawer.log_tree(root)
    assert drawer._nodes[0].status == status
    assert f"only: {status.lower()}" in _texts(sinks)[-1].lower()


def _columns_sink() -> tuple[Any, list[tuple[str, list[int]]]]:
    sent: list[tuple[str, list[int]]] = []

    def send_columns(path, indexes, columns):  # noqa: ANN001 - rerun's own signature
        sent.append((str(path), indexes[0].as_arrow_array().to_pylist()))

    return SimpleNamespace(rec=SimpleNamespace(send_columns=send_columns), tick=0, now=0.0), sent


def test_kept_rows_go_out_within_the_wall_bound_even_when_nothing_more_changes(monkeypatch) -> None:
    """The arm comes to rest: its last rows are not held until something next moves."""
    clock = [0.0]
    monkeypatch.setattr(tick_rows.time, "monotonic", lambda: clock[0])
    sinks, sent = _columns_sink()
    rows: TickRows[float] = TickRows(sinks, "a", lambda r: {"values": r})  # type: ignore[arg-type]
    rows.keep(0, 0.0, [1.0])
    rows.keep(1, 0.1, [])
    assert sent == []
    clock[0] = tick_rows.BATCH_WALL_S
    rows.keep(2, 0.2, [])  # nothing new, but what is kept is due
    assert sent == [("a", [0])]
    rows.keep(3, 0.3, [])
    assert len(sent) == 1


def test_executed_joints_of_another_count_start_a_new_batch() -> None:
    """Rows of one batch are one array: a change in the joint count sends what was kept first, not a crash."""
    sinks, sent = _columns_sink()
    arm = ArmDrawer(sinks, poses=None, geometry="visual")  # type: ignore[arg-type]
    for tick, q in enumerate((np.zeros(7), np.ones(7), np.ones(9))):
        sinks.tick, sinks.now = tick, 0.1 * tick
        arm.log_executed_q(q)
    arm.flush()
    assert sent == [(P.EXECUTED_POSITION, [0, 1]), (P.EXECUTED_POSITION, [2])]


def test_a_pose_with_no_number_is_not_sent() -> None:
    f = MovedFilter()
    f.moved({"a": ORIGIN})
    assert f.moved({"a": ((float("nan"), 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))}) == []
    assert f.moved({"a": at(1.0)}) == ["a"]
