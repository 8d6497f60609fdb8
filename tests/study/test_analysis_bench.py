"""scone-bench study-analysis and study-recovery run end to end at the smallest settings and print the JSON keys
docs/study.md names; clmm's column of study-recovery is checked where R and its ordinal package are installed."""

from __future__ import annotations

import json

import numpy as np
import pytest

from scone_bt.cli.bench import main
from scone_bt.study.r_clmm import r_unavailable

# One short chain on one process: a smoke test of the plumbing, not of the statistics (the benchmarks' job).
QUICK = ["--chains", "1", "--tune", "30", "--draws", "30", "--cores", "1"]


def test_study_analysis_prints_and_writes_its_report(tmp_path, capsys):
    out, report_path = tmp_path / "analysis", tmp_path / "report.json"
    argv = ["study-analysis", "--participants", "4", *QUICK, "--out", str(out), "--json", str(report_path)]
    assert main(argv) == 0
    report = json.loads(capsys.readouterr().out)
    assert report == json.loads(report_path.read_text())
    assert report["benchmark"] == "study-analysis" and report["data"] == "SIMULATED"
    assert report["participants"] == 4 and report["model"] == "paper"
    assert {k: report["sampler"][k] for k in ("chains", "tune", "draws", "cores", "seed")} == {
        "chains": 1,
        "tune": 30,
        "draws": 30,
        "cores": 1,
        "seed": 0,
    }
    assert report["wall_s"] > 0 and report["cpu_s"] > 0 and report["target_wall_s"] == 180.0
    assert report["wall_target_met"] == (report["wall_s"] <= 180.0)
    assert set(report["per_model_s"]) == {"mdmt", "tps_hri", "interventions"}
    assert (
        report["r_hat_max"] is None and report["divergences"] >= 0
    )  # one chain: no R-hat, null in strict JSON
    assert report["true_condition_effect"] == 1.0
    recovered = report["recovered"]
    assert set(recovered) == {"mdmt", "tps_hri", "interventions_eq4_counts"}
    for entry in recovered.values():
        low, high = entry["hdi"]
        assert low < entry["mean"] < high and entry["contains_truth"] == (low <= 1.0 <= high)
    assert report["all_recovered"] == all(e["contains_truth"] for e in recovered.values())
    low, high = report["episode_interventions_condition"]["hdi"]
    assert low < report["episode_interventions_condition"]["mean"] < high
    assert {"load_average_at_start", "cpu_count"} <= set(report)
    # --out: the analysis's own results, labelled SIMULATED, with the contrasts the report quotes.
    results = json.loads((out / "results.json").read_text())
    assert results["data"] == "SIMULATED"
    mdmt = next(c for c in results["contrasts"] if (c["model"], c["contrast"]) == ("mdmt", "condition"))
    assert mdmt["mean"] == recovered["mdmt"]["mean"] and mdmt["hdi"] == recovered["mdmt"]["hdi"]
    assert (out / "fig3.png").is_file() and (out / "scores.csv").is_file()


@pytest.fixture(scope="module")
def recovery(tmp_path_factory) -> dict:
    """One study-recovery run shared by its two tests: its report, as written to --json."""
    # Two seeds (not one): the calibration keys (spread of the estimates over the posterior sd) need two studies.
    # Eight participants give clmm, where R is installed, enough answers to fit.
    report_path = tmp_path_factory.mktemp("recovery") / "recovery.json"
    argv = ["study-recovery", "--seeds", "2", "--participants", "8", *QUICK, "--json", str(report_path)]
    assert main(argv) == 0
    return json.loads(report_path.read_text())


def test_study_recovery_reports_coverage_bias_and_calibration(recovery):
    report = recovery
    assert report["benchmark"] == "study-recovery" and report["data"] == "SIMULATED"
    assert (
        report["seeds"] == [0, 1] and report["participants"] == 8 and report["true_condition_effect"] == 1.0
    )
    assert report["priors"] == {"effect_sd": 1.0, "cutpoint_sd": 1.0, "scale_sd": 1.0}
    assert report["sampler"] == {"chains": 1, "tune": 30, "draws": 30, "cores": 1}
    assert report["wall_s"] > 0 and "load_average_at_start" in report
    assert set(report["summary"]) == set(report["runs"]) == {"mdmt", "tps_hri", "interventions_eq4_counts"}
    for name, entry in report["summary"].items():
        runs = report["runs"][name]
        assert [r["seed"] for r in runs] == [0, 1]
        means = np.array([r["mean"] for r in runs])
        assert all(r["hdi"][0] < r["mean"] < r["hdi"][1] and r["sd"] > 0 for r in runs)
        assert entry["coverage"] == sum(r["hdi"][0] <= 1.0 <= r["hdi"][1] for r in runs) / 2
        assert entry["mean_estimate"] == pytest.approx(means.mean(), abs=1e-4)
        assert entry["bias"] == pytest.approx(means.mean() - 1.0, abs=1e-4)
        assert entry["mean_posterior_sd"] == pytest.approx(np.mean([r["sd"] for r in runs]), abs=1e-4)
        assert entry["sd_of_estimates"] == pytest.approx(means.std(ddof=1), abs=1e-4)
        assert entry["sd_of_estimates_over_mean_sd"] == pytest.approx(
            entry["sd_of_estimates"] / entry["mean_posterior_sd"], abs=2e-3
        )
        assert entry["bias_se"] == pytest.approx(means.std(ddof=1) / np.sqrt(2), abs=1e-4)
    # Eq. (4) counts have no clmm counterpart, with or without R.
    assert not any("clmm" in k for k in report["summary"]["interventions_eq4_counts"])


def test_study_recovery_clmm_column(recovery):
    report = recovery
    why_not = r_unavailable()
    if why_not is not None:
        assert report["clmm"] == f"skipped: {why_not}"
        assert not any("clmm" in r for runs in report["runs"].values() for r in runs)
        pytest.skip(f"study-recovery's clmm column not checked: {why_not}")
    assert report["clmm"].startswith("ordinal::clmm")
    for name in ("mdmt", "tps_hri"):
        entry, runs = report["summary"][name], report["runs"][name]
        ml = np.array([r["clmm"] for r in runs])
        assert np.isfinite(ml).all() and all("clmm_se" in r for r in runs)
        assert entry["clmm_mean_estimate"] == pytest.approx(ml.mean(), abs=1e-4)
        diff = np.array([r["mean"] for r in runs]) - ml
        assert entry["mean_minus_clmm"] == pytest.approx(diff.mean(), abs=1e-4)
        assert entry["mean_minus_clmm_range"] == pytest.approx([diff.min(), diff.max()], abs=1e-4)
        assert {"clmm_mean_se", "clmm_sd_of_estimates"} <= set(entry)
