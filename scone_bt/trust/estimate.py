"""The person's trust, estimated online: the fitted trust-transfer model fed what the person saw in the episode.

An `OnlineTrust` is an event sink. Outcomes and help requests update it; the other events are ignored. `estimate`
turns the κ̂ of the actions now on offer into `TrustEstimated` events, one per action, each with its risk:

- **over-trust**: the predicted trust exceeds κ̂ by at least `over_margin`: the person likely relies on an action the
  robot expects to fail;
- **under-trust**: the person saw similar actions fail (failure exposure, the summed kernel similarity to failures
  seen, at least `exposure`) and κ̂ exceeds their predicted trust by at least `under_margin`.

The margins are assumptions (no data says where a gap becomes a risk); the trust model is fitted
(scone_bt.trust.transfer).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from scone_bt.errors import SconeError
from scone_bt.events import ActOutcome, Event, HelpRequested, TrustEstimated
from scone_bt.trust.transfer import TransferModel

__all__ = ["OnlineTrust", "RiskOptions", "classify_risk", "confidence_in_words"]


@dataclass(frozen=True)
class RiskOptions:
    """When a gap between the person's trust and κ̂ is logged as a risk (all assumed).

    Attributes:
        over_margin: Trust minus κ̂ (probability) from which over-trust is flagged.
        under_margin: κ̂ minus trust from which under-trust is flagged.
        exposure: Failure exposure (Σ kernel to failures seen) from which the person "saw similar actions fail".
        help_logit: Logit change per help request on the same action (assumed, as for the simulated participants).
    """

    over_margin: float = 0.25
    under_margin: float = 0.25
    exposure: float = 0.5
    help_logit: float = 0.06

    def __post_init__(self) -> None:
        for name in ("over_margin", "under_margin"):
            if not 0.0 <= getattr(self, name) <= 1.0:
                raise SconeError(f"trust risk option {name} must be in [0, 1], got {getattr(self, name)}")
        if self.exposure < 0:
            raise SconeError(f"trust risk option exposure must be 0 or more, got {self.exposure}")


def confidence_in_words(object_name: str, confidence: float) -> str:
    """What the robot says before an act the person likely over-trusts (trust_aware)."""
    return (
        f"I am not sure about this one: I may drop the {object_name} "
        f"(I expect to succeed {confidence:.0%} of the time)."
    )


def classify_risk(
    trust: float, confidence: float, exposure: float, options: RiskOptions = RiskOptions()
) -> str:
    """ "over", "under" or "" for one action (see the module docstring)."""
    if trust - confidence >= options.over_margin:
        return "over"
    if exposure >= options.exposure and confidence - trust >= options.under_margin:
        return "under"
    return ""


class OnlineTrust:
    """Tracks what the person saw and predicts their trust per action.

    Args:
        model: The fitted model (`TransferModel(load_fitted())`).
        options: Risk margins.
        disposition: The person's disposition (logit); 0 for an unknown person.
    """

    def __init__(
        self, model: TransferModel, options: RiskOptions = RiskOptions(), disposition: float = 0.0
    ) -> None:
        self.model = model
        self.options = options
        self.disposition = disposition
        self._seen: list[tuple[str, float, bool]] = []  # (action, logit effect at k = 1, a failure)

    def __call__(self, event: Event) -> None:
        """The EventSink: outcomes and help requests are what moves a person's trust."""
        p = self.model.params
        if isinstance(event, ActOutcome):
            effect = p.success_gain if event.success else -p.failure_loss
            self._seen.append((event.action, effect, not event.success))
        elif isinstance(event, HelpRequested):
            self._seen.append((event.action, self.options.help_logit, False))

    def trust(self, actions: Sequence[str]) -> np.ndarray:
        """Predicted trust (probability) per action."""
        logit = self.model.prior_logit(actions) + self.disposition
        if self._seen:
            k = self.model.kernel(actions, [a for a, _, _ in self._seen])
            logit = logit + k @ np.array([g for _, g, _ in self._seen])
        return 1.0 / (1.0 + np.exp(-logit))

    def exposure(self, actions: Sequence[str]) -> np.ndarray:
        """Σ k(action, o) over the failures seen: how much the person saw actions like these fail."""
        failed = [a for a, _, f in self._seen if f]
        if not failed:
            return np.zeros(len(actions))
        return self.model.kernel(actions, failed).sum(axis=1)

    def estimate(self, sim_time: float, offered: Mapping[str, tuple[str, float]]) -> list[TrustEstimated]:
        """One event per offered action (action text -> (object name, κ̂)), in the mapping's order."""
        actions = list(offered)
        if not actions:
            return []
        trust, exposure = self.trust(actions), self.exposure(actions)
        out = []
        for action, t, e in zip(actions, trust, exposure, strict=True):
            name, kappa = offered[action]
            risk = classify_risk(float(t), float(kappa), float(e), self.options)
            out.append(
                TrustEstimated(sim_time, action, name, round(float(t), 4), round(float(kappa), 4), risk)
            )
        return out
