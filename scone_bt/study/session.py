"""A real study session: the robot cooks with a participant who uses the tablet, then the questionnaires."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from typing import Any

from scone_bt.study.design import Condition, SessionPlan
from scone_bt.study.log import StudyLog
from scone_bt.study.ui import TabletServer

__all__ = ["run_study_session"]


def run_study_session(
    log: StudyLog,
    plan: SessionPlan,
    episode_options: Any,  # EpisodeOptions
    server: TabletServer,
    printer: Callable[[str], None] = print,
    questionnaires: bool = True,
    questionnaire_timeout_s: float | None = None,
) -> tuple[int, Any]:
    """Run one session in real time with the tablet; every event and answer is committed as it happens.

    Returns:
        The session id and the EpisodeSummary.
    """
    from scone_bt.episode import run_episode

    behaviour = replace(episode_options.behaviour, use_self_confidence=plan.condition is Condition.ON)
    options = replace(episode_options, behaviour=behaviour)
    info = {
        "recipe": options.recipe,
        "seed": options.seed,
        "robot": options.robot,
        "tablet": server.url.split("?")[0],
    }
    sid = log.start_session(plan, info)
    server.state.label = f"{plan.participant} · session {plan.session_index}"
    printer(
        f"session {sid}: participant {plan.participant}, group {plan.group.value}, session {plan.session_index}, self-confidence {plan.condition.value}"
    )
    printer(f"tablet: {server.url}")
    summary = run_episode(
        options,
        printer=printer,
        on_event=server.chain(log.event_sink(sid)),
        human_factory=server.human_factory,
        realtime=True,
    )
    log.end_session(sid, {**summary.deterministic_part(), "wall_time": round(summary.wall_time, 3)})
    if questionnaires:
        server.ask_questionnaires(lambda name, answers: log.record_responses(sid, name, answers))
        printer("episode over: the participant answers the questionnaires on the tablet")
        if not server.wait_questionnaires(questionnaire_timeout_s):
            printer("questionnaires not completed in time; the episode's events are stored")
    return sid, summary


def default_db() -> Path:
    return Path("runs") / "study.db"
