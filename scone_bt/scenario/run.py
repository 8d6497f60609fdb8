"""Running a scenario case: the episode with a test rig that sets the world up and fires the scenario's events,
then the expectations checked on the typed event stream.

The rig (`ScenarioHook`) is the episode's `EpisodeHook`: it acts only through `scone_bt.robot.rig.World` and runs
between control ticks on the episode's thread, so a case repeats exactly (same events, same JSONL log). Many
cases at once: `scone_bt.scenario.runner`.
"""

from __future__ import annotations

import json
import math
import re
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from scone_bt.checks import OutputKind, is_output_kind
from scone_bt.errors import SconeError
from scone_bt.events import Event, EventSink, Intervention
from scone_bt.scenario.expect import ExpectationFailure, Outcome, Record, check, matches
from scone_bt.scenario.model import (
    Case,
    CoverCameraEvent,
    FaultEvent,
    HideMarkerEvent,
    MoveEvent,
    NextStepEvent,
    OnTable,
    RemoveEvent,
    ShowMarkerEvent,
    SwapEvent,
    ToTableEvent,
    UncoverCameraEvent,
    profile_path,
    resolve_input,
)

__all__ = [
    "CaseResult",
    "ScenarioHook",
    "Verdict",
    "episode_options",
    "event_json",
    "run_case",
    "safe_name",
]


class Verdict:
    """A case's verdict: passed, failed, xfail (failed as expected), xpass (passed although expected to fail)."""

    PASSED = "passed"
    FAILED = "failed"
    XFAIL = "xfail"
    XPASS = "xpass"
    ERROR = "error"


@dataclass(frozen=True)
class CaseResult:
    """What one case gave.

    Attributes:
        name: The case's name.
        path: Its scenario file.
        verdict: One of `Verdict`.
        reason: Why (the first failed expectation, the expected-failure reason, or the error).
        failures: Every failed expectation.
        sim_s: Simulated seconds the episode ran.
        wall_s: Wall seconds the case's episode took (not the second run that records a failure).
        events: The episode's event log, one JSON line per event (with the tick).
        artifacts: Files written for a failing case (event log, recording).
        kept: Files a failing case would have written that were left alone: they hold something else (made after
            the check before the run; --force replaces them).
        replay: The command that opens the recording in the viewer ("" without one).
    """

    name: str
    path: str
    verdict: str
    reason: str
    failures: tuple[ExpectationFailure, ...] = ()
    sim_s: float = 0.0
    wall_s: float = 0.0
    events: tuple[str, ...] = ()
    artifacts: tuple[str, ...] = ()
    replay: str = ""
    log: tuple[str, ...] = field(default=(), compare=False)
    kept: tuple[str, ...] = ()

    @property
    def ok(self) -> bool:
        """Whether the case counts as passing (passed or failed as expected)."""
        return self.verdict in (Verdict.PASSED, Verdict.XFAIL)

    def report(self) -> str:
        """The failure report: every failed expectation with the events around it, and the artifacts."""
        lines = [f"{self.name} ({self.path}): {self.verdict}: {self.reason}"]
        for f in self.failures:
            lines.append(f.format())
        for a in self.artifacts:
            lines.append(f"  wrote {a}")
        for k in self.kept:
            lines.append(f"  not written: {k} exists and holds something else (--force replaces it)")
        if self.replay:
            lines.append(f"  replay: {self.replay}")
        return "\n".join(lines)


