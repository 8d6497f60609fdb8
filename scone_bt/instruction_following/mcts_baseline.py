"""TICC-style baseline: Monte-Carlo tree search over robot actions, with the robot's proficiency in the reward.

After Lee, Fong, Kok & Soh, "Getting to Know One Another: Calibrating Intent, Capabilities and Trust for
Human-Robot Collaboration" (IROS 2020), whose TICC-POMDP plans with POMCP over a hidden human intent while its
reward accounts for the robot's estimated capability and the human's trust. Here:

- hidden intent: the set of items the instruction needs; the belief gives each action an independent
  probability of being needed (an intent model, e.g. calibrated embedding similarity);
- proficiency: the robot's estimated success probability for each action, from the item's shelf tier;
- dynamics: a fetch succeeds with that probability; a needed item earns +1, an unneeded one costs
  ``wrong_penalty``, a failed fetch ``failure_cost``; trust rises after a good fetch and falls after a wrong or
  failed one, and after each fetch the human keeps delegating with probability equal to trust;
- search: UCT with root sampling of the hidden intent (as in POMCP), open-loop over action sequences, rollouts
  greedy on the belief. The policy executes the best root action (or stops) and searches again after each pick.
"""

from __future__ import annotations

import math
import zlib
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from scone_bt.instruction_following.states import IfState

__all__ = ["MctsOptions", "TiccMctsPolicy", "mcts_decide"]

_STOP = "<stop>"


@dataclass(frozen=True)
class MctsOptions:
    """Search and model settings.

    Attributes:
        simulations: Simulations per decision.
        exploration: UCB1 exploration constant.
        horizon: Most fetches a simulation plans ahead.
        discount: Per-fetch discount factor.
        tier_success: Estimated fetch success probability per shelf tier (tier 0 lowest); unknown tiers use the
            last entry.
        wrong_penalty: Cost of fetching an item that is not needed.
        failure_cost: Cost of a failed fetch.
        initial_trust: Human trust at the start of an instruction, in [0, 1].
        trust_gain: Fraction of the distance to 1 that trust gains after a needed fetch.
        trust_loss: Fraction of trust lost after a wrong or failed fetch.
        seed: Seeds the search.
    """

    simulations: int = 300
    exploration: float = 1.0
    horizon: int = 6
    discount: float = 0.95
    tier_success: tuple[float, ...] = (0.95, 0.85, 0.7)
    wrong_penalty: float = 1.0
    failure_cost: float = 0.5
    initial_trust: float = 0.9
    trust_gain: float = 0.1
    trust_loss: float = 0.3
    seed: int = 0


@dataclass
class _Node:
    visits: int = 0
    value: float = 0.0
    children: dict[str, _Node] = field(default_factory=dict)


def _step(
    action: str,
    needed: set[str],
    trust: float,
    success: dict[str, float],
    opts: MctsOptions,
    rng: np.random.Generator,
) -> tuple[float, float, bool]:
    """Reward, new trust, and whether the human keeps delegating after one fetch."""
    if rng.random() < success[action]:
        if action in needed:
            reward, trust = 1.0, trust + opts.trust_gain * (1.0 - trust)
        else:
            reward, trust = -opts.wrong_penalty, trust * (1.0 - opts.trust_loss)
    else:
        reward, trust = -opts.failure_cost, trust * (1.0 - opts.trust_loss)
    return reward, trust, bool(rng.random() < trust)


def _rollout_value(belief: float, p_success: float, opts: MctsOptions) -> float:
    return p_success * (belief - (1.0 - belief) * opts.wrong_penalty) - (1.0 - p_success) * opts.failure_cost


def _backup(root: _Node, path: list[_Node], rewards: list[float], tail: float, discount: float) -> None:
    """Back the simulation's discounted returns up the nodes of ``path`` (after ``root``), the rollout's ``tail``
    after the last reward."""
    ret = tail * discount ** len(rewards)
    for k in range(len(rewards) - 1, -1, -1):
        ret = rewards[k] + discount * ret
        n = path[k + 1]
        n.visits += 1
        n.value += (ret - n.value) / n.visits
    root.visits += 1


