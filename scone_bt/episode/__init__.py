"""One cooking episode: build the world and the tree, tick until the recipe is done, summarise."""

from scone_bt.episode.printer import LinePrinter, decision_line
from scone_bt.episode.resources import EpisodeResources, ModelPool
from scone_bt.episode.runner import EpisodeOptions, run_episode
from scone_bt.episode.summary import EpisodeSummary

__all__ = [
    "EpisodeOptions",
    "EpisodeResources",
    "EpisodeSummary",
    "LinePrinter",
    "ModelPool",
    "decision_line",
    "run_episode",
]
