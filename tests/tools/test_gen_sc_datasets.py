"""The dataset generator: one real simulated execution per profile row, seeded and resumable."""

from __future__ import annotations

import dataclasses
import importlib.util
import json
from pathlib import Path

import numpy as np
import pytest

from scone_bt.benchmarks.self_confidence import load_profile, read_records
from scone_bt.benchmarks.self_confidence.generate import choose_objects

ROOT = Path(__file__).resolve().parents[2]
PROFILES = ROOT / "tools" / "profiles"


def test_object_draws_are_seeded_and_cover_the_catalogue(kitchen_cfg):
    prof = load_profile(PROFILES / "p00_nominal.yaml")
    objects = kitchen_cfg.catalogue.objects
    draws = [choose_objects(prof, i, objects) for i in range(10 * len(objects))]  # coupon collector: ~7 n
    assert [t.name for t, _ in draws[:20]] == [choose_objects(prof, i, objects)[0].name for i in range(20)]
    assert len({t.name for t, _ in draws}) == len(objects)
    assert all(len(o) == prof.objects_on_shelf - 1 and t not in o for t, o in draws)


def test_injections_only_hit_matching_objects(kitchen_cfg):
    prof = load_profile(PROFILES / "p08_transparent_blind.yaml")
    glass = next(o for o in kitchen_cfg.catalogue.objects if o.material == "glass")
    paper = next(o for o in kitchen_cfg.catalogue.objects if o.material == "paper")
    hits = [prof.draw_injections(glass, np.random.default_rng(i)) for i in range(200)]
    assert 0.55 < np.mean(["perception" in h for h in hits]) < 0.85
    assert not any(prof.draw_injections(paper, np.random.default_rng(i)) for i in range(200))


@pytest.mark.slow
def test_generator_runs_real_executions_and_resumes(tmp_path):
    spec = importlib.util.spec_from_file_location("gen_sc_datasets", ROOT / "tools" / "gen_sc_datasets.py")
    tool = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(tool)
    # A fast profile: the injected perception miss on glass ends those runs before motion.
    prof_dir = tmp_path / "profiles"
    prof_dir.mkdir()
    (prof_dir / "p.yaml").write_text((PROFILES / "p08_transparent_blind.yaml").read_text())
    out = tmp_path / "data"
    argv = ["--profiles", str(prof_dir), "--out", str(out), "--executions", "2", "--jobs", "1"]
    assert tool.main(argv) == 0
    records = read_records(out / "p08_transparent_blind.csv")
    assert [r.index for r in records] == [0, 1]
    prof = load_profile(prof_dir / "p.yaml")
    for r in records:
        assert r.seed == prof.execution_seed(r.index)
        assert r.action == f"Put {r.object} on table"
        assert r.success == (r.failure_stage is None)
        assert r.detail
    log = json.loads((out / "generation.json").read_text())
    assert log["runs"][-1]["executions_run"] == 2
    assert tool.main(argv) == 0  # everything recorded: nothing runs again
    assert json.loads((out / "generation.json").read_text())["runs"][-1]["executions_run"] == 0
    assert [dataclasses.astuple(r) for r in read_records(out / "p08_transparent_blind.csv")] == [
        dataclasses.astuple(r) for r in records
    ]