class ScenarioHook:
    """The test rig of one case (`scone_bt.episode.runner.EpisodeHook`): sets the world up, fires the events."""

    def __init__(self, case: Case, log: Callable[[str], None]) -> None:
        self.case = case
        self.spec = case.spec
        self.log = log
        self.tick = 0
        self.records: list[Record] = []
        self.world: Any = None
        self.human: Any = None
        self.events: EventSink | None = None
        self._pending = list(enumerate(self.spec.events))
        self._triggered: dict[int, float] = {}  # event index -> sim time its condition was met
        self._watch = [n for ex in self.spec.expect if isinstance(ex, OnTable) for n in ex.on_table]
        self.final_on_table: dict[str, bool] = {}

    # ------------------------------------------------------------------------------------------- EpisodeHook
    def attach(self, world: Any, robot: Any, human: Any, events: EventSink) -> None:
        from scone_bt.robot.rig import SlotRef

        self.world = world
        self.human = human
        self.events = events
        faults = self._start_faults()
        if faults:
            self.world.apply_fault(**faults)
            self.log(f"scenario: robot condition {faults}")
        w = self.spec.world
        for pl in w.place:
            unit, tier, index = pl.slot.split("/")
            self.world.place_on_shelf(
                pl.product, SlotRef(unit, int(tier), int(index)), math.radians(pl.yaw_deg)
            )
            if pl.gap_m is not None:
                for name, side in zip(pl.neighbours, (1, -1), strict=False):
                    self.world.place_beside(name, pl.product, pl.gap_m, side)
                continue
            for name, beside in pl.neighbour_slots(self.world.slots_on_tier(unit, int(tier))):
                u, t, i = beside.split("/")
                self.world.place_on_shelf(name, SlotRef(u, int(t), int(i)))
        for name in w.on_table:
            if not self.world.place_on_table(name):
                raise SconeError(f"{self.case.path}: world.on_table: no free table spot for {name!r}")
        if w.place or w.on_table:
            self.world.advance(0.5)  # let what was put down settle before the robot's first look
        for name in w.hidden_markers:
            self.world.hide_marker(name)
        self._fire(0)

    def after_tick(self, control_ticks: int) -> None:
        self.tick = control_ticks
        self._fire(control_ticks)
        for name in self._watch:
            self.final_on_table[name] = self.world.is_on_table(name)

    # ------------------------------------------------------------------------------------------- events
    def observe(self, event: Event) -> None:
        """The episode's `on_event`: keep the event with its tick, and note the conditions it meets."""
        self.records.append(Record(self.tick, event))
        for index, ev in self._pending:
            if ev.when is not None and index not in self._triggered and matches(event, ev.when):
                self._triggered[index] = event.sim_time

    def _due(self, index: int, ev: Any, now: float) -> bool:
        if ev.at is not None:
            return now + 1e-9 >= ev.at + ev.delay_s
        met = self._triggered.get(index)
        return met is not None and now + 1e-9 >= met + ev.delay_s

    def _fire(self, tick: int) -> None:
        now = self.world.sim_time
        for index, ev in list(self._pending):
            if self._due(index, ev, now):
                self._pending.remove((index, ev))
                self._apply(ev)
                self.log(f"scenario: t={now:.1f} s tick {tick}: event {index} ({_event_text(ev)})")

    def _apply(self, ev: Any) -> None:
        from scone_bt.robot.rig import SlotRef

        w = self.world
        if isinstance(ev, MoveEvent):
            unit, tier, index = ev.move.slot.split("/")
            w.place_on_shelf(
                ev.move.product, SlotRef(unit, int(tier), int(index)), math.radians(ev.move.yaw_deg)
            )
        elif isinstance(ev, SwapEvent):
            w.swap(ev.swap.product, ev.swap.with_)
        elif isinstance(ev, RemoveEvent):
            w.remove(ev.remove)
        elif isinstance(ev, ToTableEvent):
            w.place_on_table(ev.to_table)
        elif isinstance(ev, HideMarkerEvent):
            w.hide_marker(ev.hide_marker)
        elif isinstance(ev, ShowMarkerEvent):
            w.show_marker(ev.show_marker)
        elif isinstance(ev, CoverCameraEvent):
            w.cover_camera(ev.cover_camera)
        elif isinstance(ev, UncoverCameraEvent):
            w.uncover_camera(ev.uncover_camera)
        elif isinstance(ev, FaultEvent):
            w.apply_fault(**ev.fault.values())
        elif isinstance(ev, NextStepEvent):
            self._next_step()

    def _next_step(self) -> None:
        """The human does the current step by hand: brings every item it still needs to the table."""
        human = self.human
        if human.done:
            return
        step = human.recipe.steps[human.step_index]
        for name in step.objects:
            if not self.world.is_on_table(name) and self.world.place_on_table(name):
                assert self.events is not None
                self.events(
                    Intervention(
                        self.world.sim_time, name, "scenario: the human did the step by hand", "by-hand"
                    )
                )

    def _start_faults(self) -> dict[str, Any]:
        r = self.spec.robot
        out: dict[str, Any] = {}
        if r.profile is not None:
            from scone_bt.benchmarks.self_confidence.profiles import load_profile

            p = load_profile(profile_path(r.profile, self.case.base))
            pairs = {
                "gripper_force": p.gripper_max_force,
                "finger_friction": p.finger_friction,
                "camera_noise": p.camera_noise_std,
                "depth_noise": p.depth_noise_std,
                "planner_budget_s": p.planner_time_limit_s,
                "calibration_offset": tuple(p.calibration_offset) if any(p.calibration_offset) else None,
                "velocity_scale": p.velocity_scale,
                "acceleration_scale": p.acceleration_scale,
                "jerk_scale": p.jerk_scale,
            }
            out.update({k: v for k, v in pairs.items() if v is not None})
            if p.injected:
                # an injected failure sabotages a stage by fiat (the dataset generator's device for rare
                # failures); an episode has only physical causes, so they are named and left out
                stages = sorted({i.stage for i in p.injected})
                self.log(
                    f"scenario: profile {p.name}: injected {', '.join(stages)} failures not applied in episodes"
                )
        out.update(r.values())
        return out


