"""The whole study in simulation: N simulated participants, two counterbalanced sessions each, questionnaires.

Two modes:
- physics (default): every session is a real run_episode in PyBullet with a TrustfulHuman (30-90 s each);
- fast (``fast=True``): synthetic episodes without physics (synthetic.py), a second or so for a whole study.
Everything goes into a StudyLog labelled SIMULATED, which `scone-study analyze` reads like a real study.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from scone_bt.errors import SconeError
from scone_bt.events import Event, EventSink
from scone_bt.study.design import Condition, assign_group, plan_session
from scone_bt.study.log import StudyLog
from scone_bt.study.questionnaires import QUESTIONNAIRES
from scone_bt.study.synthetic import SyntheticOptions, SyntheticRobot, run_synthetic_episode
from scone_bt.study.trust import SimulatedParticipant, TrustfulHuman, TrustParameters

__all__ = ["SimulationOptions", "simulate_participant", "simulate_study"]


@dataclass(frozen=True)
class SimulationOptions:
    """What to simulate.

    Attributes:
        participants: Number of simulated participants (groups alternate A, B, A, ...).
        seed: Seeds participants, robot and episodes.
        fast: Synthetic episodes (no physics).
        trust: The participants' trust model.
        synthetic: Fast-mode episode settings.
        recipe: Recipe of physics episodes (short by default).
        distractors: Distractors on the shelf in physics episodes.
        max_ticks: Limit of physics episodes (0.1 s ticks).
        robot: Robot file (arm model) of physics episodes.
        backend: Robot backend of physics episodes (`scone_bt.robot.registry.BACKENDS`).
        experience_path: Experience store κ̂ is rebuilt from in physics episodes (None: learn within each episode).
    """

    participants: int = 10
    seed: int = 0
    fast: bool = False
    trust: TrustParameters = field(default_factory=TrustParameters)
    synthetic: SyntheticOptions = field(default_factory=SyntheticOptions)
    recipe: str = "example:hummus"
    distractors: int = 2
    max_ticks: int = 3000
    robot: str = "panda"
    backend: str = "sim"
    experience_path: Path | None = None

    def __post_init__(self) -> None:
        if self.participants < 2:
            raise SconeError(
                f"a simulated study needs at least 2 participants (one per group), got {self.participants}"
            )


@functools.lru_cache(maxsize=1)
def _models() -> Any:
    """One model pool per process: every physics episode a worker runs shares its embedder (MiniLM loads once)."""
    from scone_bt.episode import ModelPool

    return ModelPool()


@functools.lru_cache(maxsize=1)
def _catalogue_names() -> tuple[str, ...]:
    """The kitchen catalogue's object names (loaded once per process: every participant task needs them)."""
    from scone_bt.config import load_kitchen

    return tuple(load_kitchen().catalogue.names())


def _physics_episode(
    options: SimulationOptions,
    condition: Condition,
    participant: SimulatedParticipant,
    seed: int,
    sink: EventSink,
) -> dict[str, Any]:
    from scone_bt.behaviours import BehaviourOptions
    from scone_bt.episode import EpisodeOptions, run_episode

    behaviour = BehaviourOptions(
        use_self_confidence=condition is Condition.ON, experience_path=options.experience_path, seed=seed
    )
    episode = EpisodeOptions(
        arm=options.robot,
        backend=options.backend,
        recipe=options.recipe,
        seed=seed,
        max_ticks=options.max_ticks,
        distractors=options.distractors,
        behaviour=behaviour,
    )

    def factory(kitchen, recipe, human_options, human_seed):  # noqa: ANN001 - run_episode's HumanFactory
        return TrustfulHuman(
            kitchen, recipe, replace(human_options), seed=human_seed, participant=participant
        )

    def on_event(event: Event) -> None:
        sink(event)
        participant.observe(event)

    summary = run_episode(
        episode, printer=lambda _line: None, on_event=on_event, human_factory=factory, models=_models()
    )
    return {"synthetic": False, **summary.deterministic_part()}


