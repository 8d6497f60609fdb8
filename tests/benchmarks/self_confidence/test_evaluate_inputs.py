"""Inputs of the evaluation: experience-store exports, one-line errors for bad datasets, the shipped profiles.

(Moved from tests/tools/test_eval_sc.py when tools/eval_sc.py became `scone-bench sc evaluate`.)
"""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest

from scone_bt.benchmarks.self_confidence import load_datasets, load_profile, load_profiles, read_dataset
from scone_bt.errors import ConfigError

ROOT = Path(__file__).resolve().parents[3]

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
    # a measured quantity is finite and not negative: an inf made κ̂'s confidence NaN far from its row
    for column, value in (("detected_height_m", "-inf"), ("width_m", "-0.5"), ("mass_kg", "nan")):
        (tmp_path / "x.csv").write_text(
            f"action,object,outcome,{column}\nPut salt on table,salt,success,{value}\n"
        )
        with pytest.raises(ConfigError) as info:
            load_datasets(tmp_path)
        assert str(info.value) == (
            f"{tmp_path / 'x.csv'} row 2: {column} {float(value):g} must be a finite number ≥ 0 (or empty)"
        )


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
