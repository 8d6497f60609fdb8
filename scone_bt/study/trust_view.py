"""The person's estimated trust on the tablet's study view: per action on offer, beside κ̂, risks in plain words.

A `TrustView` is the tablet's copy of the online estimate (`scone_bt.trust.estimate.OnlineTrust`, the trust-transfer
model fitted to human ratings). It is fed every event of the episode; at each decision it estimates the person's
trust in every action the gate scored, from the κ̂ the gate computed for it, and turns the `TrustEstimated` events
into `TrustRow` lines. The researcher's page always shows them; the participant's tablet only while the researcher
shows them (`TabletState.show_trust`).

The rows are the tablet's view, not events of the episode: the study log stores the episode's events as they are
with and without the view (and a ``trust_view`` record each time the researcher shows or hides it).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from scone_bt.events import DecisionMade, Event, TrustEstimated

__all__ = ["BlackboardOffer", "RISK_WORDS", "TrustRow", "TrustView", "trust_rows"]

RISK_WORDS: Mapping[str, str] = {
    "over": "over-trust risk: likely trusted more than the robot's confidence warrants",
    "under": "under-trust risk: similar actions were seen to fail, but the robot is confident",
    "": "no risk flagged",
}
"""What each risk (`scone_bt.trust.estimate.classify_risk`) means, in the words the study view shows."""


@dataclass(frozen=True)
class TrustRow:
    """One action's line of the study view.

    Attributes:
        object_name: The object the action moves.
        action: The action text.
        trust: The person's estimated trust that the robot succeeds, in [0, 1].
        confidence: κ̂ for the action, in [0, 1].
        risk: "over", "under" or "".
        words: The risk in plain words (`RISK_WORDS`).
    """

    object_name: str
    action: str
    trust: float
    confidence: float
    risk: str
    words: str

    def to_json(self) -> dict[str, Any]:
        return {
            "object": self.object_name,
            "action": self.action,
            "trust": self.trust,
            "confidence": self.confidence,
            "risk": self.risk,
            "words": self.words,
        }


def trust_rows(estimates: Sequence[TrustEstimated]) -> list[TrustRow]:
    """The study view's lines for the estimates, in their order."""
    return [
        TrustRow(e.object_name, e.action, e.trust, e.confidence, e.risk, RISK_WORDS[e.risk])
        for e in estimates
    ]


class BlackboardOffer:
    """Action text -> (object, κ̂) for every action the gate scored at a decision, in its ranking.

    The gate writes κ̂ of every ranked action to the blackboard before it emits the decision, so an event sink
    reading it on the episode's thread sees this decision's values. Without them (no tree: a test feeding events),
    the decision's own action. Actions without a finite κ̂ are left out.
    """

    def __init__(self) -> None:
        self._reader: Any = None

    def _client(self) -> Any:
        import py_trees

        from scone_bt.behaviours.base import Keys

        if self._reader is None:  # one client: py_trees keeps every client it ever made
            self._reader = py_trees.blackboard.Client(name="tablet-trust")
            for key in (Keys.CONFIDENCES, Keys.AFFORDANCES):
                self._reader.register_key(key=key, access=py_trees.common.Access.READ)
        return self._reader

    def __call__(self, decision: DecisionMade) -> dict[str, tuple[str, float]]:
        from scone_bt.behaviours.base import Keys

        reader = self._client()
        conf = reader.get(Keys.CONFIDENCES) if reader.exists(Keys.CONFIDENCES) else None
        affordances = reader.get(Keys.AFFORDANCES) if reader.exists(Keys.AFFORDANCES) else None
        objects = {a.text: a.object_name for a in affordances or []}
        offered = {t: (objects[t], float(c)) for t, c in (conf or {}).items() if t in objects}
        if not offered and decision.action is not None and decision.object_name is not None:
            offered = {decision.action: (decision.object_name, decision.confidence)}
        return {t: (name, c) for t, (name, c) in offered.items() if math.isfinite(c)}


def _fitted_online_trust() -> Any:
    """The fitted model's online estimate (its ζ loads here, once per process)."""
    from scone_bt.trust.estimate import OnlineTrust
    from scone_bt.trust.transfer import TransferModel, load_fitted

    return OnlineTrust(TransferModel(load_fitted()))


class TrustView:
    """The tablet's online estimate of the person's trust: an event sink that returns rows at each decision.

    Args:
        make_trust: Builds the `OnlineTrust` (default: the fitted model); called once, by `load` or the first event.
        offered: The actions on offer at a decision (default `BlackboardOffer`, the blackboard's κ̂).
    """

    def __init__(
        self,
        make_trust: Callable[[], Any] = _fitted_online_trust,
        offered: Callable[[DecisionMade], Mapping[str, tuple[str, float]]] | None = None,
    ) -> None:
        self._make_trust = make_trust
        self._offered = offered or BlackboardOffer()
        self._trust: Any = None

    def load(self) -> None:
        """Build the model now (before Start: loading ζ at the first decision would stall the episode)."""
        if self._trust is None:
            self._trust = self._make_trust()

    def __call__(self, event: Event) -> list[TrustRow] | None:
        """Feed one event; at a decision, the rows for the actions on offer (None for other events)."""
        self.load()
        self._trust(event)
        if not isinstance(event, DecisionMade):
            return None
        return trust_rows(self._trust.estimate(event.sim_time, self._offered(event)))
