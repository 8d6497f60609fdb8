"""A simulated participant: a latent trust that follows what the robot does, take-overs, and questionnaire answers.

The trust model (documented in docs/study.md):

- Trust ``t`` in (0, 1) is the participant's belief that the robot's next action will succeed. It starts at
  ``sigmoid(initial_mean + u_p)``, with ``u_p ~ Normal(0, initial_sd)`` a participant's disposition.
- A success moves it towards 1: ``t += success_gain * (1 - t)``; a failure towards 0: ``t -= failure_loss * t``
  (failures weigh more than successes, the usual negativity bias); a help request moves it by ``help_gain`` in the
  same way (positive: a robot that knows its limits is judged capable).
- When the robot starts an action, the participant takes over with probability
  ``max_takeover * sigmoid((intervention_threshold - t) / intervention_slope)``: rarely when trust is high, often
  when it is low.
- Between the two sessions, trust relaxes half-way back to the participant's disposition (``carry_over``).
- Questionnaires are answered from the latent trust on the logit scale,
  ``tau = logit(t) + condition_effect * [self-confidence on] + session_effect * [session 2] + e``,
  ``e ~ Normal(0, response_noise_sd)`` once per session; item ``q`` with K categories is answered by the ordered
  logit ``P(y <= k) = sigmoid(c_k - (tau + d_q))`` with evenly spaced cut-points ``c`` and fixed item offsets
  ``d_q``; reverse-scored items are answered on the flipped scale. This is the generative form of the paper's
  Eq. (3), so with the dynamics switched off (gains 0) the analysis must recover ``condition_effect`` exactly.

With ``transfer`` set (the fitted model, scone_bt.trust.transfer; the default of `scone-study simulate` and
`power`), trust is per action and moves across actions through ζ: the person's trust that the robot can do action ``a`` is
``sigmoid(prior(a) + u_p + Σ_o w_o k(a, o) g_o)`` over what they saw (``g_o`` = the fitted success gain or failure
loss, ``help_logit`` for a help request; ``w_o`` = 1, times ``carry_over`` for session-1 events in session 2), with
``u_p ~ Normal(0, disposition_sd)``. Take-overs use the trust in the action the robot starts; questionnaires the
trust in a generic fetch (GENERIC_ACTION), which every outcome moves by its similarity. Fitted to human ratings:
prior, gains, kernel, disposition sd. Assumed (no data): help_logit, the take-over curve, carry_over, and the
answer model.
"""

from __future__ import annotations

import functools
import math
from dataclasses import asdict, dataclass, field, replace
from typing import Any

import numpy as np

from scone_bt.affordances.types import action_text
from scone_bt.errors import SconeError, UnknownNameError
from scone_bt.events import ActOutcome, ActStarted, ConfidenceStated, Event, HelpRequested
from scone_bt.human import SimulatedHuman
from scone_bt.study.design import Condition, Group
from scone_bt.study.questionnaires import Questionnaire
from scone_bt.trust.transfer import TransferModel, TransferParameters, load_fitted

__all__ = [
    "GENERIC_ACTION",
    "TRUST_PARAMETER_SETS",
    "TrustParameters",
    "SimulatedParticipant",
    "TrustfulHuman",
    "item_offsets",
    "trust_parameters",
]

GENERIC_ACTION = "Put the object on table"
"""The action whose trust a participant's questionnaire answers come from under the transfer model."""
TRUST_PARAMETER_SETS: tuple[str, ...] = ("fitted", "hand")


def _sigmoid(x: float) -> float:
    return 1.0 / (1.0 + math.exp(-x))


def _logit(p: float) -> float:
    p = min(max(p, 1e-6), 1 - 1e-6)
    return math.log(p / (1 - p))


