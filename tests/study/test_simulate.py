import pytest

from scone_bt.errors import SconeError
from scone_bt.study.design import Condition, Group
from scone_bt.study.simulate import SimulationOptions, simulate_study
from scone_bt.study.synthetic import SyntheticOptions, SyntheticRobot, run_synthetic_episode
from scone_bt.study.trust import SimulatedParticipant


def _robot():
    return SyntheticRobot(
        success={"salt": 1.0, "flour": 0.0, "egg carton": 0.0},
        confidence={"salt": 0.9, "flour": 0.1, "egg carton": 0.8},
    )


def test_synthetic_episode_follows_the_tree_rules():
    events = []
    calm = SimulatedParticipant("S", Group.A, seed=0)
    calm.params = calm.params.__class__(max_takeover=0.0)
    opts = SyntheticOptions(steps=3, drop_probability=0.0)
    on = run_synthetic_episode(
        _robot(), Condition.ON, calm, lambda e: events.append((e.kind, e.to_json())), 0, opts
    )
    # on: flour is asked for at once (κ̂ 0.1); the over-confident egg carton fails 3 times, then the robot asks
    assert on["help_requests"] == 2 and on["failures"] == 3 and on["successes"] == 1
    events.clear()
    off = run_synthetic_episode(
        _robot(), Condition.OFF, calm, lambda e: events.append((e.kind, e.to_json())), 0, opts
    )
    assert off["help_requests"] == 2 and off["failures"] == 6
    assert [k for k, _ in events].count("step_done") == 3
    assert {k for k, _ in events} <= {"decision", "act", "outcome", "help_request", "help", "step_done"}


def test_fast_study_is_labelled_and_complete(tmp_path):
    log = simulate_study(
        tmp_path / "sim.db", SimulationOptions(participants=4, fast=True, seed=2), printer=lambda _l: None
    )
    sessions = log.sessions()
    assert log.simulated and all(s.simulated for s in sessions) and len(sessions) == 8
    assert [s.group for s in sessions] == ["A", "A", "B", "B", "A", "A", "B", "B"]
    assert [s.condition for s in sessions[:4]] == ["on", "off", "off", "on"]
    assert len(log.responses()) == 8 * 22
    assert all(s.summary["synthetic"] and s.ended for s in sessions)
    assert sum(log.interventions(s.id) for s in sessions) == sum(s.summary["interventions"] for s in sessions)
    with pytest.raises(SconeError, match="exists"):
        simulate_study(tmp_path / "sim.db", SimulationOptions(participants=4, fast=True))
    paths = log.export_csv(tmp_path / "csv")
    assert paths["sessions"].read_text().splitlines()[1].startswith("SIMULATED,")


@pytest.mark.slow
def test_physics_sessions_in_one_process_share_one_embedder():
    from scone_bt.study.simulate import _models, simulate_participant

    records = simulate_participant(0, SimulationOptions(participants=2, max_ticks=15, distractors=1))
    assert len(records) == 2 and all(r.events for r in records)
    assert _models().loads == 1  # two episodes, MiniLM loaded once
