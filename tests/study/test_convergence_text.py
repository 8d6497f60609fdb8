"""The analysis report's convergence line: R-hat is undefined with one chain and says so."""

from __future__ import annotations

import math

import numpy as np

from scone_bt.study.analysis import ModelFit, convergence_text


def _fit(r_hat: float, divergences: int = 0) -> ModelFit:
    return ModelFit("trust", 100, {"condition": np.zeros(4)}, r_hat, 812.0, divergences, 3.0)


def test_one_chain_says_r_hat_needs_two_chains_not_nan() -> None:
    text = convergence_text(_fit(math.nan))
    assert text.startswith("R-hat: needs ≥ 2 chains  ESS min 812")
    assert "nan" not in text and "check convergence" not in text
    assert convergence_text(_fit(math.nan, divergences=2)).endswith("<- check convergence")


def test_several_chains_report_r_hat_and_flag_a_high_one() -> None:
    assert convergence_text(_fit(1.002)).startswith("R-hat max 1.002  ESS min 812  divergences 0")
    assert convergence_text(_fit(1.2)).endswith("<- check convergence")
