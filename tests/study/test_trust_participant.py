"""Simulated participants with the fitted trust-transfer model (the default of scone-study simulate and power)."""

from __future__ import annotations

import math

import pytest

from scone_bt.errors import UnknownNameError
from scone_bt.events import ActOutcome, ActStarted, HelpRequested
from scone_bt.study.cli import main
from scone_bt.study.design import Group
from scone_bt.study.trust import SimulatedParticipant, trust_parameters

JAR, BOTTLE, RICE = (
    "Put the glass jar on table",
    "Put the glass bottle on table",
    "Put the bag of rice on table",
)


def _logit(p: float) -> float:
    return math.log(p / (1 - p))


def _participant(**overrides: float) -> SimulatedParticipant:
    return SimulatedParticipant("P1", Group.A, trust_parameters("fitted", **overrides), seed=3)


def test_a_failure_moves_trust_in_similar_actions_more() -> None:
    p = _participant()
    bottle, rice, general = p.trust_in(BOTTLE), p.trust_in(RICE), p.trust
    p.observe(ActOutcome(1.0, JAR, "glass jar", False, "grasp", 5.0))
    assert bottle - p.trust_in(BOTTLE) > rice - p.trust_in(RICE) > 0
    assert p.trust < general and p.history[-1] == ("outcome", p.trust)


def test_session_two_keeps_part_of_the_change_and_help_requests_are_the_assumed_shift() -> None:
    p = _participant()
    start = _logit(p.trust_in(JAR))
    p.observe(ActOutcome(1.0, JAR, "glass jar", False, "grasp", 5.0))
    dropped = start - _logit(p.trust_in(JAR))
    p.start_session(2)
    assert start - _logit(p.trust_in(JAR)) == pytest.approx(dropped * 0.5)  # carry_over 0.5, on the logit
    before = p.trust_in(RICE)
    p.observe(HelpRequested(2.0, RICE, "bag of rice"))
    assert p.trust_in(RICE) > before


def test_take_overs_follow_trust_in_the_action_started() -> None:
    p = _participant()
    for _ in range(3):
        p.observe(ActOutcome(1.0, JAR, "glass jar", False, "grasp", 5.0))
    p.observe(ActStarted(2.0, JAR, "glass jar", 0.4))
    on_jar = p.takeover_probability()
    p.observe(ActStarted(3.0, RICE, "bag of rice", 0.4))
    assert on_jar > p.takeover_probability()


def test_static_fitted_participants_ignore_the_episode() -> None:
    params = trust_parameters("fitted").static(condition_effect=1.0)
    assert not params.dynamic and params.condition_effect == 1.0 and params.transfer is not None
    p = SimulatedParticipant("P1", Group.A, params, seed=3)
    start = p.trust
    p.observe(ActOutcome(1.0, JAR, "glass jar", False, "grasp", 5.0))
    p.observe(HelpRequested(2.0, RICE, "bag of rice"))
    assert p.trust == start


def test_parameter_sets_and_the_simulate_flag(tmp_path, capsys) -> None:
    with pytest.raises(UnknownNameError, match="valid: fitted, hand"):
        trust_parameters("guessed")
    assert trust_parameters("hand").transfer is None
    assert main(["simulate", "--fast", "--participants", "2", "--db", str(tmp_path / "f.db")]) == 0
    assert "trust fitted to human ratings" in capsys.readouterr().out
    argv = [
        "simulate",
        "--fast",
        "--participants",
        "2",
        "--trust-params",
        "hand",
        "--db",
        str(tmp_path / "h.db"),
    ]
    assert main(argv) == 0
    assert "hand-set trust parameters" in capsys.readouterr().out
    with pytest.raises(SystemExit) as bad:  # argparse's choices: the valid names on one usage line
        main(["simulate", "--fast", "--trust-params", "guess", "--db", str(tmp_path / "x.db")])
    assert bad.value.code == 2 and "choose from 'fitted', 'hand'" in capsys.readouterr().err


def test_a_spoken_warning_moves_trust_towards_the_stated_confidence() -> None:
    from scone_bt.events import ConfidenceStated

    p = _participant()
    before = _logit(p.trust_in(JAR))
    p.observe(ConfidenceStated(1.0, JAR, "glass jar", "I may drop the glass jar", 0.3))
    assert _logit(p.trust_in(JAR)) == pytest.approx(before + 0.5 * (_logit(0.3) - before))  # warning_weight
    assert _participant().params.static().warning_weight == 0.0
