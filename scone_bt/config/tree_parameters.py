"""The `parameters:` section of a tree file: the one place the robot's decision defaults live.

`scone-run`, `run_episode` and every script read them from the tree file; a key the file leaves out takes the
default below (the shipped trees/assistive_cooking.yaml states every one of them). `BehaviourOptions` fields left
at None are filled from here (`BehaviourOptions.resolve`).
"""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import Field

from scone_bt.config.schema import StrictModel

__all__ = ["ProbeParameters", "TreeParameters", "PARAMETER_NAMES"]


class ProbeParameters(StrictModel):
    """The heft test (scone_bt/gate/probe.py, scone_bt/motion/probe.py): when the budget gate probes, and how."""

    enabled: bool = True
    below: Annotated[float, Field(ge=0, le=1, allow_inf_nan=False)] = 1.0
    above: Annotated[float, Field(ge=0, le=1, allow_inf_nan=False)] = 0.45
    lift_m: Annotated[float, Field(ge=0.005, le=0.05, allow_inf_nan=False)] = 0.015
    hold_s: Annotated[float, Field(ge=0.1, le=3, allow_inf_nan=False)] = 0.5


class TreeParameters(StrictModel):
    """Validated tree parameters (see trees/assistive_cooking.yaml for what each means)."""

    embedder: Annotated[str, Field(min_length=1)] = "minilm"
    estimator: Annotated[str, Field(min_length=1)] = "physical"
    confidence_threshold: Annotated[float, Field(ge=0, le=1, allow_inf_nan=False)] = 0.5
    relevance_threshold: Annotated[float, Field(ge=-1, le=1, allow_inf_nan=False)] = 0.33
    recipe_aware: bool = True
    clarify_margin: Annotated[float, Field(ge=0, le=1, allow_inf_nan=False)] = 0.03
    max_failures_per_action: Annotated[int, Field(ge=1, le=1000)] = 3
    gate: Literal["budget", "paper"] = "budget"
    target_failure_rate: Annotated[float, Field(gt=0, lt=1, allow_inf_nan=False)] = 0.15
    probe: ProbeParameters = ProbeParameters()


PARAMETER_NAMES: tuple[str, ...] = tuple(TreeParameters.model_fields)
