"""A real study session: the robot cooks with a participant who uses the tablet, then the questionnaires."""

from __future__ import annotations

import time
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

    With the server's start gate the episode is built, then waits in "Waiting to start" until the participant or
    the researcher presses Start; a ``start`` event (who, and the wall seconds waited) is stored then, and
    simulated time and the episode's events begin after it. Each time the researcher shows or hides the person's
    estimated trust on the participant's tablet, a ``trust_view`` record (shown, and the simulated time) is stored.

    Returns:
        The session id and the EpisodeSummary.
    """
    from scone_bt.episode import run_episode

    behaviour = replace(episode_options.behaviour, use_self_confidence=plan.condition is Condition.ON)
    options = replace(episode_options, behaviour=behaviour)
    from scone_bt.tree import load_tree_spec

    resolved = behaviour.resolve(load_tree_spec(options.tree).parameters)
    info = {
        "recipe": options.recipe,
        "seed": options.seed,
        "robot": options.arm,
        "tablet": server.url.split("?")[0],
        # simulated seconds the robot announces each attempt before moving (the time to take over)
        "takeover_window_s": resolved.takeover_window_s,
        "start_gate": server.state.start_gate,
        # the participant's tablet shows the person's estimated trust (changes: the trust_view records)
        "trust_shown": server.state.trust_shown,
    }
    sid = log.start_session(plan, info)

    def trust_view(shown: bool) -> None:
        """The researcher showed or hid the estimated trust on the tablet: stored when it happened."""
        log.record_event(
            sid,
            "trust_view",
            {"sim_time": round(server.state.sim_time, 3), "shown": shown, "by": "researcher"},
        )

    server.state.on_trust_view = trust_view
    server.state.label = f"{plan.participant} · session {plan.session_index}"
    printer(
        f"session {sid}: participant {plan.participant}, group {plan.group.value}, session {plan.session_index}, self-confidence {plan.condition.value}"
    )
    printer(f"tablet: {server.url}")

    def wait_to_start() -> None:
        built = time.monotonic()  # the robot is ready: models loaded, tree set up
        if server.state.start_gate:
            printer(f"waiting for Start on the tablet, or on the researcher's page: {server.researcher_url}")
        by = server.state.wait_start()
        log.record_event(
            sid, "start", {"sim_time": 0.0, "by": by, "waited_s": round(time.monotonic() - built, 3)}
        )
        printer(f"session started ({by})")

    summary = run_episode(
        options,
        printer=printer,
        on_event=server.chain(log.event_sink(sid)),
        human_factory=server.human_factory,
        realtime=True,
        wait_to_start=wait_to_start,
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