def _event_text(ev: Any) -> str:
    data = ev.model_dump(exclude_none=True, exclude={"at", "when", "delay_s"}, by_alias=True)
    return ", ".join(f"{k}: {v}" for k, v in data.items())


def episode_options(
    case: Case, save: Path | None = None, experience: Path | None = None, seed: int | None = None
) -> Any:
    """The `EpisodeOptions` of a case (paths relative to the scenario file resolved)."""
    from scone_bt.behaviours import BehaviourOptions
    from scone_bt.config.tree_parameters import PARAMETER_NAMES
    from scone_bt.episode import EpisodeOptions
    from scone_bt.human import ClarifyAnswer, HelpAnswer, HumanOptions

    w, base = case.spec.world, case.base
    params = {k: v for k, v in w.parameters.items() if k in PARAMETER_NAMES}
    s = w.seed if seed is None else seed
    behaviour = BehaviourOptions(
        **params,
        use_self_confidence=w.self_confidence,
        experience_path=experience,
        seed=s,
    )
    h = case.spec.human
    return EpisodeOptions(
        backend=w.robot,
        arm=resolve_input(w.arm, base),
        kitchen=resolve_input(w.kitchen, base),
        catalogues=tuple(resolve_input(c, base) for c in w.catalogues),
        tree=resolve_input(w.tree, base),
        recipe=resolve_input(w.recipe, base),
        seed=s,
        max_ticks=w.max_ticks,
        tick_period=w.tick_period,
        distractors=w.distractors,
        behaviour=behaviour,
        human=HumanOptions(
            fetch_time_s=h.fetch_time_s,
            cook_time_s=h.cook_time_s,
            patience_s=h.patience_s,
            takeover_probability=h.takeover_probability,
            takeover_delay_s=h.takeover_delay_s,
            clarify_time_s=h.clarify_time_s,
            help_answer=HelpAnswer(h.help_answer),
            clarify_answer=ClarifyAnswer(h.clarify_answer),
        ),
        save=save,
    )


WALL_CLOCK_FIELDS = ("planning_s",)
"""Event fields that measure wall time (DecisionMade.planning_s): left out of the event log, which must repeat."""


def event_json(record: Record) -> str:
    """One line of a case's event log: the tick, the event's kind, then its stored payload less wall times."""
    payload = {k: v for k, v in record.event.to_json().items() if k not in WALL_CLOCK_FIELDS}
    return json.dumps({"tick": record.tick, "event": record.event.kind, **payload}, ensure_ascii=False)


def safe_name(name: str) -> str:
    """A case name as a file name."""
    return re.sub(r"[^A-Za-z0-9_.=-]+", "_", name).strip("_") or "case"


def case_outputs(name: str, out_dir: Path) -> tuple[Path, Path]:
    """Where a failing case's event log (JSON Lines) and recording (.rrd) are written."""
    stem = safe_name(name)
    return out_dir / f"{stem}.events.jsonl", out_dir / f"{stem}.rrd"


def _foreign(path: Path, kind: OutputKind) -> bool:
    """Whether `path` holds something other than an earlier output of its kind (never overwritten)."""
    return path.exists() and not is_output_kind(path, kind)


