"""Draws the robot's decisions: the affordances ranked by relevance and κ̂, the gate's decision and its reason,
and each object's κ̂ over time."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import numpy as np
import rerun as rr

from scone_bt.experience.types import ExecutionContext
from scone_bt.gate.types import Decision, DecisionKind
from scone_bt.viz import paths as P
from scone_bt.viz.colours import GATE_COLOURS
from scone_bt.viz.render import affordances_markdown, decision_markdown, rank_affordances
from scone_bt.viz.series import NamedSeries
from scone_bt.viz.sinks import Sinks
from scone_bt.viz.snapshot import AffordanceRow

__all__ = ["CONFIDENCE_BARS", "RELEVANCE_BARS", "DecisionDrawer"]

RELEVANCE_BARS = (31, 119, 180)
"""The relevance bars' colour (RGB)."""
CONFIDENCE_BARS = (44, 160, 44)
"""The κ̂ bars' colour (RGB)."""


class DecisionDrawer:
    """The affordance bars and table, the gate's decision (text, kind, chosen κ̂ and relevance), κ̂ per object."""

    def __init__(self, sinks: Sinks) -> None:
        self._sinks = sinks
        self._rows: list[AffordanceRow] = []
        self._contexts: dict[str, ExecutionContext] = {}
        self._decision: Decision | None = None
        self._confidence = NamedSeries(sinks, P.CONFIDENCE)

    def log_static(self) -> None:
        """The decision kinds' colours and the chosen action's series' names (static)."""
        rec = self._sinks.rec
        rec.log(
            P.GATE_KIND,
            rr.StateConfiguration(values=list(GATE_COLOURS), colors=list(GATE_COLOURS.values())),
            static=True,
        )
        # The bars' colours never change: sent once, not with every chart. (BarChart.from_fields(color=...)
        # without values trips rerun's values converter, so the colour goes as its own component.)
        for path, colour in (
            (P.AFFORDANCE_RELEVANCE, RELEVANCE_BARS),
            (P.AFFORDANCE_CONFIDENCE, CONFIDENCE_BARS),
        ):
            rec.log(
                path,
                [rr.components.ColorBatch([colour]).described(rr.BarChart.descriptor_color())],
                static=True,
            )
        rec.log(P.GATE_CONFIDENCE, rr.SeriesLines(names=["chosen action κ̂"]), static=True)
        rec.log(P.GATE_RELEVANCE, rr.SeriesLines(names=["chosen action relevance"]), static=True)

    def log_gate(
        self,
        rows: Sequence[AffordanceRow] | None,
        decision: Decision | None,
        contexts: Mapping[str, ExecutionContext] | None = None,
    ) -> None:
        """New affordance rows and/or a new decision; the table shows the latest of both."""
        rec = self._sinks.rec
        if rows is not None:
            self._rows = rank_affordances(rows)
            self._contexts = dict(contexts or {})
            relevance = np.nan_to_num(np.array([r[1] for r in self._rows], dtype=float))
            confidence = np.nan_to_num(np.array([r[2] for r in self._rows], dtype=float))
            rec.log(P.AFFORDANCE_RELEVANCE, rr.BarChart(relevance))
            rec.log(P.AFFORDANCE_CONFIDENCE, rr.BarChart(confidence))
        if decision is not None:
            self._log_decision(decision)
        rec.log(
            P.AFFORDANCE_TABLE,
            rr.TextDocument(
                affordances_markdown(self._rows, self._decision, self._contexts),
                media_type=rr.MediaType.MARKDOWN,
            ),
        )

    def log_confidences(self, confidences: Mapping[str, float]) -> None:
        """κ̂ per object (finite values only)."""
        for name, value in confidences.items():
            if math.isfinite(value):
                self._confidence.log(name, float(value))

    def _log_decision(self, decision: Decision) -> None:
        rec = self._sinks.rec
        self._decision = decision
        rec.log(
            P.GATE_DECISION, rr.TextDocument(decision_markdown(decision), media_type=rr.MediaType.MARKDOWN)
        )
        rec.log(P.GATE_KIND, rr.StateChange(state=[decision.kind.value]))
        if decision.kind is not DecisionKind.IDLE and math.isfinite(decision.confidence):
            rec.log(P.GATE_CONFIDENCE, rr.Scalars(float(decision.confidence)))
            rec.log(P.GATE_RELEVANCE, rr.Scalars(float(decision.relevance)))
        level = rr.TextLogLevel.WARN if decision.kind is DecisionKind.ASK else rr.TextLogLevel.INFO
        rec.log(
            P.LOG,
            rr.TextLog(
                f"gate: {decision.kind.value} {decision.action or ''} — {decision.reason}", level=level
            ),
        )
