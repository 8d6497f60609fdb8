"""What one episode did: the counts a seeded rerun repeats, the times it does not, and the summary's text."""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any

from scone_bt.episode.printer import RULE_LABELS, percent, promise_words

__all__ = ["EpisodeSummary"]


@dataclass(frozen=True)
class EpisodeSummary:
    """What happened. All counts are deterministic for a given seed; times are not.

    ``condition`` is the condition the robot ran in (`condition_line`); ``decided_by_rule`` counts the decisions a
    rule other than κ̂ against the threshold made, by `DecisionMade.rule`; ``failure_budget`` is the budget gate's
    target failure rate (None for another gate), ``strict_promise`` whether that budget explored only on earned
    credit (``exploration_credit``; read only with ``failure_budget``, `promise_words`); ``set_back`` counts
    the attempts a heft test set back where they stood (neither successes nor failures).
    """

    recipe_id: str
    recipe_title: str
    robot: str
    completed: bool
    steps_completed: int
    steps_total: int
    attempted: int
    successes: int
    failures: int
    failures_by_stage: dict[str, int]
    help_requests: int
    clarifications: int
    interventions: int
    takeovers: int
    decisions: int
    control_ticks: int
    tree_ticks: int
    sim_time: float
    wall_time: float
    needed_on_table: dict[str, bool]
    decision_log: tuple[str, ...]
    startup_to_first_decision_s: float | None = None
    wall_breakdown: dict[str, float] = field(default_factory=dict)
    cpu_breakdown: dict[str, float] = field(default_factory=dict)
    physics_steps: int = 0
    physics_steps_skipped: int = 0
    renders: int = 0
    condition: str = ""
    decided_by_rule: dict[str, int] = field(default_factory=dict)
    not_stocked: int = 0
    failure_budget: float | None = None
    strict_promise: bool = False
    bodies: int = 0
    constraints: int = 0
    set_back: int = 0

    def deterministic_part(self) -> dict[str, Any]:
        """The fields a seeded rerun must reproduce exactly."""
        d = asdict(self)
        for timing in ("wall_time", "startup_to_first_decision_s", "wall_breakdown", "cpu_breakdown"):
            d.pop(timing)
        d.pop("tree_ticks")  # ticks while the planner thread computes depend on the machine's speed
        return d

    def format(self) -> str:
        fails = ", ".join(f"{k} {v}" for k, v in sorted(self.failures_by_stage.items())) or "none"
        on_table = sum(self.needed_on_table.values())
        # the recipe's ingredients no product stands for: the human brings them (not counted above)
        brought = (
            f"   {self.not_stocked} more not stocked (the human brings them)" if self.not_stocked else ""
        )
        # an attempt the episode's end cut short has no outcome: said, so the counts add up
        cut = self.attempted - self.successes - self.failures - self.takeovers - self.set_back
        labelled = self.successes + self.failures
        rate = (
            f"   failure rate {percent(round(self.failures / labelled, 3))} (budget {percent(self.failure_budget)}, "
            f"{promise_words(self.strict_promise)})"
            if self.failure_budget is not None and labelled
            else ""
        )
        rules = ", ".join(f"{RULE_LABELS.get(k, k)} {v}" for k, v in sorted(self.decided_by_rule.items()))
        return "\n".join(
            [
                f"── summary: {self.recipe_title} ({self.recipe_id}) with {self.robot} ──",
                *([f"condition          {self.condition}"] if self.condition else []),
                f"steps completed    {self.steps_completed}/{self.steps_total}{'' if self.completed else '  (stopped early)'}",
                f"ingredients        {on_table}/{len(self.needed_on_table)} on the table{brought}",
                f"actions attempted  {self.attempted}   successes {self.successes}   failures {self.failures} ({fails})"
                + (f"   taken over {self.takeovers}" if self.takeovers else "")
                + (f"   set back after a heft {self.set_back}" if self.set_back else "")
                + (f"   cut short by the end of the episode {cut}" if cut > 0 else "")
                + rate,
                f"help requests      {self.help_requests}   clarifications {self.clarifications}"
                f"   interventions {self.interventions}",
                f"decisions          {self.decisions}   control ticks {self.control_ticks}"
                + (f"   made by a rule, not κ̂: {rules}" if rules else ""),
                f"time               {self.sim_time:.1f} s simulated, {self.wall_time:.1f} s wall",
            ]
        )
