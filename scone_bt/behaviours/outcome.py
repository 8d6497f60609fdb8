"""ObserveOutcome and UpdateSelfConfidence: label the attempt and store it durably, then update κ̂.

The outcome is committed to the experience store before it is printed or emitted: whatever a user or the study
log has seen reported is stored, even if the process is killed right after.
"""

from __future__ import annotations

import time

import py_trees

from scone_bt.behaviours.base import Keys, StageBehaviour
from scone_bt.experience.types import Outcome
from scone_bt.motion.types import FailureStage

__all__ = ["ObserveOutcome", "UpdateSelfConfidence"]


class ObserveOutcome(StageBehaviour):
    READS = (Keys.DECISION, Keys.AFFORDANCES, Keys.MOTION_OUTCOME)
    WRITES = (Keys.OUTCOME,)

    def setup(self, **kwargs: object) -> None:
        self.store = self.services.store()

    def update(self) -> py_trees.common.Status:
        s = self.services
        decision = self.read(Keys.DECISION)
        motion = self.read(Keys.MOTION_OUTCOME)
        by_text = {a.text: a for a in self.read(Keys.AFFORDANCES, [])}
        name = by_text[decision.action].object_name
        if motion.stage is FailureStage.CANCELLED:
            s.stats.cancelled += 1
            s.printer(f"    ~ the human took over: {decision.action}")
            self.write(Keys.OUTCOME, None)
            return py_trees.common.Status.SUCCESS
        # The robot's outcome sensor: is the object resting on the table now?
        success = bool(motion.success and s.kitchen.is_on_table(name))
        stage = None if success else (motion.stage or FailureStage.PLACE).value
        outcome = Outcome(
            time=time.time(),
            action=decision.action,
            object_name=name,
            embedder=s.options.embedder,
            success=success,
            failure_stage=stage,
            context={**s.context, "sim_time": round(s.kitchen.sim_time, 3)},
            robot_id=s.robot_id,
            arm=s.robot_config.name,
            profile=s.options.profile,
        )
        if self.store is not None:
            self.store.append(outcome)  # committed before it is reported, and before κ̂ changes
        if success:
            s.stats.successes += 1
            s.printer(f"    + success: {name} is on the table ({motion.duration:.1f} s)")
        else:
            s.stats.failures += 1
            s.stats.failures_by_stage[stage] = s.stats.failures_by_stage.get(stage, 0) + 1
            s.stats.failures_by_action[decision.action] = (
                s.stats.failures_by_action.get(decision.action, 0) + 1
            )
            s.printer(f"    x failure at {stage}: {motion.message.split(';')[0]}")
        s.emit("outcome", action=decision.action, object=name, success=success, stage=stage)
        self.write(Keys.OUTCOME, outcome)
        return py_trees.common.Status.SUCCESS


class UpdateSelfConfidence(StageBehaviour):
    READS = (Keys.OUTCOME, Keys.ACTION_EMBEDDINGS)

    def setup(self, **kwargs: object) -> None:
        self.estimator = self.services.estimator()

    def update(self) -> py_trees.common.Status:
        outcome: Outcome | None = self.read(Keys.OUTCOME)
        if outcome is None:
            self.feedback_message = "no label (human took over)"
            return py_trees.common.Status.SUCCESS
        vector = self.read(Keys.ACTION_EMBEDDINGS, {})[outcome.action]
        self.estimator.update(vector, outcome.success)
        self.feedback_message = (
            f"κ̂ updated with {'success' if outcome.success else 'failure'} of {outcome.action}"
        )
        return py_trees.common.Status.SUCCESS
