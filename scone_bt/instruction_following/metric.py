"""The instruction-following (IF) metric of the SCONE paper's Table I.

In each state the policy repeatedly picks its most relevant remaining action until it stops or none remain.
A state's accuracy is the share of its picks that were relevant; its recall the share of relevant actions
picked. Both are averaged over states. A policy that picks nothing in a state that has relevant actions scores 0
there (its share is undefined, and stopping at once is the wrong answer); in a state with none it scores 1.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Protocol

from scone_bt.instruction_following.states import IfState

__all__ = ["Policy", "Episode", "IfScore", "run_episode", "score_episode", "evaluate"]


class Policy(Protocol):
    """Chooses the next action for an instruction, or None to stop."""

    name: str

    def choose(self, state: IfState, remaining: Sequence[str], picked: Sequence[str]) -> str | None:
        """The next action among ``remaining`` (never one already ``picked``), or None to stop."""
        ...


@dataclass(frozen=True)
class Episode:
    """What a policy did in one state.

    Attributes:
        state: The state.
        picks: Actions in the order picked.
        accuracy: Share of picks that were relevant, in [0, 1].
        recall: Share of relevant actions picked, in [0, 1] (1 when none were relevant).
    """

    state: IfState
    picks: tuple[str, ...]
    accuracy: float
    recall: float


@dataclass(frozen=True)
class IfScore:
    """A policy's IF scores over a set of states.

    Attributes:
        policy: Policy name.
        accuracy: Mean per-state accuracy, in [0, 1].
        recall: Mean per-state recall, in [0, 1].
        picks_per_state: Mean number of picks.
        empty_states: States where the policy picked nothing.
        states: Number of states.
        episodes: Per-state detail, for failure analysis.
    """

    policy: str
    accuracy: float
    recall: float
    picks_per_state: float
    empty_states: int
    states: int
    episodes: tuple[Episode, ...]

    def to_json(self) -> dict[str, object]:
        """Summary numbers (no per-state detail)."""
        return {
            "policy": self.policy,
            "accuracy": round(self.accuracy, 4),
            "recall": round(self.recall, 4),
            "picks_per_state": round(self.picks_per_state, 3),
            "empty_states": self.empty_states,
            "states": self.states,
        }


def score_episode(state: IfState, picks: Sequence[str]) -> Episode:
    """Accuracy and recall of one sequence of picks."""
    hits = sum(1 for p in picks if p in state.relevant)
    # No picks: right only when nothing was relevant.
    accuracy = hits / len(picks) if picks else float(not state.relevant)
    recall = hits / len(state.relevant) if state.relevant else 1.0
    return Episode(state=state, picks=tuple(picks), accuracy=accuracy, recall=recall)


def run_episode(policy: Policy, state: IfState) -> Episode:
    """Let the policy pick until it stops or no action remains."""
    remaining = list(state.available)
    picks: list[str] = []
    while remaining:
        choice = policy.choose(state, tuple(remaining), tuple(picks))
        if choice is None:
            break
        if choice not in remaining:
            raise ValueError(
                f"policy {policy.name!r} picked {choice!r}, which is not among the remaining actions"
            )
        picks.append(choice)
        remaining.remove(choice)
    return score_episode(state, picks)


def evaluate(policy: Policy, states: Sequence[IfState]) -> IfScore:
    """The policy's IF accuracy and recall averaged over ``states`` (which must not be empty)."""
    if not states:
        raise ValueError("no states to evaluate")
    episodes = tuple(run_episode(policy, s) for s in states)
    n = len(episodes)
    return IfScore(
        policy=policy.name,
        accuracy=sum(e.accuracy for e in episodes) / n,
        recall=sum(e.recall for e in episodes) / n,
        picks_per_state=sum(len(e.picks) for e in episodes) / n,
        empty_states=sum(1 for e in episodes if not e.picks),
        states=n,
        episodes=episodes,
    )
