"""Named scalar series: one plot line per name (an object's κ̂, a person's trust in it, a counter)."""

from __future__ import annotations

import rerun as rr

from scone_bt.viz.render import slug
from scone_bt.viz.sinks import Sinks

__all__ = ["NamedSeries"]


class NamedSeries:
    """Scalars under ``root``/<slug of name>, each series named once (static) when first logged.

    Args:
        sinks: The recording's streams.
        root: The entity path the series sit under.
        step: Drawn as steps (a count), not interpolated.
    """

    def __init__(self, sinks: Sinks, root: str, step: bool = False) -> None:
        self._sinks = sinks
        self._root = root
        self._step = step
        self._named: set[str] = set()

    def log(self, name: str, value: float) -> None:
        entity = f"{self._root}/{slug(name)}"
        if entity not in self._named:
            self._named.add(entity)
            mode = rr.components.InterpolationMode.StepAfter if self._step else None
            self._sinks.rec.log(entity, rr.SeriesLines(names=[name], interpolation_mode=mode), static=True)
        self._sinks.rec.log(entity, rr.Scalars(value))
