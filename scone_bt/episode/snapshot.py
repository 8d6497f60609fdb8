"""Collects what changed during one tick into a viz TickSnapshot."""

from __future__ import annotations

from typing import Any

import numpy as np
import py_trees

from scone_bt.behaviours import Keys, Services
from scone_bt.motion.types import TimedTrajectory

__all__ = ["SnapshotBuilder"]


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
    """Reads the blackboard after each tick and reports only what is new (frames, decisions, plans)."""

    def __init__(self, services: Services) -> None:
        self.services = services
        self.reader = py_trees.blackboard.Client(name="viz")
        for key in (
            Keys.FRAME,
            Keys.DETECTIONS,
            Keys.RANKED,
            Keys.CONFIDENCES,
            Keys.DECISION,
            Keys.AFFORDANCES,
            Keys.MOTION_TASK,
            Keys.MOTION_OUTCOME,
        ):
            self.reader.register_key(key=key, access=py_trees.common.Access.READ)
        self._seen: dict[str, int] = {}
        self.lines: list[str] = []

    def _new(self, key: str) -> Any:
        value = self.reader.get(key) if self.reader.exists(key) else None
        if value is None or self._seen.get(key) == id(value):
            return None
        self._seen[key] = id(value)
        return value

    def build(self, tick: int, root: py_trees.behaviour.Behaviour) -> Any:
        from scone_bt.viz import RecipeView, TickSnapshot

        s = self.services
        kitchen = s.kitchen
        frame = self._new(Keys.FRAME)
        decision = self._new(Keys.DECISION)
        affordances = None
        confidences: dict[str, float] = {}
        if decision is not None:
            ranked = self.reader.get(Keys.RANKED) or []
            conf = self.reader.get(Keys.CONFIDENCES) or {}
            affordances = [
                (r.text, float(r.relevance), float(conf.get(r.text, float("nan")))) for r in ranked
            ]
            by_text = {a.text: a.object_name for a in (self.reader.get(Keys.AFFORDANCES) or [])}
            confidences = {by_text[t]: float(c) for t, c in conf.items() if t in by_text}
        ee_path = trajectory = None
        task = self.reader.get(Keys.MOTION_TASK) if self.reader.exists(Keys.MOTION_TASK) else None
        if task is not None:
            plan = task.plan
            if plan is not None and hasattr(plan, "segments") and self._seen.get("plan") != id(plan):
                self._seen["plan"] = id(plan)
                ee_path = plan.ee_path(task.system.arm)
                trajectory = _concatenate([seg.trajectory for seg in plan.segments])
        human = s.human
        recipe = RecipeView(
            title=s.recipe.recipe.title,
            steps=tuple(st.instruction for st in s.recipe.steps),
            current=None if human.done else human.step_index,
            done=tuple(human.step_done),
        )
        st = s.stats
        counters = {
            "attempted": st.attempted,
            "successes": st.successes,
            "failures": st.failures,
            "help_requests": st.help_requests,
            "clarifications": st.clarifications,
            "interventions": human.interventions,
            "steps_done": human.steps_completed(),
        }
        lines, self.lines = self.lines, []
        return TickSnapshot(
            tick=tick,
            sim_time=kitchen.sim_time,
            link_poses=kitchen.link_poses(),
            object_poses={
                n: (o.position, o.orientation) for n in kitchen.objects for o in [kitchen.object_state(n)]
            },
            frame=frame,
            detections=(self.reader.get(Keys.DETECTIONS) or []) if frame is not None else (),
            affordances=affordances,
            decision=decision,
            ee_path=ee_path,
            trajectory=trajectory,
            executed_q=kitchen.arm_joint_positions(),
            tree=root,
            confidences=confidences,
            counters=counters,
            recipe=recipe,
            log_lines=lines,
        )
