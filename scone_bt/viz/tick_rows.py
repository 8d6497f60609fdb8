"""Rows logged tick by tick, sent to rerun in one `send_columns` call per batch (`TickRows`).

A call costs about as much as a tick's physics step: the moved bodies and the simulated time, sent each in its own
call every tick, were a third of the recorder's cost (`scone-bench viz`). A batch goes out after `BATCH_TICKS`
ticks or `BATCH_WALL_S` of wall time, whichever comes first, and on every flush. Each row carries the tick and
simulated time it was logged at, so the recording is the same either way; a live viewer sees it at most
`BATCH_WALL_S` later.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from typing import Any, Generic, TypeVar

import numpy as np
import rerun as rr

from scone_bt.viz import paths as P
from scone_bt.viz.sinks import Sinks

__all__ = ["BATCH_TICKS", "BATCH_WALL_S", "TickRows", "sim_time_column"]

BATCH_TICKS = 100
"""Ticks whose rows are sent together at the most."""
BATCH_WALL_S = 0.1
"""Wall seconds a kept row waits at the most (what a live viewer lags by)."""

Row = TypeVar("Row")


def sim_time_column(seconds: Sequence[float] | np.ndarray) -> rr.TimeColumn:
    """The simulated-time index of rows at ``seconds``, in whole nanoseconds rounded as ``rr.set_time`` rounds.

    One numpy conversion for the column: given plain floats, rerun converts them one by one (a third of a batch's
    cost), and given a float array it truncates, so a row could land a nanosecond before the tick it was logged at.
    """
    nanos = np.round(np.asarray(seconds, dtype=float) * 1e9).astype(np.int64)
    return rr.TimeColumn(P.SIM_TIME, duration=nanos.astype("timedelta64[ns]"))


class TickRows(Generic[Row]):
    """One entity's rows, kept with their tick and simulated time until due, then sent in one call.

    Args:
        sinks: Where the recording goes.
        path: The entity the rows are logged to.
        columns: The component columns of a batch's rows (e.g. ``rr.Scalars.columns``).
    """

    def __init__(self, sinks: Sinks, path: str, columns: Callable[[list[Row]], Any]) -> None:
        self._sinks = sinks
        self._path = path
        self._columns = columns
        self._rows: list[tuple[int, float, Row]] = []
        self._ticks = 0
        self._since: float | None = None

    def keep(self, tick: int, sim_time: float, rows: Sequence[Row]) -> None:
        """This tick's rows (none: nothing kept, no tick counted); the batch goes out once it is due.

        Call it every tick, with no rows when nothing changed: the wall-time bound is checked here, so rows kept
        before the arm came to rest go out within BATCH_WALL_S, not when something next moves.
        """
        if rows:
            self._rows.extend((int(tick), float(sim_time), row) for row in rows)
            self._ticks += 1
            if self._since is None:
                self._since = time.monotonic()
        if self._since is not None and (
            self._ticks >= BATCH_TICKS or time.monotonic() - self._since >= BATCH_WALL_S
        ):
            self.flush()

    def flush(self) -> None:
        """Send every kept row now (nothing when none is kept)."""
        self._ticks, self._since = 0, None
        if not self._rows:
            return
        rows, self._rows = self._rows, []
        self._sinks.rec.send_columns(
            self._path,
            indexes=[
                rr.TimeColumn(P.TICK, sequence=np.fromiter((r[0] for r in rows), np.int64, len(rows))),
                sim_time_column(np.fromiter((r[1] for r in rows), float, len(rows))),
            ],
            columns=self._columns([r[2] for r in rows]),
        )
