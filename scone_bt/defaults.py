"""The one source of an episode's defaults: `EpisodeOptions`, `scone-run`, `scone-study` and scenario files read
them from here (a light module: the command lines build their help text without importing the simulator)."""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["EPISODE", "EpisodeDefaults"]


@dataclass(frozen=True)
class EpisodeDefaults:
    """What an episode is when nothing says otherwise.

    Attributes:
        arm: Robot file (robots/<name>.yaml; ``--arm``; the backend it runs on is ``--robot``).
        kitchen: Kitchen file (perception/<name>.yaml).
        tree: Tree file (trees/<name>.yaml).
        recipe: Recipe reference (example:<name>, a corpus id or a file).
        seed: The default of both seeds of an episode: the world's and the human's (`EpisodeOptions.seed`) and
            the robot's own streams (`BehaviourOptions.seed`).
        max_ticks: Limit on control ticks.
        tick_period: Simulated seconds per control tick.
        distractors: Products not in the recipe put on the shelf.
        takeover_probability: Chance the simulated human takes over an action the robot attempts, in [0, 1].
        learn_from: Whose stored outcomes rebuild κ̂ from an outcome store: "self", "same-model" or "fleet".
    """

    arm: str = "panda"
    kitchen: str = "kitchen"
    tree: str = "assistive_cooking"
    recipe: str = "example:tomato-pasta"
    seed: int = 0
    max_ticks: int = 4000
    tick_period: float = 0.1
    distractors: int = 6
    takeover_probability: float = 0.0
    learn_from: str = "self"


EPISODE = EpisodeDefaults()
"""The defaults."""
