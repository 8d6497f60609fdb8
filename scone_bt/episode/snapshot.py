"""Collects what changed during one tick into a viz TickSnapshot."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
import py_trees

from scone_bt.behaviours import Keys
from scone_bt.events import EpisodeStats, EventLog
from scone_bt.motion.types import TimedTrajectory
from scone_bt.stocking import StockedRecipe

if TYPE_CHECKING:
    from scone_bt.viz.scene import SceneView

__all__ = ["SnapshotBuilder", "episode_counters"]


def episode_counters(stats: EpisodeStats) -> dict[str, int]:
    """The running totals the recording shows (rerun's counters): attempts, and how each ended (success, failure,
    or set back by the heft test: ``aborted``), help requests, clarifications, interventions, steps done."""
    return {
        "attempted": stats.attempted,
        "successes": stats.successes,
        "failures": stats.failures,
        "aborted": stats.aborted,
        "help_requests": stats.help_requests,
        "clarifications": stats.clarifications,
        "interventions": stats.interventions,
        "steps_done": stats.steps_done,
    }


def _concatenate(parts: list[TimedTrajectory]) -> TimedTrajectory | None:
    """One trajectory from consecutive segments (times made continuous)."""
    parts = [p for p in parts if len(p.times)]
    if not parts:
        return None
    offsets = np.cumsum(
        [0.0] + [p.duration + (p.times[1] - p.times[0] if len(p.times) > 1 else 0.0) for p in parts[:-1]]
    )
    return TimedTrajectory(
        times=np.concatenate([p.times + o for p, o in zip(parts, offsets, strict=True)]),
        positions=np.concatenate([p.positions for p in parts]),
        velocities=np.concatenate([p.velocities for p in parts]),
        accelerations=np.concatenate([p.accelerations for p in parts]),
    )


class SnapshotBuilder:
    """Reads the blackboard after each tick and reports only what is new (frames, decisions, plans).

    Args:
        scene: The backend's view of the world (poses for the 3D view; the recording may show ground truth).
        recipe: The recipe being cooked.
        human: The human (the recipe view shows their progress).
        events: The episode's events (the counters are their fold).
        lines: The log lines printed since the last snapshot; emptied by each `build`.
        trust: The person's trust estimated online (`scone_bt.trust.estimate.OnlineTrust`), fed the episode's
            events here; at each decision it gives the trust per offered object beside κ̂, and over-/under-trust
            risks as log lines. The estimate is drawn, never sent to the event sinks: the episode's events are
            the same with and without a viewer.
    """

    def __init__(
        self,
        scene: SceneView,
        recipe: StockedRecipe,
        human: Any,
        events: EventLog,
        lines: list[str],
        trust: Any = None,
    ) -> None:
        self.scene = scene
        self.recipe = recipe
        self.human = human
        self.events = events
        self.reader = py_trees.blackboard.Client(name="viz")
        for key in (
            Keys.FRAME,
            Keys.DETECTIONS,
            Keys.RANKED,
            Keys.CONFIDENCES,
            Keys.CONTEXTS,
            Keys.DECISION,
            Keys.AFFORDANCES,
            Keys.MOTION_TASK,
            Keys.MOTION_OUTCOME,
        ):
            self.reader.register_key(key=key, access=py_trees.common.Access.READ)
        self._seen: dict[str, int] = {}
        self.lines = lines
        self.trust = trust
        self._fed = 0  # events already given to `trust`

    def _new(self, key: str) -> Any:
        value = self.reader.get(key) if self.reader.exists(key) else None
        if value is None or self._seen.get(key) == id(value):
            return None
        self._seen[key] = id(value)
        return value

    def _person_trust(
        self, sim_time: float, conf: dict[str, float], by_text: dict[str, str]
    ) -> dict[str, float]:
        """The person's estimated trust per offered object at a decision (nothing without `trust`)."""
        if self.trust is None:
            return {}
        for event in self.events.events[self._fed :]:
            self.trust(event)
        self._fed = len(self.events.events)
        offered = {t: (by_text[t], float(c)) for t, c in conf.items() if t in by_text}
        estimates = self.trust.estimate(sim_time, offered)
        for e in estimates:
            if e.risk:
                self.lines.append(
                    f"{e.risk}-trust risk: {e.object_name} (person's trust ~{e.trust:.2f}, κ̂ {e.confidence:.2f})"
                )
        return {e.object_name: e.trust for e in estimates}

    def build(self, tick: int, root: py_trees.behaviour.Behaviour) -> Any:
        from scone_bt.viz import RecipeView, TickSnapshot

        scene = self.scene
        frame = self._new(Keys.FRAME)
        decision = self._new(Keys.DECISION)
        affordances = None
        confidences: dict[str, float] = {}
        contexts: dict[str, Any] = {}
        conf: dict[str, float] = {}
        by_text: dict[str, str] = {}
        if decision is not None:
            contexts = dict(self.reader.get(Keys.CONTEXTS) or {}) if self.reader.exists(Keys.CONTEXTS) else {}
            ranked = self.reader.get(Keys.RANKED) or []
            conf = self.reader.get(Keys.CONFIDENCES) or {}
            affordances = [
                (r.text, float(r.relevance), float(conf.get(r.text, float("nan")))) for r in ranked
            ]
            by_text = {a.text: a.object_name for a in (self.reader.get(Keys.AFFORDANCES) or [])}
            confidences = {by_text[t]: float(c) for t, c in conf.items() if t in by_text}
        person_trust = self._person_trust(scene.sim_time, conf, by_text)
        ee_path = trajectory = None
        task = self.reader.get(Keys.MOTION_TASK) if self.reader.exists(Keys.MOTION_TASK) else None
        if task is not None:
            plan = task.plan
            if plan is not None and hasattr(plan, "segments") and self._seen.get("plan") != id(plan):
                self._seen["plan"] = id(plan)
                ee_path = plan.ee_path(task.system.arm)  # the simulated backend's handle is its motion task
                trajectory = _concatenate([seg.trajectory for seg in plan.segments])
        human = self.human
        recipe = RecipeView(
            title=self.recipe.recipe.title,
            steps=tuple(st.instruction for st in self.recipe.steps),
            current=None if human.done else human.step_index,
            done=tuple(human.step_done),
        )
        counters = episode_counters(self.events.stats)
        lines = list(self.lines)
        self.lines.clear()
        return TickSnapshot(
            tick=tick,
            sim_time=scene.sim_time,
            link_poses=scene.link_poses(),
            object_poses={
                n: (o.position, o.orientation) for n in scene.objects for o in [scene.object_state(n)]
            },
            frame=frame,
            detections=(self.reader.get(Keys.DETECTIONS) or []) if frame is not None else (),
            affordances=affordances,
            decision=decision,
            ee_path=ee_path,
            trajectory=trajectory,
            executed_q=scene.arm_joint_positions(),
            tree=root,
            confidences=confidences,
            person_trust=person_trust,
            contexts=contexts,
            counters=counters,
            recipe=recipe,
            log_lines=lines,
        )