@dataclass(frozen=True)
class TrustParameters:
    """The simulated participants' trust model. Trust is a probability; effects marked (logit) are on the logit scale.

    Attributes:
        initial_mean: Mean initial trust (logit); 0.4 is t ≈ 0.6.
        initial_sd: Between-participant sd of initial trust (logit).
        success_gain: Fraction of the way to full trust gained per observed success.
        failure_loss: Fraction of trust lost per observed failure.
        help_gain: Fraction of the way to full trust per help request (negative: help requests cost trust).
        intervention_threshold: Trust below which take-overs become likely.
        intervention_slope: Width of the take-over curve (trust units).
        max_takeover: Take-over probability at very low trust.
        carry_over: Share of the session-1 trust change kept at the start of session 2.
        condition_effect: Shift of the answers (logit) when self-confidence is on; a known effect for recovery checks.
        session_effect: Shift of the answers (logit) in session 2.
        response_noise_sd: Per-session noise of the answers (logit).
        item_sd: Spread of the fixed item offsets (logit).
        transfer: The fitted per-action model (scone_bt.trust.transfer); None: the single hand-set trust above.
        help_logit: With `transfer`: logit change per help request on the same action, transferred like an
            outcome. Assumed (no data): the hand-set help_gain's effect at trust 0.5.
        warning_weight: With `transfer`: share of the logit gap between the person's trust in an action and the κ̂
            the robot states (`ConfidenceStated`, trust_aware) that the statement closes, transferred like an
            outcome. Assumed (no data on how people take a spoken warning).
    """

    initial_mean: float = 0.4
    initial_sd: float = 0.6
    success_gain: float = 0.08
    failure_loss: float = 0.15
    help_gain: float = 0.03
    intervention_threshold: float = 0.4
    intervention_slope: float = 0.06
    max_takeover: float = 0.6
    carry_over: float = 0.5
    condition_effect: float = 0.0
    session_effect: float = 0.0
    response_noise_sd: float = 0.3
    item_sd: float = 0.3
    transfer: TransferParameters | None = None
    help_logit: float = 0.06
    warning_weight: float = 0.5

    def __post_init__(self) -> None:
        for name in ("success_gain", "failure_loss", "max_takeover", "carry_over"):
            v = getattr(self, name)
            if not 0.0 <= v <= 1.0:
                raise SconeError(f"trust parameter {name} must be in [0, 1], got {v}")
        if not -1.0 <= self.help_gain <= 1.0:
            raise SconeError(f"trust parameter help_gain must be in [-1, 1], got {self.help_gain}")
        if self.intervention_slope <= 0 or min(self.initial_sd, self.response_noise_sd, self.item_sd) < 0:
            raise SconeError("trust parameters: intervention_slope must be positive and the sds non-negative")

    @property
    def dynamic(self) -> bool:
        """False when trust ignores what the robot does (the setting for effect-recovery checks)."""
        if self.transfer is not None:
            t = self.transfer
            return bool(t.success_gain or t.failure_loss or self.help_logit or self.warning_weight)
        return bool(self.success_gain or self.failure_loss or self.help_gain)

    def static(self, **overrides: float) -> TrustParameters:
        """The same participants with trust that ignores the episodes (every gain 0)."""
        transfer = self.transfer and replace(self.transfer, success_gain=0.0, failure_loss=0.0)
        return replace(
            self,
            success_gain=0.0,
            failure_loss=0.0,
            help_gain=0.0,
            help_logit=0.0,
            warning_weight=0.0,
            transfer=transfer,
            **overrides,
        )

    def describe(self) -> dict:
        """JSON-ready parameters (stored with every simulated session)."""
        return asdict(self)

    @property
    def label(self) -> str:
        """One line for output: where the parameters come from."""
        if self.transfer is None:
            return "hand-set trust parameters (docs/study.md)"
        return (
            f"trust fitted to human ratings ({self.transfer.source}; transfer across actions through "
            f"{self.transfer.embedder}); help requests, take-overs, carry-over: hand-set (assumed)"
        )


def trust_parameters(name: str, **overrides: float) -> TrustParameters:
    """A named parameter set: "fitted" (the committed fit, scone_bt/trust/fitted.json) or "hand" (the dataclass
    defaults)."""
    if name not in TRUST_PARAMETER_SETS:
        raise UnknownNameError("trust parameters", name, TRUST_PARAMETER_SETS)
    if name == "hand":
        return TrustParameters(**dict[str, Any](overrides))
    return TrustParameters(**dict[str, Any](transfer=load_fitted(), **overrides))


@functools.lru_cache(maxsize=2)
def _transfer_model(params: TransferParameters) -> TransferModel:
    """One model per process (it loads ζ once)."""
    return TransferModel(params)


def item_offsets(questionnaire: Questionnaire, sd: float, seed: int = 1234) -> dict[str, float]:
    """Fixed per-item offsets d_q (logit), the same for every participant (items differ in how easy they are to endorse)."""
    rng = np.random.default_rng([seed, sum(map(ord, questionnaire.name))])
    return {
        it.key: float(v)
        for it, v in zip(questionnaire.items, rng.normal(0.0, sd, len(questionnaire.items)), strict=True)
    }


def _cutpoints(k: int) -> np.ndarray:
    """Evenly spaced cut-points for K categories, spread so that all categories get used."""
    return np.linspace(-3.0, 3.0, k - 1) * (1.0 if k <= 8 else 1.15)


