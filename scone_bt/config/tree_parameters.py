"""The `parameters:` section of a tree file: the one place the robot's decision defaults live.

`scone-run`, `run_episode` and every script read them from the tree file; a key the file leaves out takes the
default below (the shipped trees/assistive_cooking.yaml states every one of them). `BehaviourOptions` fields left
at None are filled from here (`BehaviourOptions.resolve`).
"""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType
from typing import Annotated, Literal

from pydantic import Field

from scone_bt.config.ranges import Range
from scone_bt.config.schema import StrictModel

__all__ = [
    "ProbeParameters",
    "TreeParameters",
    "PARAMETER_NAMES",
    "GateName",
    "PROBE_RANGES",
    "TREE_DEFAULTS",
]


GateName = Literal["budget", "paper"]
"""The gate rules a tree can run: the failure budget (scone_bt/gate/budget.py), or the paper's fixed threshold
(scone_bt/gate/gate.py)."""


class ProbeParameters(StrictModel):
    """The heft test (scone_bt/gate/probe.py, scone_bt/motion/probe.py): when the budget gate probes, and how.

    A nested section of the tree file (``probe:``); `scone-run` has one option per field, ``--probe-<name>``
    (`scone_bt.cli.tree_options`), and a field given there overrides only that key of the tree file's section.
    """

    enabled: Annotated[
        bool, Field(description="heft what κ̂ is unsure of before carrying it (the budget gate only)")
    ] = True
    below: Annotated[
        float,
        Field(
            ge=0,
            le=1,
            allow_inf_nan=False,
            description="probe actions whose κ̂ is down to this far below the budget's threshold τ",
        ),
    ] = 1.0
    above: Annotated[
        float,
        Field(
            ge=0,
            le=1,
            allow_inf_nan=False,
            description="probe actions whose κ̂ is up to this far above τ (0: only what would be asked)",
        ),
    ] = 0.45
    full_band_at: Annotated[
        float,
        Field(
            ge=0,
            lt=1,
            allow_inf_nan=False,
            description="under this target_failure_rate the band below τ narrows as below × (α / this)⁴, so a "
            "strict promise probes only what κ̂ is nearly sure of (0: never narrows)",
        ),
    ] = 0.15
    lift_m: Annotated[
        float,
        Field(
            ge=0.005, le=0.05, allow_inf_nan=False, description="how far the probe lifts the product, metres"
        ),
    ] = 0.015
    hold_s: Annotated[
        float,
        Field(
            ge=0.1,
            le=3,
            allow_inf_nan=False,
            description="how long the probe holds it up while the fingers feel its load, simulated seconds",
        ),
    ] = 0.5


class TreeParameters(StrictModel):
    """Validated tree parameters: the one declaration of the robot's decision settings.

    `scone-run`'s options (`scone_bt.cli.tree_options`) and `BehaviourOptions`' fields are derived from these
    fields; each description is the option's help text (trees/assistive_cooking.yaml says more about each).
    """

    embedder: Annotated[
        str,
        Field(
            min_length=1,
            description="ζ: minilm, mpnet, mpnet-ft, glove, onehot, finetuned:<dir> or a model directory",
        ),
    ] = "minilm"
    estimator: Annotated[
        str,
        Field(
            min_length=1,
            description="κ̂ estimator: knn, lgbm, rf, svm, mlp, xgb, gp, conformal, each also as eps-<name>, "
            "grounded-<name> (not conformal) and <name>-cal, or physical",
        ),
    ] = "physical"
    confidence_threshold: Annotated[
        float,
        Field(ge=0, le=1, allow_inf_nan=False, description="with gate paper: act when κ̂ ≥ this, else ask"),
    ] = 0.5
    relevance_threshold: Annotated[
        float,
        Field(
            ge=-1, le=1, allow_inf_nan=False, description="ρ: minimum cosine similarity of a relevant action"
        ),
    ] = 0.33
    recipe_aware: Annotated[
        bool,
        Field(
            description="rank against the recipe the robot knows and track its step from what it sees; off: the "
            "paper's setting (the human's current step text alone, with ρ)"
        ),
    ] = True
    clarify_margin: Annotated[
        float,
        Field(
            ge=0,
            le=1,
            allow_inf_nan=False,
            description="unnamed candidates closer than this in cosine similarity are ambiguous: ask which is meant",
        ),
    ] = 0.03
    max_failures_per_action: Annotated[
        int,
        Field(
            ge=1,
            le=1000,
            description="after this many failures of one action in an episode, ask (the control condition: the paper's 3)",
        ),
    ] = 1
    gate: Annotated[
        GateName,
        Field(
            description="budget: keep the share of failed attempts at or under target_failure_rate, online; "
            "paper: the fixed confidence_threshold"
        ),
    ] = "budget"
    target_failure_rate: Annotated[
        float,
        Field(
            gt=0,
            lt=1,
            allow_inf_nan=False,
            description="the promise of the budget gate: the share of attempts that may fail, kept over the long "
            "run, in (0, 1)",
        ),
    ] = 0.15
    trust_aware: Annotated[
        bool,
        Field(
            description="say the robot's confidence in words before an act the person likely over-trusts "
            "(the person's trust estimated online from what they saw)"
        ),
    ] = False
    takeover_window_s: Annotated[
        float,
        Field(
            ge=0,
            le=60,
            allow_inf_nan=False,
            description="simulated seconds the robot announces an attempt before it moves, so that a person on the "
            "tablet can take over (simulated humans get no window)",
        ),
    ] = 2.0
    exploration_credit: Annotated[
        bool,
        Field(
            description="the strict promise: explore (attempt below the threshold) only while one more failure "
            "keeps failures ≤ target_failure_rate × attempts + 1; off: explore while still learning "
            "(the budget gate only)"
        ),
    ] = True
    probe: Annotated[
        ProbeParameters,
        Field(description="the heft test: when the budget gate lifts a product a little to feel it first"),
    ] = ProbeParameters()


PARAMETER_NAMES: tuple[str, ...] = tuple(TreeParameters.model_fields)

TREE_DEFAULTS = TreeParameters()
"""Every tree parameter's default: the robot's decision settings when a tree file and the command line say
nothing. The gate's and the motion's own option objects (gate.budget.BudgetOptions, gate.probe.ProbeOptions,
motion.probe.ProbeSettings) take their defaults from here."""

PROBE_RANGES: Mapping[str, Range] = MappingProxyType(
    {
        "below": Range.of_field(ProbeParameters, "below"),
        "above": Range.of_field(ProbeParameters, "above"),
        "full_band_at": Range.of_field(ProbeParameters, "full_band_at"),
        "lift_m": Range.of_field(ProbeParameters, "lift_m", "metres"),
        "hold_s": Range.of_field(ProbeParameters, "hold_s", "seconds"),
        # the set-back judge's limits: not tree parameters, but both the gate's and the motion's options take them
        "max_unsteady": Range(0.0, 1.0, low_open=True),
        "max_traction": Range(0.0, 10.0, low_open=True),
    }
)
"""The heft test's intervals, declared once: the tree file's fields, and the judge's limits that
gate.probe.ProbeOptions and motion.probe.ProbeSettings share (both check their values with these)."""
