"""Draws the episode's course: simulated time, the counters (attempts, failures, help requests...), the recipe's
progress and the printed log lines."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import rerun as rr

from scone_bt.viz import paths as P
from scone_bt.viz.render import recipe_markdown
from scone_bt.viz.series import NamedSeries
from scone_bt.viz.sinks import Sinks
from scone_bt.viz.snapshot import RecipeView
from scone_bt.viz.tick_rows import TickRows

__all__ = ["TimelineDrawer"]


class TimelineDrawer:
    """Simulated time each tick; a counter or the recipe when it changed; every log line."""

    def __init__(self, sinks: Sinks) -> None:
        self._sinks = sinks
        self._counters: dict[str, int] = {}
        self._counter_series = NamedSeries(sinks, P.COUNTERS, step=True)
        self._recipe: RecipeView | None = None
        self._times: TickRows[float] = TickRows(
            sinks, P.EPISODE_SIM_TIME, lambda times: rr.Scalars.columns(scalars=times)
        )

    def log_static(self) -> None:
        """The simulated-time series' name (static)."""
        self._sinks.rec.log(P.EPISODE_SIM_TIME, rr.SeriesLines(names=["simulated time (s)"]), static=True)

    def log_sim_time(self, tick: int, sim_time: float) -> None:
        """Simulated time at this tick, sent in batches (viz.tick_rows: one call per batch)."""
        self._times.keep(tick, sim_time, [float(sim_time)])

    def flush(self) -> None:
        """Send the kept simulated times now (the recorder's flush and close call it)."""
        self._times.flush()

    def log_counters(self, counters: Mapping[str, int]) -> None:
        for name, value in counters.items():
            if self._counters.get(name) != value:
                self._counters[name] = int(value)
                self._counter_series.log(name, float(value))

    def log_recipe(self, recipe: RecipeView) -> None:
        """The recipe's steps and their state, when they changed."""
        if recipe != self._recipe:
            self._recipe = recipe
            self._sinks.rec.log(
                P.RECIPE, rr.TextDocument(recipe_markdown(recipe), media_type=rr.MediaType.MARKDOWN)
            )

    def log_lines(self, lines: Sequence[str]) -> None:
        for line in lines:
            self._sinks.rec.log(P.LOG, rr.TextLog(line, level=_log_level(line)))


def _log_level(line: str) -> rr.TextLogLevel:
    head = line.lstrip().lower()
    if head.startswith(("error", "failed", "failure")):
        return rr.TextLogLevel.ERROR
    if head.startswith(("warn", "ask", "help", "- set back")):
        return rr.TextLogLevel.WARN
    return rr.TextLogLevel.INFO
