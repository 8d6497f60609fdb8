"""ObserveOutcome and UpdateSelfConfidence: label the attempt and store it durably, then update κ̂.

The outcome is committed to the experience store before it is emitted (and so before it is printed or logged):
whatever a user or the study log has seen reported is stored, even if the process is killed right after. It
carries the execution context the gate perceived when it chose the action (`Keys.TARGET_CONTEXT`), with what the
heft test felt when the action was probed (experience.felt): the context the robot had when it committed, so a
grounded κ̂ learns from, and a restarted robot rebuilds from, the context the attempt ran in.

After a probe, the judge's verdict (`Keys.PROBE_JUDGE`, gate.after_probe) says whether the attempt that carried on
was explored (below τ, on the strict rule's credit: a failure counts as an explored one), whether the probe felt
the product held fast (the attempt counts in that rule's own record, gate.after_probe), and whether a set-back
was the fingers' word (stored: κ̂ learns it could not carry it) or κ̂'s own doubt (not stored: like an ask, it
teaches nothing).
"""

from __future__ import annotations

import time

import py_trees

from scone_bt.affordances.types import Affordance
from scone_bt.behaviours.base import Keys, StageBehaviour
from scone_bt.behaviours.context import EpisodeContext, OutcomeLabels
from scone_bt.behaviours.ports import Clock, OutcomeRecorder, Provider, SelfConfidence
from scone_bt.confidence.grounded import kappa_rows
from scone_bt.events import ActCancelled, ActOutcome, EventSink, PlanInfeasible, ProbeAborted
from scone_bt.experience.felt import FeltReading, felt_context
from scone_bt.experience.types import Outcome
from scone_bt.gate.after_probe import ProbeVerdict
from scone_bt.motion.types import FailureStage, MotionOutcome
from scone_bt.robot.interface import Robot

__all__ = ["ObserveOutcome", "RecordInfeasible", "UpdateSelfConfidence", "label_outcome"]


def label_outcome(motion: MotionOutcome, on_table: bool) -> tuple[bool, FailureStage | None]:
    """Success and failure stage of an attempt: a success needs the motion's success *and* the outcome sensor's
    word that the object rests on the table; a failure without a stage failed at placing it."""
    success = bool(motion.success and on_table)
    return success, None if success else (motion.stage or FailureStage.PLACE)


class _RecordsOutcomes(StageBehaviour):
    """A behaviour that labels what happened to the target and stores it durably before anyone is told."""

    def __init__(
        self,
        name: str,
        clock: Clock,
        recorder: Provider[OutcomeRecorder | None],
        events: EventSink,
        labels: OutcomeLabels,
    ) -> None:
        super().__init__(name)
        self.clock = clock
        self._recorder = recorder
        self.events = events
        self.labels = labels

    def setup(self, **kwargs: object) -> None:
        self.store = self._recorder()

    def _record(
        self,
        target: Affordance,
        success: bool,
        stage: str | None,
        felt: FeltReading | None = None,
        **extra: object,
    ) -> Outcome:
        """The outcome of ``target`` with its labels and perceived context (with what a probe ``felt``, a
        motion.probe.ProbeReading), committed to the store (if any)."""
        labels = self.labels
        outcome = Outcome(
            time=time.time(),
            action=target.text,
            object_name=target.object_name,
            embedder=labels.embedder,
            success=success,
            failure_stage=stage,
            context={**labels.context, "sim_time": round(self.clock(), 3), **extra},
            robot_id=labels.robot_id,
            arm=labels.arm,
            profile=labels.profile,
            execution=felt_context(self.read(Keys.TARGET_CONTEXT), felt),
        )
        if self.store is not None:
            self.store.append(outcome)  # committed before it is reported, and before κ̂ changes
        return outcome


