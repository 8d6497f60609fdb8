"""The self-confidence benchmark: metrics, dataset reading, profiles, and the evaluator end to end on tiny data."""

from __future__ import annotations

import csv
import importlib.util
import json
from pathlib import Path

import numpy as np
import pytest

from scone_bt.benchmarks.self_confidence import (
    EvalOptions,
    auroc,
    brier_score,
    embed_datasets,
    evaluate_pair,
    expected_calibration_error,
    load_datasets,
    load_profile,
    load_profiles,
    normalised_auc,
    prior_baseline,
    read_dataset,
)
from scone_bt.errors import ConfigError

ROOT = Path(__file__).resolve().parents[2]

# Synthetic robot: glass and heavy things fail, everything else succeeds (plus one noisy object).
_FAILS = {"olive oil", "vinegar", "soy sauce", "honey", "flour", "milk"}
_OBJECTS = [
    *sorted(_FAILS),
    "salt",
    "sugar",
    "butter",
    "pasta",
    "rice",
    "garlic",
    "onion",
    "lemon",
    "cheese",
    "eggs",
]


def _load_tool(name: str):
    spec = importlib.util.spec_from_file_location(name, ROOT / "tools" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _write_synthetic(directory: Path, n_datasets: int = 3, rows: int = 40) -> None:
    directory.mkdir(parents=True, exist_ok=True)
    for d in range(n_datasets):
        rng = np.random.default_rng(d)
        with (directory / f"robot{d}.csv").open("w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["action", "object", "outcome", "failure_stage", "seed"])
            for i in range(rows):
                obj = _OBJECTS[int(rng.integers(len(_OBJECTS)))]
                ok = obj not in _FAILS if obj != "eggs" else bool(rng.random() < 0.5)
                w.writerow(
                    [f"Put {obj} on table", obj, "success" if ok else "failure", "" if ok else "grasp", i]
                )


# ----------------------------------------------------------------------------------------------- metrics
def test_metrics_known_values():
    y = np.array([1, 1, 0, 0], dtype=bool)
    assert auroc(np.array([0.9, 0.8, 0.2, 0.1]), y) == 1.0
    assert auroc(np.array([0.1, 0.2, 0.8, 0.9]), y) == 0.0
    assert auroc(np.array([0.5, 0.5, 0.5, 0.5]), y) == 0.5
    assert np.isnan(auroc(np.array([0.3, 0.4]), np.array([True, True])))
    assert brier_score(np.array([1.0, 0.0]), np.array([True, False])) == 0.0
    assert brier_score(np.full(4, 0.5), y) == 0.25
    assert expected_calibration_error(np.array([1.0, 1.0, 0.0, 0.0]), y) == 0.0
    # All predictions 0.8 while half succeed: |0.5 - 0.8| = 0.3.
    assert expected_calibration_error(np.full(4, 0.8), y) == pytest.approx(0.3)
    assert normalised_auc([10, 20, 30], [0.7, 0.7, 0.7]) == pytest.approx(0.7)
    assert normalised_auc([10, 20, 30], [0.0, 0.5, 1.0]) == pytest.approx(0.5)


# ----------------------------------------------------------------------------------------------- datasets
def test_reads_experience_export_and_splits_robots(tmp_path):
    path = tmp_path / "export.csv"
    with path.open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["time", "action", "object_name", "embedder", "success", "failure_stage", "context"])
        for i in range(6):
            robot = "a" if i % 2 else "b"
            w.writerow(
                [
                    i,
                    "Put salt on table",
                    "salt",
                    "minilm",
                    i % 3 != 0,
                    "" if i % 3 else "grasp",
                    json.dumps({"robot": robot}),
                ]
            )
    sets = read_dataset(path)
    assert sorted(d.name for d in sets) == ["export:a", "export:b"]
    assert all(len(d) == 3 for d in sets)
    b = next(d for d in sets if d.name == "export:b")
    assert b.success.tolist() == [False, True, True]


def test_bad_datasets_give_one_line_errors(tmp_path):
    (tmp_path / "x.csv").write_text("action,outcome\nPut salt on table,success\n")
    with pytest.raises(ConfigError, match="missing column object"):
        load_datasets(tmp_path)
    (tmp_path / "x.csv").write_text("action,object,outcome\nPut salt on table,salt,maybe\n")
    with pytest.raises(ConfigError, match="not one of success, failure"):
        load_datasets(tmp_path)
    _write_synthetic(tmp_path / "short", n_datasets=1, rows=30)
    with pytest.raises(ConfigError, match="needs at least 100"):
        load_datasets(tmp_path / "short", min_rows=100)


# ----------------------------------------------------------------------------------------------- profiles
def test_shipped_profiles_are_documented_and_distinct(kitchen_cfg, robot_cfg):
    profiles = load_profiles(ROOT / "tools" / "profiles")
    assert len(profiles) >= 10
    assert len({p.seed for p in profiles}) == len(profiles)
    assert all(len(p.description) > 40 for p in profiles)
    applied = {p.name: p.apply(kitchen_cfg, robot_cfg) for p in profiles}
    distinct = {
        (r.gripper, r.limits, r.planner, k.camera, p.calibration_offset, p.injected, p.objects_on_shelf)
        for p in profiles
        for k, r in [applied[p.name]]
    }
    assert len(distinct) == len(profiles)
    weak = next(p for p in profiles if p.name == "p01_weak_gripper")
    assert applied[weak.name][1].gripper.max_force == weak.gripper_max_force < robot_cfg.gripper.max_force


def test_profile_errors_name_valid_keys(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("name: x\ndescription: y\nseed: 1\ngripper: {force: 3}\n")
    with pytest.raises(ConfigError, match="unknown key 'force'; valid: max_force, finger_friction"):
        load_profile(bad)
    bad.write_text("name: x\ndescription: y\nseed: 1\ninjected: [{stage: transit, rate: 0.5}]\n")
    with pytest.raises(ConfigError, match="not one of perception, planning, grasp"):
        load_profile(bad)


# ----------------------------------------------------------------------------------------------- Algorithm 1
def test_semantic_signal_beats_the_prior_on_synthetic_data(tmp_path):
    from scone_bt.confidence import make_estimator
    from scone_bt.embedding import load_embedder

    _write_synthetic(tmp_path)
    datasets = load_datasets(tmp_path)
    options = EvalOptions(n_test=10, steps=(10, 20, 30), shuffles=3)
    vocabulary = sorted({a for d in datasets for a in d.actions})
    X = embed_datasets(datasets, load_embedder("onehot", vocabulary=vocabulary).embed)
    knn = evaluate_pair("onehot", "knn", datasets, X, lambda s: make_estimator("knn", seed=s), options)
    prior = prior_baseline(datasets, options)
    assert len(knn.curve_mean) == 3 and len(knn.auc) == 3
    assert 0.0 <= min(knn.auc) <= max(knn.auc) <= 1.0
    # Outcomes are a function of the object (except eggs): memorising actions must beat the majority class.
    assert np.mean(knn.final_accuracy) > np.mean(prior.final_accuracy) + 0.1
    assert np.mean(knn.auroc) > 0.8
    again = evaluate_pair("onehot", "knn", datasets, X, lambda s: make_estimator("knn", seed=s), options)
    assert again.auc == knn.auc  # seeded shuffles: identical numbers


def test_eval_cli_end_to_end(tmp_path):
    data, out = tmp_path / "data", tmp_path / "out"
    _write_synthetic(data)
    tool = _load_tool("eval_sc")
    argv = ["--datasets", str(data), "--out-dir", str(out), "--embedders", "onehot", "glove", "nonexistent"]
    argv += [
        "--estimators",
        "knn",
        "eps-lgbm",
        "--shuffles",
        "2",
        "--n-test",
        "10",
        "--steps",
        "10",
        "20",
        "30",
    ]
    assert tool.main([*argv, "--jobs", "1"]) == 0
    payload = json.loads((out / "self_confidence.json").read_text())
    assert payload["embedders"] == ["onehot", "glove"]
    assert "nonexistent" in payload["embedders_skipped"]
    assert len(payload["results"]) == 4
    for r in payload["results"]:
        assert r["n_train"] == [10, 20, 30]
        assert len(r["auc"]["per_shuffle"]) == 2
        assert 0.0 <= r["auc"]["mean"] <= 1.0
    table = (out / "self_confidence_tables.md").read_text()
    assert "| Embedding | knn | eps-lgbm |" in table and "| glove |" in table
    assert (out / "self_confidence_curves.png").stat().st_size > 1000
    assert tool.main([*argv, "--estimators", "nope"]) == 2  # one-line error naming the valid estimators
