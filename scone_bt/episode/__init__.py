"""One cooking episode: build the world and the tree, tick until the recipe is done, summarise."""

from scone_bt.episode.runner import EpisodeOptions, EpisodeSummary, run_episode

__all__ = ["EpisodeOptions", "EpisodeSummary", "run_episode"]