class ObserveOutcome(_RecordsOutcomes):
    """Labels a finished attempt from the robot's own sensors (is the product on the table now?) and stores it
    before anything learns from it; a heft test's set-back is a label only when the fingers felt it unsafe, a
    cancelled attempt none. Writes the outcome (None: nothing to learn); always SUCCESS."""

    READS = (Keys.TARGET, Keys.TARGET_CONTEXT, Keys.MOTION_OUTCOME, Keys.PROBE_JUDGE)
    WRITES = (Keys.OUTCOME,)

    def __init__(
        self,
        name: str,
        robot: Robot,
        recorder: Provider[OutcomeRecorder | None],
        events: EventSink,
        labels: OutcomeLabels,
    ) -> None:
        super().__init__(name, robot.now, recorder, events, labels)
        self.robot = robot

    @classmethod
    def from_context(cls, name: str, context: EpisodeContext) -> ObserveOutcome:
        return cls(name, context.robot, context.recorder, context.events, context.labels)

    def update(self) -> py_trees.common.Status:
        target = self.read(Keys.TARGET)
        motion: MotionOutcome = self.read(Keys.MOTION_OUTCOME)
        action, name = target.text, target.object_name
        now = self.robot.now()
        if motion.stage is FailureStage.CANCELLED:
            self.events(ActCancelled(now, action, name))
            self.write(Keys.OUTCOME, None)
            return py_trees.common.Status.SUCCESS
        judge = self.read(Keys.PROBE_JUDGE, None)
        # None: no probe, or the arm never held the product up (no reading to judge)
        verdict: ProbeVerdict | None = None if judge is None else judge.verdict
        if motion.aborted:  # the heft test set it back where it stood
            # the fingers' word is a label (κ̂ learns it could not carry it); κ̂'s own doubt is not
            felt_unsafe = verdict is None or verdict.felt_unsafe
            outcome = (
                self._record(target, False, FailureStage.PROBE.value, motion.probe, probe=motion.probe_reason)
                if felt_unsafe
                else None
            )
            reading = motion.probe
            self.events(
                ProbeAborted(
                    now,
                    action,
                    name,
                    motion.probe_reason,
                    duration_s=float(motion.duration),
                    probe_s=float(getattr(reading, "seconds", 0.0)),
                    load_n=float(getattr(reading, "load_n", 0.0)),
                )
            )
            self.write(Keys.OUTCOME, outcome)
            return py_trees.common.Status.SUCCESS
        # The robot's outcome sensor: is the object resting on the table now?
        success, stage = label_outcome(motion, self.robot.is_on_table(name))
        outcome = self._record(target, success, None if stage is None else stage.value, motion.probe)
        self.events(
            ActOutcome(
                now,
                action,
                name,
                success,
                outcome.failure_stage,
                duration_s=float(motion.duration),
                message=motion.message.split(";")[0],
                explored=verdict is not None and verdict.explored,
                held_fast=verdict is not None and verdict.held_fast,
                by_feel=verdict is not None and verdict.by_feel,
                traction=None if verdict is None else verdict.traction,
            )
        )
        self.write(Keys.OUTCOME, outcome)
        return py_trees.common.Status.SUCCESS


class RecordInfeasible(_RecordsOutcomes):
    """A plan the gate found infeasible before committing is experience too: stored (failure at planning, with the
    context it was planned in) and labelled for κ̂ (`Keys.OUTCOME`, which UpdateSelfConfidence learns from). It is
    not an attempt: nothing moved, the human saw no failure. Any other ask writes no outcome."""

    READS = (Keys.TARGET, Keys.TARGET_CONTEXT, Keys.PLAN_VERDICT)
    WRITES = (Keys.OUTCOME,)

    @classmethod
    def from_context(cls, name: str, context: EpisodeContext) -> RecordInfeasible:
        return cls(name, context.robot.now, context.recorder, context.events, context.labels)

    def update(self) -> py_trees.common.Status:
        verdict = self.read(Keys.PLAN_VERDICT)
        target = self.read(Keys.TARGET)
        if verdict is None or target is None:
            self.write(Keys.OUTCOME, None)
            return py_trees.common.Status.SUCCESS
        outcome = self._record(target, False, FailureStage.PLANNING.value, infeasible=verdict.reason)
        self.events(
            PlanInfeasible(self.clock(), target.text, target.object_name, verdict.reason, verdict.message)
        )
        self.write(Keys.OUTCOME, outcome)
        self.feedback_message = f"no plan for {target.object_name}: {verdict.reason}"
        return py_trees.common.Status.SUCCESS


class UpdateSelfConfidence(StageBehaviour):
    """κ̂ learns the last outcome, in the context the attempt ran in (with what a probe felt); always SUCCESS."""

    READS = (Keys.OUTCOME, Keys.ACTION_EMBEDDINGS)

    def __init__(self, name: str, kappa: Provider[SelfConfidence]) -> None:
        super().__init__(name)
        self._kappa = kappa

    @classmethod
    def from_context(cls, name: str, context: EpisodeContext) -> UpdateSelfConfidence:
        return cls(name, context.kappa)

    def setup(self, **kwargs: object) -> None:
        self.estimator = self._kappa()

    def update(self) -> py_trees.common.Status:
        outcome: Outcome | None = self.read(Keys.OUTCOME)
        if outcome is None:
            self.feedback_message = "no label (the human took over, or the robot asked)"
            return py_trees.common.Status.SUCCESS
        vector = self.read(Keys.ACTION_EMBEDDINGS, {})[outcome.action]
        # a grounded κ̂ learns from the context the attempt ran in (with what a probe felt)
        vector = kappa_rows(self.estimator, vector[None], [outcome.execution])[0]
        self.estimator.update(vector, outcome.success)
        self.feedback_message = (
            f"κ̂ updated with {'success' if outcome.success else 'failure'} of {outcome.action}"
        )
        return py_trees.common.Status.SUCCESS
