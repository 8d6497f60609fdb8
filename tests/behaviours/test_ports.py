"""The real collaborators and the fakes satisfy the interfaces the behaviours are written against."""

from __future__ import annotations

import pytest

from scone_bt.behaviours.ports import (
    AttemptHistory,
    HumanChannel,
    OutcomeRecorder,
    PlannerSeeds,
    SelfConfidence,
)
from scone_bt.confidence import make_estimator
from scone_bt.episode.seeds import PlannerSeedStream, SeedPlan
from scone_bt.events import EventLog
from scone_bt.experience.store import ExperienceStore
from scone_bt.human import SimulatedHuman
from scone_bt.motion.system import PickAndPlaceTask as MotionTask
from scone_bt.robot import MotionHandle, Robot, SimRobot
from scone_bt.study.tablet import TabletHuman
from tests.behaviours.fakes import FakeHandle, FakeHuman, FakeRobot


def _members(protocol: type) -> list[str]:
    return [n for n in vars(protocol) if not n.startswith("_")]


@pytest.mark.parametrize(
    ("cls", "protocol"),
    [
        (SimRobot, Robot),
        (MotionTask, MotionHandle),
        (ExperienceStore, OutcomeRecorder),
        (EventLog, AttemptHistory),
        (PlannerSeedStream, PlannerSeeds),
    ],
)
def test_real_classes_have_every_member_of_their_interface(cls, protocol) -> None:
    missing = [
        m
        for m in _members(protocol)
        if not hasattr(cls, m) and m not in getattr(cls, "__dataclass_fields__", {})
    ]
    assert not missing, f"{cls.__name__} lacks {missing}"


@pytest.mark.parametrize("cls", [SimulatedHuman, TabletHuman])
def test_the_humans_are_human_channels(cls) -> None:
    from types import SimpleNamespace

    from scone_bt.stocking import StockedStep

    recipe = SimpleNamespace(steps=(StockedStep("Add salt.", ("salt",)),))
    assert isinstance(cls(SimpleNamespace(sim_time=0.0), recipe), HumanChannel)


def test_fakes_and_instances_pass_the_runtime_checks() -> None:
    assert isinstance(FakeRobot(), Robot) and isinstance(FakeHandle(), MotionHandle)
    assert isinstance(FakeHuman(), HumanChannel)
    assert isinstance(make_estimator("knn", seed=0), SelfConfidence)
    assert isinstance(EventLog(), AttemptHistory) and isinstance(PlannerSeedStream(SeedPlan(0)), PlannerSeeds)