@dataclass
class SimulatedParticipant:
    """One simulated participant across both sessions.

    Attributes:
        participant: Participant id.
        group: Condition order.
        params: The trust model.
        seed: Seeds disposition, take-overs, answers.
    """

    participant: str
    group: Group
    params: TrustParameters = field(default_factory=TrustParameters)
    seed: int = 0

    def __post_init__(self) -> None:
        self.rng = np.random.default_rng(self.seed)
        transfer = self.params.transfer
        # The transfer model's disposition is an offset to each action's prior; the hand-set one is the trust.
        if transfer is not None:
            self.disposition = float(self.rng.normal(0.0, transfer.disposition_sd))
        else:
            self.disposition = self.params.initial_mean + float(self.rng.normal(0.0, self.params.initial_sd))
        self._seen: list[tuple[str, float, float]] = []  # (action, logit effect at k = 1, weight)
        self._current: str | None = None
        self.trust = self._general() if transfer is not None else _sigmoid(self.disposition)
        self.history: list[tuple[str, float]] = [("start", self.trust)]

    # ----------------------------------------------------------------------------------------- per action
    def trust_in(self, action: str) -> float:
        """Trust that the robot can do `action` (the hand-set model has one trust for every action)."""
        if self.params.transfer is None:
            return self.trust
        model = _transfer_model(self.params.transfer)
        logit = float(model.prior_logit([action])[0]) + self.disposition
        if self._seen:
            k = model.kernel([action], [a for a, _, _ in self._seen])[0]
            logit += float(np.sum(k * np.array([g * w for _, g, w in self._seen])))
        return _sigmoid(logit)

    def _general(self) -> float:
        return self.trust_in(GENERIC_ACTION)

    def consider(self, action: str) -> None:
        """The robot is about to start `action`: take-overs are decided on the trust in it."""
        self._current = action

    # ----------------------------------------------------------------------------------------- dynamics
    def start_session(self, session_index: int) -> None:
        """Session 2 starts with part of the session-1 change kept (carry_over)."""
        if session_index > 1 and self.params.transfer is not None:
            self._seen = [(a, g, w * self.params.carry_over) for a, g, w in self._seen]
            self.trust = self._general()
            self.history.append(("session", self.trust))
        elif session_index > 1:
            base = _sigmoid(self.disposition)
            self.trust = base + self.params.carry_over * (self.trust - base)
            self.history.append(("session", self.trust))

    def observe(self, event: Event) -> None:
        """React to one episode event (the on_event stream): outcomes and help requests move trust."""
        p = self.params
        if p.transfer is not None:
            self._observe_transfer(event)
            return
        if isinstance(event, ActOutcome):
            if event.success:
                self.trust += p.success_gain * (1.0 - self.trust)
            else:
                self.trust -= p.failure_loss * self.trust
        elif isinstance(event, HelpRequested):
            g = p.help_gain
            self.trust += g * (1.0 - self.trust) if g >= 0 else g * self.trust
        else:
            return
        self.trust = min(max(self.trust, 1e-4), 1 - 1e-4)
        self.history.append((event.kind, self.trust))

    def _observe_transfer(self, event: Event) -> None:
        t = self.params.transfer
        assert t is not None
        if isinstance(event, ActStarted):
            self._current = event.action
            return
        if isinstance(event, ActOutcome):
            self._seen.append((event.action, t.success_gain if event.success else -t.failure_loss, 1.0))
        elif isinstance(event, HelpRequested):
            self._seen.append((event.action, self.params.help_logit, 1.0))
        elif isinstance(event, ConfidenceStated):
            gap = _logit(event.confidence) - _logit(self.trust_in(event.action))
            self._seen.append((event.action, self.params.warning_weight * gap, 1.0))
        else:
            return
        self.trust = self._general()
        self.history.append((event.kind, self.trust))

    def takeover_probability(self) -> float:
        p = self.params
        trust = self.trust_in(self._current) if self._current is not None else self.trust
        return p.max_takeover * _sigmoid((p.intervention_threshold - trust) / p.intervention_slope)

    def decides_to_take_over(self) -> bool:
        """One seeded draw when the robot starts an action."""
        return bool(self.rng.random() < self.takeover_probability())

    # ----------------------------------------------------------------------------------------- answers
    def latent(self, condition: Condition, session_index: int) -> float:
        """Latent trust on the logit scale at questionnaire time, noise included (one draw per call)."""
        p = self.params
        tau = _logit(self.trust) + (p.condition_effect if condition is Condition.ON else 0.0)
        tau += p.session_effect if session_index == 2 else 0.0
        return tau + float(self.rng.normal(0.0, p.response_noise_sd))

    def answer(
        self, questionnaire: Questionnaire, condition: Condition, session_index: int
    ) -> dict[str, float]:
        """Answers to every item, drawn from the ordered-logit response model."""
        tau = self.latent(condition, session_index)
        offsets = item_offsets(questionnaire, self.params.item_sd)
        cuts = _cutpoints(questionnaire.n_categories)
        answers: dict[str, float] = {}
        for it in questionnaire.items:
            eta = tau + offsets[it.key]
            cdf = np.append(1.0 / (1.0 + np.exp(-(cuts - eta))), 1.0)
            probs = np.diff(np.concatenate([[0.0], cdf]))
            cat = int(self.rng.choice(len(probs), p=probs / probs.sum()))
            if it.reverse:
                cat = questionnaire.n_categories - 1 - cat
            answers[it.key] = questionnaire.values[cat]
        return answers


@dataclass
class TrustfulHuman(SimulatedHuman):
    """A SimulatedHuman whose take-overs come from a SimulatedParticipant's trust (for physics episodes).

    Feed the episode's events to ``participant.observe`` (simulate.py chains it into on_event).
    """

    participant: SimulatedParticipant | None = None

    def decide_takeover(self, object_name: str) -> None:
        self._takeover_at = None
        if self.participant is not None:
            self.participant.consider(action_text(object_name))
        if self.participant is not None and self.participant.decides_to_take_over():
            self._takeover_at = (object_name, self.kitchen.sim_time + self.options.takeover_delay_s)