@dataclass(frozen=True)
class _SessionRecord:
    """One simulated session, computed in a worker and written to the log by the caller, in participant order."""

    plan: Any  # SessionPlan
    info: dict[str, Any]
    events: list[Event]
    responses: list[tuple[str, dict[str, Any]]]
    summary: dict[str, Any]
    line: str


def simulate_participant(index: int, options: SimulationOptions) -> list[_SessionRecord]:
    """Both sessions of participant `index` (a work item: seeded by options.seed and index alone)."""
    robot = SyntheticRobot.sample(_catalogue_names(), options.seed) if options.fast else None
    pid = f"SIM{index + 1:03d}"
    group = assign_group(index)
    participant = SimulatedParticipant(pid, group, options.trust, seed=options.seed * 100_003 + index)
    records = []
    for session_index in (1, 2):
        plan = plan_session(pid, group, session_index)
        participant.start_session(session_index)
        seed = options.seed * 1_000 + 10 * index + session_index
        info = {
            "simulated": True,
            "mode": "fast" if options.fast else "physics",
            "seed": seed,
            "trust_model": options.trust.describe(),
        }
        events: list[Event] = []
        sink = events.append
        if robot is not None:
            summary = run_synthetic_episode(robot, plan.condition, participant, sink, seed, options.synthetic)
        else:
            summary = _physics_episode(options, plan.condition, participant, seed, sink)
        summary["final_trust"] = round(participant.trust, 4)
        responses = [
            (q.name, dict(participant.answer(q, plan.condition, session_index)))
            for q in QUESTIONNAIRES.values()
        ]
        line = (
            f"  {pid} group {group.value} session {session_index} ({plan.condition.value:>3}): "
            f"{summary.get('successes', 0)} successes, {summary.get('failures', 0)} failures, "
            f"{summary.get('help_requests', 0)} help requests, {summary.get('interventions', 0)} interventions, "
            f"trust {participant.trust:.2f}"
        )
        records.append(_SessionRecord(plan, info, events, responses, summary, line))
    return records


def simulate_study(
    db_path: str | Path,
    options: SimulationOptions,
    printer: Callable[[str], None] = print,
    engine: Any = None,
    after_participant: Callable[[int], None] | None = None,
) -> StudyLog:
    """Run the simulated study into a new SIMULATED StudyLog at db_path (refuses an existing file).

    Participants are independent work items: with `engine` (scone_bt.distributed.EngineOptions, e.g. Ray) they
    run in parallel; the log is written in participant order whatever order they finish in, so the file's
    content does not depend on the engine or the number of workers. Default: one after another, in this process.
    ``after_participant`` is called with each participant's index once its sessions are in the log.
    """
    from scone_bt.distributed import EngineOptions, imap_tasks, start_engine

    path = Path(db_path)
    if path.exists():
        raise SconeError(f"{path} exists; a simulated study writes a new file (choose another --db)")
    if not options.fast:  # an unknown recipe is one line before the log file or its header exists
        from scone_bt.recipes import load_recipe

        load_recipe(options.recipe)
    start_engine(engine)  # an unreachable cluster fails here, before the log file exists
    log = StudyLog(path, simulated=True)
    mode = "fast (synthetic episodes, no physics)" if options.fast else "physics episodes"
    printer(f"SIMULATED study: {options.participants} participants, {mode}, seed {options.seed} -> {path}")
    pending: dict[int, list[_SessionRecord]] = {}
    next_index = 0
    items = list(range(options.participants))
    for i, records in imap_tasks(
        simulate_participant, items, engine=engine or EngineOptions(workers=1), shared=options
    ):
        pending[i] = records
        while next_index in pending:
            for rec in pending.pop(next_index):
                # A simulated session is one transaction: the seed regenerates it, and per-event fsyncs would dominate.
                with log.batch():
                    sid = log.start_session(rec.plan, rec.info)
                    for event in rec.events:
                        log.record(sid, event)
                    for name, answers in rec.responses:
                        log.record_responses(sid, name, answers)
                    log.end_session(sid, rec.summary)
                printer(rec.line)
            if after_participant is not None:
                after_participant(next_index)
            next_index += 1
    return log
