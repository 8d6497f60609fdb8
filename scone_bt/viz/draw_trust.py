"""Draws the person's estimated trust in each object's fetch, beside the robot's κ̂ for it."""

from __future__ import annotations

import math
from collections.abc import Mapping

from scone_bt.viz import paths as P
from scone_bt.viz.series import NamedSeries
from scone_bt.viz.sinks import Sinks

__all__ = ["TrustDrawer"]


class TrustDrawer:
    """One series per object under the person-trust root (finite values only)."""

    def __init__(self, sinks: Sinks) -> None:
        self._series = NamedSeries(sinks, P.PERSON_TRUST)

    def log_trust(self, person_trust: Mapping[str, float]) -> None:
        for name, value in person_trust.items():
            if math.isfinite(value):
                self._series.log(name, float(value))