def mcts_decide(
    remaining: Sequence[str],
    belief: dict[str, float],
    success: dict[str, float],
    options: MctsOptions | None = None,
    rng: np.random.Generator | None = None,
) -> tuple[str | None, dict[str, float]]:
    """One TICC-style decision: the action to fetch now, or None to stop.

    Args:
        remaining: Actions still possible.
        belief: Action → probability that the instruction needs it.
        success: Action → estimated probability that fetching it succeeds.
        options: Search and model settings.
        rng: Random source (default: seeded from ``options.seed``).

    Returns:
        The chosen action (None for stop) and each root action's mean return.
    """
    opts = options or MctsOptions()
    rng = rng or np.random.default_rng(opts.seed)
    actions = list(remaining)
    if not actions:
        return None, {}
    root = _Node()
    for _ in range(opts.simulations):
        needed = {a for a, u in zip(actions, rng.random(len(actions)), strict=True) if u < belief[a]}
        node, path, rewards = root, [root], []
        left, trust, depth, alive = list(actions), opts.initial_trust, 0, True
        # Selection and expansion along the tree.
        while alive and depth < opts.horizon:
            options_here = [*left, _STOP]
            untried = [a for a in options_here if a not in node.children]
            if untried:
                a = untried[int(rng.integers(len(untried)))]
                node.children[a] = _Node()
                expanded = True
            else:
                log_n = math.log(node.visits + 1)
                a = max(
                    options_here,
                    key=lambda x: (
                        node.children[x].value
                        + opts.exploration * math.sqrt(log_n / (node.children[x].visits + 1e-9))
                    ),
                )
                expanded = False
            node = node.children[a]
            path.append(node)
            if a == _STOP:
                rewards.append(0.0)
                alive = False
                break
            r, trust, alive = _step(a, needed, trust, success, opts, rng)
            rewards.append(r)
            left.remove(a)
            depth += 1
            if expanded:
                break
        # Rollout: fetch greedily by expected value under the belief while it is positive.
        tail, disc = 0.0, 1.0
        while alive and left and depth < opts.horizon:
            a = max(left, key=lambda x: _rollout_value(belief[x], success[x], opts))
            if _rollout_value(belief[a], success[a], opts) <= 0.0:
                break
            r, trust, alive = _step(a, needed, trust, success, opts, rng)
            tail += disc * r
            disc *= opts.discount
            left.remove(a)
            depth += 1
        _backup(root, path, rewards, tail, opts.discount)
    values = {a: c.value for a, c in root.children.items() if c.visits}
    best = max(values, key=lambda a: (values[a], root.children[a].visits))
    return (None if best == _STOP else best), values


@dataclass
class TiccMctsPolicy:
    """Fetches what the TICC-style search chooses, searching again after each pick, until it chooses to stop.

    Attributes:
        belief_fn: State → action → probability that the instruction needs it (the intent model).
        options: Search and model settings.
        name: Row label in the results table.
    """

    belief_fn: Callable[[IfState], dict[str, float]]
    options: MctsOptions = field(default_factory=MctsOptions)
    name: str = "TICC-style MCTS"

    def success(self, state: IfState) -> dict[str, float]:
        """The robot's proficiency estimate per action, from its shelf tier."""
        table = self.options.tier_success
        out = {}
        for a in state.available:
            tier = state.locations.get(a, (len(table) - 1, 0))[0]
            out[a] = table[min(max(tier, 0), len(table) - 1)]
        return out

    def choose(self, state: IfState, remaining: Sequence[str], picked: Sequence[str]) -> str | None:
        """The searched action, or None when stopping has the best value."""
        # Seed per state and step so results do not depend on evaluation order.
        seed = (self.options.seed, _hash_text(state.instruction), len(picked))
        rng = np.random.default_rng(seed)
        choice, _ = mcts_decide(remaining, self.belief_fn(state), self.success(state), self.options, rng)
        return choice


def _hash_text(text: str) -> int:
    """A stable 32-bit hash of a text (Python's hash() is salted per process)."""
    return zlib.crc32(text.encode())
