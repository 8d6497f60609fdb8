"""PickAndPlace takes what stands on the table from the table detections, never from the simulator (fakes only)."""

from __future__ import annotations

from types import SimpleNamespace

import py_trees
import pytest

from scone_bt.behaviours import Keys
from scone_bt.behaviours.pick_and_place import PickAndPlace
from scone_bt.behaviours.services import EpisodeStats
from scone_bt.config import ObjectSpec
from scone_bt.perception.types import Detection

SPECS = {
    n: ObjectSpec(n, (), "cylinder", (0.05, 0.05, h), 0.2, 0.6, "test", (1, 1, 1, 1), i)
    for i, (n, h) in enumerate((("salt", 0.1), ("honey", 0.12), ("oil", 0.22)))
}


class _Task:
    def start(self) -> None:
        self.started = True


class _Motion:
    def __init__(self) -> None:
        self.calls: list[dict] = []

    def pick_and_place(self, target, spec, obstacles, rng_seed, table_obstacles=None):
        self.calls.append(dict(target=target, spec=spec, obstacles=obstacles, table=table_obstacles))
        return _Task()


def _det(name, xyz):
    return Detection(name, 0, xyz, 0.0, 1.0, (0, 0, 1, 1))


@pytest.fixture
def behaviour():
    py_trees.blackboard.Blackboard.clear()
    motion = _Motion()
    human = SimpleNamespace(robot_busy=lambda busy: None, decide_takeover=lambda name: None)
    services = SimpleNamespace(
        motion=lambda: motion,
        # No kitchen with true poses: reading ground truth would raise.
        kitchen=SimpleNamespace(),
        kitchen_config=SimpleNamespace(catalogue=SimpleNamespace(get=SPECS.__getitem__)),
        options=SimpleNamespace(seed=4),
        stats=EpisodeStats(),
        human=human,
        emit=lambda *a, **k: None,
    )
    node = PickAndPlace("PickAndPlace", services)
    node.setup()
    writer = py_trees.blackboard.Client(name="test")
    for key in (Keys.DECISION, Keys.AFFORDANCES, Keys.DETECTIONS, Keys.TABLE_DETECTIONS):
        writer.register_key(key=key, access=py_trees.common.Access.WRITE)
    target = _det("salt", (0.5, 0.3, 0.16))
    writer.set(Keys.DECISION, SimpleNamespace(action="Put salt on table", confidence=0.9))
    writer.set(
        Keys.AFFORDANCES,
        [SimpleNamespace(text="Put salt on table", object_name="salt", detection=target)],
    )
    writer.set(Keys.DETECTIONS, [target, _det("honey", (0.5, 0.4, 0.18))])
    return node, motion, writer


def test_without_a_table_camera_the_robot_knows_only_its_own_placements(behaviour):
    node, motion, _ = behaviour
    node.initialise()
    (call,) = motion.calls
    assert call["table"] is None  # the motion system then uses what it placed itself
    assert [d.name for d, _ in call["obstacles"]] == ["honey"]
    assert call["spec"] is SPECS["salt"]


def test_table_obstacles_come_from_the_table_detections_with_catalogue_sizes(behaviour):
    node, motion, writer = behaviour
    writer.set(Keys.TABLE_DETECTIONS, (_det("oil", (0.4, -0.4, 0.22)), _det("salt", (0.5, -0.3, 0.1))))
    node.initialise()
    (call,) = motion.calls
    assert [(d.name, s) for d, s in call["table"]] == [("oil", SPECS["oil"])]  # the target itself is left out
