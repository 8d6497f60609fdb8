"""Study planning: seeded work items, counts drawn from Eq. (4), simulated questionnaire answers on their scale,
the same result on 1 and 2 worker processes."""

from __future__ import annotations

import json

import numpy as np
import pytest

from scone_bt.errors import SconeError, UnknownNameError
from scone_bt.study.analysis import decide
from scone_bt.study.cli import main
from scone_bt.study.power import (
    PowerOptions,
    _simulate_answers,
    run_one,
    run_power,
    simulate_counts,
    work_items,
    write_power,
)
from scone_bt.study.questionnaires import get_questionnaire


def test_options_are_checked_before_any_work():
    with pytest.raises(SconeError, match="participant numbers must be 2 to 1000"):
        PowerOptions(participants=(1, 10))
    with pytest.raises(SconeError, match="participant numbers must be 2 to 1000"):
        PowerOptions(participants=(10, 100_000_000))  # ran on with no progress
    for effect in (25.0, -11.0, float("nan")):  # 25 overflowed the simulated counts
        with pytest.raises(SconeError, match=r"--effect must be in \[-10, 10\]"):
            PowerOptions(effect=effect, measure="interventions")
    with pytest.raises(UnknownNameError, match="valid: interventions, mdmt, tps_hri"):
        PowerOptions(measure="sus")
    with pytest.raises(SconeError, match="not a comma list of whole numbers"):
        PowerOptions.from_text("10,x")
    with pytest.raises(SconeError, match="ROPE must be"):
        PowerOptions(rope=(0.2, -0.2))
    with pytest.raises(SconeError, match="--answer-noise-sd must be 0 or more"):
        PowerOptions(response_noise_sd=-0.1)
    assert PowerOptions().response_noise_sd == 0.0  # answers from Eq. (3), the model that is fitted
    assert PowerOptions.from_text("31, 10,10").participants == (10, 31)


def test_work_items_have_their_own_seeds_whatever_the_order():
    a = work_items(PowerOptions(participants=(10, 20), repetitions=3, seed=4))
    b = work_items(PowerOptions(participants=(20, 10), repetitions=3, seed=4))
    assert sorted(a, key=lambda w: (w.participants, w.repetition)) == sorted(
        b, key=lambda w: (w.participants, w.repetition)
    )
    assert len({w.study_seed for w in a}) == 6 and len({w.sampler_seed for w in a}) == 6
    assert work_items(PowerOptions(participants=(10,), repetitions=1, seed=5))[0] != a[0]


def test_counts_follow_eq4():
    data = simulate_counts(400, effect=1.0, seed=3, participant_sd=0.0)
    s = data.sessions
    assert data.simulated and len(s) == 800 and set(s["group"]) == {"A", "B"}
    on, off = s[s["condition"] == "on"]["interventions"], s[s["condition"] == "off"]["interventions"]
    assert np.log(on.mean() / off.mean()) == pytest.approx(1.0, abs=0.12)
    assert off.mean() == pytest.approx(1.5, rel=0.15)
    assert simulate_counts(6, 1.0, seed=3).sessions.equals(simulate_counts(6, 1.0, seed=3).sessions)


@pytest.mark.slow
def test_power_is_the_same_on_one_and_two_workers_and_is_written(tmp_path, capsys):
    options = dict(
        participants=(6, 12), repetitions=1, effect=1.0, measure="interventions", chains=1, tune=60, draws=60
    )
    one = run_power(PowerOptions(workers=1, **options))
    two = run_power(PowerOptions(workers=2, **options))

    def strip(runs):  # noqa: ANN001, ANN202 - JSON text: R-hat of one chain is NaN, and NaN != NaN
        return json.dumps([{k: v for k, v in r.items() if k != "seconds"} for r in runs])

    assert strip(one.runs) == strip(two.runs)
    assert [p.participants for p in one.points] == [6, 12]
    assert all(0.0 <= p.power <= 1.0 and p.power_ci[0] <= p.power <= p.power_ci[1] for p in one.points)
    paths = write_power(one, tmp_path / "power")
    assert paths["plot"].stat().st_size > 10_000
    assert json.loads(paths["json"].read_text())["data"] == "SIMULATED"
    with pytest.raises(SconeError, match="already holds power.json, power.png"):
        write_power(one, tmp_path / "power")
    assert main(["power", "--n", "6,x", "--out", str(tmp_path / "p2")]) == 2
    assert "not a comma list" in capsys.readouterr().err


def test_questionnaire_power_run_answers_on_the_scale_and_seeded(tmp_path):
    # A large stated effect on 4 participants, one short chain: quick, and the direction cannot be missed.
    options = PowerOptions(
        participants=(4,), repetitions=1, effect=3.0, measure="mdmt", chains=1, tune=60, draws=60
    )
    item = work_items(options)[0]
    answers = _simulate_answers(options, item, tmp_path).ratings
    mdmt = answers[answers["questionnaire"] == "mdmt"]
    k = get_questionnaire("mdmt").n_categories
    assert len(mdmt) > 0 and set(mdmt["n_categories"]) == {k}
    assert mdmt["category"].between(0, k - 1).all()
    assert (
        mdmt.groupby("participant")["condition"].nunique().eq(2).all() and mdmt["participant"].nunique() == 4
    )
    assert set(mdmt["group"]) == {
        "A",
        "B",
    }  # both condition orders, or condition and session would be aliased
    # Static trust: the stated effect is the only difference between the conditions.
    means = mdmt.groupby("condition")["category"].mean()
    assert means["on"] > means["off"] + 1.0

    first, again = run_one(options, item), run_one(options, item)
    assert set(first) == {
        "participants",
        "repetition",
        "study_seed",
        "sampler_seed",
        "mean",
        "hdi",
        "decision",
        "r_hat_max",
        "divergences",
        "seconds",
    }
    assert (first["participants"], first["repetition"]) == (4, 0)
    assert (first["study_seed"], first["sampler_seed"]) == (item.study_seed, item.sampler_seed)
    assert first["hdi"][0] < first["mean"] < first["hdi"][1] and first["mean"] > 0
    assert first["decision"] == decide(tuple(first["hdi"]), options.rope)
    assert np.isnan(first["r_hat_max"])  # one chain: no R-hat
    # Seeded: the same work item gives the same study and the same draws.
    strip = ("seconds", "r_hat_max")
    assert {k: v for k, v in first.items() if k not in strip} == {
        k: v for k, v in again.items() if k not in strip
    }
