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
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from scone_bt.errors import SconeError
from scone_bt.events import ActOutcome, Event, HelpRequested
from scone_bt.human import SimulatedHuman
from scone_bt.study.design import Condition, Group
from scone_bt.study.questionnaires import Questionnaire

__all__ = ["TrustParameters", "SimulatedParticipant", "TrustfulHuman", "item_offsets"]


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
        return bool(self.success_gain or self.failure_loss or self.help_gain)


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
        self.disposition = self.params.initial_mean + float(self.rng.normal(0.0, self.params.initial_sd))
        self.trust = _sigmoid(self.disposition)
        self.history: list[tuple[str, float]] = [("start", self.trust)]

    # ----------------------------------------------------------------------------------------- dynamics
    def start_session(self, session_index: int) -> None:
        """Session 2 starts with part of the session-1 change kept (carry_over)."""
        if session_index > 1:
            base = _sigmoid(self.disposition)
            self.trust = base + self.params.carry_over * (self.trust - base)
            self.history.append(("session", self.trust))

    def observe(self, event: Event) -> None:
        """React to one episode event (the on_event stream): outcomes and help requests move trust."""
        p = self.params
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

    def takeover_probability(self) -> float:
        p = self.params
        return p.max_takeover * _sigmoid((p.intervention_threshold - self.trust) / p.intervention_slope)

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
        if self.participant is not None and self.participant.decides_to_take_over():
            self._takeover_at = (object_name, self.kitchen.sim_time + self.options.takeover_delay_s)