def _episode(
    case: Case, models: Any, save: Path | None, experience: Path | None
) -> tuple[Any, ScenarioHook, list[str]]:
    from scone_bt.episode import run_episode

    lines: list[str] = []
    for seed in case.spec.world.experience_from:  # earlier episodes whose outcomes the robot starts with
        assert experience is not None
        run_episode(episode_options(case, None, experience, seed), printer=lines.append, models=models)
        lines.append(f"scenario: learnt from an episode with seed {seed}")
    hook = ScenarioHook(case, lines.append)
    summary = run_episode(
        episode_options(case, save, experience),
        printer=lines.append,
        on_event=hook.observe,
        models=models,
        hook=hook,
    )
    return summary, hook, lines


def run_case(
    case: Case,
    out_dir: Path | None = None,
    models: Any = None,
    record_failures: bool = True,
    force: bool = False,
) -> CaseResult:
    """Run one case and check its expectations.

    A case that fails unexpectedly writes ``<name>.events.jsonl`` into ``out_dir`` and, with ``record_failures``,
    runs again (it repeats exactly) to save ``<name>.rrd``, and gives the command that replays it.
    """
    started = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="scone-scenario-") as tmp:
        store = Path(tmp) / "experience.sqlite" if case.spec.world.experience_from else None
        try:
            summary, hook, lines = _episode(case, models, None, store)
        except SconeError as exc:
            return CaseResult(
                case.name, str(case.path), Verdict.ERROR, str(exc), wall_s=time.perf_counter() - started
            )
    wall_s = time.perf_counter() - started  # the case's own run: not the second one that records a failure
    end = Outcome(
        completed=summary.completed,
        steps_completed=summary.steps_completed,
        on_table={**summary.needed_on_table, **hook.final_on_table},
        ticks=summary.control_ticks,
        sim_time=summary.sim_time,
    )
    failures = tuple(f for ex in case.spec.expect if (f := check(ex, hook.records, end)) is not None)
    events = tuple(event_json(r) for r in hook.records)
    expected_fail = case.spec.expected == "fail"
    if failures:
        verdict = Verdict.XFAIL if expected_fail else Verdict.FAILED
        reason = f"{failures[0].expectation}: {failures[0].problem}"
        if expected_fail:
            reason = f"expected failure ({case.spec.reason}); {reason}"
    else:
        verdict = Verdict.XPASS if expected_fail else Verdict.PASSED
        reason = f"passed although expected to fail ({case.spec.reason})" if expected_fail else ""
    written = _Written()
    if out_dir is not None and verdict in (Verdict.FAILED, Verdict.XPASS):
        written = _write_artifacts(case, out_dir, events, models, record_failures, force)
    return CaseResult(
        case.name,
        str(case.path),
        verdict,
        reason,
        failures,
        sim_s=summary.sim_time,
        wall_s=wall_s,
        events=events,
        artifacts=written.artifacts,
        replay=written.replay,
        log=tuple(lines),
        kept=written.kept,
    )


@dataclass(frozen=True)
class _Written:
    """What a failing case left in the output folder: files written, files kept (`CaseResult`), the replay."""

    artifacts: tuple[str, ...] = ()
    kept: tuple[str, ...] = ()
    replay: str = ""


def _write_artifacts(
    case: Case, out_dir: Path, events: tuple[str, ...], models: Any, record_failures: bool, force: bool
) -> _Written:
    """The failing case's event log and (``record_failures``) its recording, run again; a file there of another
    kind (made after the check before the run) is kept unless ``force``."""
    out_dir.mkdir(parents=True, exist_ok=True)
    log, rrd = case_outputs(case.name, out_dir)
    artifacts: list[str] = []
    kept: list[str] = []
    if _foreign(log, "json") and not force:
        kept.append(str(log))
    else:
        log.write_text("".join(e + "\n" for e in events), encoding="utf-8")
        artifacts.append(str(log))
    if not record_failures:
        return _Written(tuple(artifacts), tuple(kept))
    if _foreign(rrd, "rrd") and not force:
        return _Written(tuple(artifacts), (*kept, str(rrd)))
    with tempfile.TemporaryDirectory(prefix="scone-scenario-") as tmp:
        store = Path(tmp) / "experience.sqlite" if case.spec.world.experience_from else None
        _episode(case, models, rrd, store)
    from scone_bt.cli.run import viewer_command

    return _Written((*artifacts, str(rrd)), tuple(kept), viewer_command(rrd))
