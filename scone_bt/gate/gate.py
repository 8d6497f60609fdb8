"""The gate: act on the best relevant action, ask the human for help with it, or ask which item is meant.

`decide` is a pure function of the ranked actions, their κ̂ confidences, the ambiguous candidates and the options:

0. Recipe-aware ranking (`recipe_aware`; actions carry a ``need``, "" for those no step wants): the candidate is the most relevant "now" action; with none,
   ``ambiguous`` candidates → CLARIFY (ask which one the step means); else the most relevant "later" action;
   else IDLE. The relevance threshold is not applied: the ranking already decided.
1. Otherwise (the step's text alone, the paper's setting): no action, or the best one's relevance is below
   `relevance_threshold` → IDLE (the instruction is not something the robot can help with, or it is done).
2. `use_self_confidence=False` (the paper's control condition) → ACT on the best relevant action, always.
3. Otherwise ACT if its confidence ≥ the threshold, else ASK. The threshold is `confidence_threshold`, or
   `1 - target_error_rate` when a target error rate is given; with the conformal estimator (whose confidence is
   1 − the conformal p-value of failure) that bounds the fraction of would-fail actions attempted by that rate.
4. Exploration (ε-greedy κ̂, `explore` set for the chosen action): ACT instead of ASK, marked ``explored``; the
   decision's confidence stays κ̂'s belief, so what is shown and logged is never the exploration draw.

Only the single most relevant action is considered (as in the paper); ties in relevance go to the earlier one.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

from scone_bt.errors import SconeError
from scone_bt.gate.types import Decision, DecisionKind
from scone_bt.relevance.types import RankedAction

__all__ = ["GateOptions", "decide"]


@dataclass(frozen=True)
class GateOptions:
    """How the gate decides.

    Attributes:
        confidence_threshold: Act when κ̂ ≥ this success probability, in [0, 1].
        relevance_threshold: Cosine similarity an action needs to count as relevant, in [-1, 1]
            (use RelevanceFilter.threshold learnt from labelled data).
        use_self_confidence: False is the paper's control: always act on the best relevant action.
        target_error_rate: If set, in (0, 1), replaces confidence_threshold by 1 − target_error_rate; meant for
            the conformal estimator, where it is the tolerated fraction of would-fail actions attempted.
        recipe_aware: The ranking knows the recipe (rule 0); False is the paper's step-text-only gate (rule 1).

    These defaults are the bare rule's, the paper's step-text-only gate; the robot's come from its tree file
    (config.tree_parameters: a relevance threshold of 0.33 and a recipe-aware ranking).
    """

    confidence_threshold: float = 0.5
    relevance_threshold: float = 0.0
    use_self_confidence: bool = True
    target_error_rate: float | None = None
    recipe_aware: bool = False

    def __post_init__(self) -> None:
        if not 0.0 <= self.confidence_threshold <= 1.0:
            raise SconeError(f"confidence_threshold must be in [0, 1], got {self.confidence_threshold}")
        if not -1.0 <= self.relevance_threshold <= 1.0:
            raise SconeError(f"relevance_threshold must be in [-1, 1], got {self.relevance_threshold}")
        if self.target_error_rate is not None and not 0.0 < self.target_error_rate < 1.0:
            raise SconeError(f"target_error_rate must be in (0, 1) or None, got {self.target_error_rate}")

    @property
    def act_threshold(self) -> float:
        """The confidence an action needs for ACT."""
        if self.target_error_rate is not None:
            return 1.0 - self.target_error_rate
        return self.confidence_threshold


def _told_apart(confidence: float, threshold: float) -> tuple[str, str]:
    """Both numbers with two decimals, or with as many more (up to six) as it takes for them to differ: a reason
    must never read "confidence 0.93 < 0.93"."""
    for digits in range(2, 7):
        a, b = f"{confidence:.{digits}f}", f"{threshold:.{digits}f}"
        if a != b:
            return a, b
    return f"{confidence:.2f}", f"{threshold:.2f}"  # equal to six decimals: the threshold itself acts


def decide(
    ranked: Sequence[RankedAction],
    confidences: Sequence[float],
    options: GateOptions,
    ambiguous: Sequence[str] = (),
    explore: Sequence[bool] = (),
) -> Decision:
    """Act on the most relevant action, ask for help with it, ask which item is meant, or idle; see the module
    docstring.

    Its named steps, in order: `_check_aligned`, `_candidates` (rule 0), `_nothing_to_fetch`, the most relevant
    candidate and `_probability`, `_irrelevant` (rule 1), then `_act_or_ask` (rules 2 to 4).

    Args:
        ranked: Candidate actions with their relevance (any order; usually rank_actions' best-first list).
        confidences: κ̂ success probability of each, aligned with `ranked`.
        options: Thresholds and mode.
        ambiguous: Action texts the step could mean about equally (recipe-aware ranking); asked about when
            no action is needed now or later.
        explore: Per action, aligned with `ranked`: the ε-greedy estimator's exploration draw (rule 4); empty for
            estimators that do not explore.

    Raises:
        SconeError: lengths differ, or a confidence is not a number in [0, 1].
    """
    _check_aligned(ranked, confidences, explore)
    pool = _candidates(ranked, options.recipe_aware, ambiguous)
    if not pool:
        return _nothing_to_fetch(ambiguous)
    best = max(pool, key=lambda i: (ranked[i].relevance, -i))
    action = ranked[best]
    conf = _probability(action, confidences[best])
    if not options.recipe_aware and action.relevance < options.relevance_threshold:
        return _irrelevant(action, conf, options.relevance_threshold)
    # the flag is read only below the threshold: reading it may draw a random number (a lazy ε-greedy draw)
    return _act_or_ask(action, conf, options, lambda: bool(explore and explore[best]))


def _check_aligned(
    ranked: Sequence[RankedAction], confidences: Sequence[float], explore: Sequence[bool]
) -> None:
    """One confidence per action, and one exploration flag per action where there are any."""
    if len(ranked) != len(confidences):
        raise SconeError(
            f"{len(ranked)} ranked actions but {len(confidences)} confidences; pass one per action"
        )
    if explore and len(explore) != len(ranked):
        raise SconeError(
            f"{len(ranked)} ranked actions but {len(explore)} exploration flags; pass one per action"
        )


def _candidates(ranked: Sequence[RankedAction], recipe_aware: bool, ambiguous: Sequence[str]) -> list[int]:
    """Indices of the actions the gate may pick from: every action, or with recipe-aware ranking (rule 0) those
    needed now, else (the step being clear) those needed later."""
    if not recipe_aware:
        return list(range(len(ranked)))
    now = [i for i, r in enumerate(ranked) if r.need == "now"]
    # an ambiguous step still needs something: ask which before fetching for steps ahead
    return now or ([] if ambiguous else [i for i, r in enumerate(ranked) if r.need == "later"])


def _nothing_to_fetch(ambiguous: Sequence[str]) -> Decision:
    """No candidate: ask which item an ambiguous step means (CLARIFY), else IDLE."""
    if ambiguous:
        return Decision(
            DecisionKind.CLARIFY,
            None,
            float("nan"),
            float("nan"),
            "which one does the step mean: " + ", ".join(ambiguous),
            candidates=tuple(ambiguous),
        )
    return Decision(DecisionKind.IDLE, None, float("nan"), float("nan"), "no actions are available")


def _probability(action: RankedAction, confidence: float) -> float:
    """κ̂'s confidence in `action` as a float, refused unless it is a probability."""
    conf = float(confidence)
    if not (0.0 <= conf <= 1.0) or math.isnan(conf):
        raise SconeError(f"confidence of {action.text!r} is {conf}; κ̂ must give a probability in [0, 1]")
    return conf


def _irrelevant(action: RankedAction, conf: float, relevance_threshold: float) -> Decision:
    """IDLE: even the most relevant action is below the relevance threshold (rule 1)."""
    return Decision(
        DecisionKind.IDLE,
        None,
        action.relevance,
        conf,
        f"no action is relevant (best {action.text!r} {action.relevance:.2f} < {relevance_threshold:.2f})",
    )


def _act_or_ask(
    action: RankedAction, conf: float, options: GateOptions, explored: Callable[[], bool]
) -> Decision:
    """ACT without self-confidence (rule 2) or when κ̂ reaches the threshold (rule 3); below it, ACT on an
    exploration draw (rule 4, `explored` read only here), else ASK."""
    need = action.need
    if not options.use_self_confidence:
        return Decision(
            DecisionKind.ACT,
            action.text,
            action.relevance,
            conf,
            "acting: self-confidence is off",
            need,
            rule="self-confidence-off",
        )
    threshold = options.act_threshold
    if conf >= threshold:
        return Decision(
            DecisionKind.ACT,
            action.text,
            action.relevance,
            conf,
            "confident: {} ≥ {}".format(*_told_apart(conf, threshold)),
            need,
        )
    if explored():
        return Decision(
            DecisionKind.ACT,
            action.text,
            action.relevance,
            conf,
            "exploring (ε-greedy): confidence {} < {}, trying to learn".format(*_told_apart(conf, threshold)),
            need,
            explored=True,
        )
    return Decision(
        DecisionKind.ASK,
        action.text,
        action.relevance,
        conf,
        "asking for help: confidence {} < {}".format(*_told_apart(conf, threshold)),
        need,
    )
