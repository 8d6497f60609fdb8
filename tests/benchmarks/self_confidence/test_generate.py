"""`scone-bench sc generate`: seeded draws over the whole catalogue, context of each execution, a user's own
products, resuming a partial file, and one-line errors on bad input."""

from __future__ import annotations

import json
import os
import re
from pathlib import Path

import numpy as np
import pytest

from scone_bt.benchmarks.self_confidence import load_profile, read_records
from scone_bt.benchmarks.self_confidence.generate import choose_objects, drawable_products
from scone_bt.cli.bench import main as bench

ROOT = Path(__file__).resolve().parents[3]
PROFILES = ROOT / "tools" / "profiles"


def test_draws_are_seeded_uniform_over_the_whole_catalogue_and_fit_the_shelving(kitchen_cfg):
    from scone_bt.stocking import plan_stocking

    prof = load_profile(PROFILES / "p00_nominal.yaml")
    pool = drawable_products(kitchen_cfg)
    assert len(pool) >= 0.95 * len(kitchen_cfg.catalogue)
    draws = [choose_objects(prof, i, pool, kitchen_cfg.scene) for i in range(100)]
    assert [t.name for t, _ in draws[:10]] == [
        choose_objects(prof, i, pool, kitchen_cfg.scene)[0].name for i in range(10)
    ]
    targets = [t.name for t, _ in draws]
    # Uniform over hundreds of products: 100 draws give mostly distinct targets, from many families.
    assert len(set(targets)) >= 85
    assert len({t.family for t, _ in draws}) >= 10
    for t, others in draws[:20]:
        assert len(others) == prof.objects_on_shelf - 1 and t not in others
        plan_stocking(kitchen_cfg.scene, [t, *others], np.random.default_rng(0))  # fits side by side


def test_injections_only_hit_matching_objects(kitchen_cfg):
    prof = load_profile(PROFILES / "p08_transparent_blind.yaml")
    glass = next(o for o in kitchen_cfg.catalogue.objects if o.material == "glass")
    paper = next(o for o in kitchen_cfg.catalogue.objects if o.material == "paper")
    hits = [prof.draw_injections(glass, np.random.default_rng(i)) for i in range(200)]
    assert 0.55 < np.mean(["perception" in h for h in hits]) < 0.85
    assert not any(prof.draw_injections(paper, np.random.default_rng(i)) for i in range(200))


@pytest.mark.slow
def test_generate_on_a_user_catalogue_restricted_draw_and_resume(tmp_path, user_catalogue, capsys):
    mine = user_catalogue(tmp_path)
    products = tmp_path / "draw.txt"
    products.write_text("# my tins and one shop product\nsmoked paprika tin\nsaffron tin\nmatcha tin\nsalt\n")
    out = tmp_path / "data"
    # The nominal robot with three products per execution (the draw is restricted to four).
    profiles = tmp_path / "profiles"
    profiles.mkdir()
    text = (PROFILES / "p00_nominal.yaml").read_text()
    (profiles / "p00_nominal.yaml").write_text(re.sub(r"objects_on_shelf: \d+", "objects_on_shelf: 3", text))
    argv = [
        "sc", "generate", "--profiles", "p00_nominal", "--profiles-dir", str(profiles), "--out", str(out),
        "--catalogue", str(mine), "--products", str(products), "--workers", "1", "--no-progress",
    ]  # fmt: skip
    prof = load_profile(profiles / "p00_nominal.yaml")
    assert prof.objects_on_shelf == 3
    # Stopped after its first row (a tiny --max-minutes): the profile is left as a partial file.
    assert bench([*argv, "--executions", "2", "--max-minutes", "0.0001"]) == 1
    partial = out / ".p00_nominal.partial.csv"
    assert partial.is_file() and not (out / "p00_nominal.csv").exists()
    first = read_records(partial)
    assert len(first) == 1
    capsys.readouterr()
    assert bench([*argv, "--executions", "2"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["executions_run"] == 1 and summary["executions_resumed"] == 1  # row 0 is not run again
    assert summary["products_drawn_from"] == 4 and summary["user_catalogues"] == ["my_products.yaml"]
    records = read_records(out / "p00_nominal.csv")
    assert records[0] == first[0] and not partial.exists()
    allowed = {"smoked paprika tin", "saffron tin", "matcha tin", "salt"}
    for r in records:
        assert r.object in allowed
        assert r.seed == prof.execution_seed(r.index)
        assert r.action == f"Put {r.object} on table"
        assert r.success == (r.failure_stage is None)
        if r.detected:  # perceived: where the detection stands
            assert r.shelf_unit and r.shelf_tier >= 0 and r.slot >= 0 and r.clearance_m >= 0
        else:  # nothing perceived, nothing recorded
            assert not r.shelf_unit and r.shelf_tier is r.slot is r.clearance_m is r.neighbours is None
        assert r.width_m > 0 and r.mass_kg > 0 and r.material
        if r.detected and r.detected_width_m is not None:
            assert abs(r.detected_width_m - r.width_m) < 0.02  # measured from the depth image
    assert any(r.family == "my tins" for r in records) or all(r.object == "salt" for r in records)
    log = json.loads((out / "generation.json").read_text())
    assert [run["executions_run"] for run in log["runs"]] == [1, 1]
    assert str(tmp_path) not in (out / "generation.json").read_text()


def _one_line_error(capsys, argv: list[str]) -> str:
    assert bench(argv) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "Traceback" not in err
    return err


def test_bad_inputs_are_one_line_errors_before_any_execution(tmp_path, capsys):
    base = ["sc", "generate", "--profiles-dir", str(PROFILES), "--out", str(tmp_path / "o"), "--no-progress"]
    err = _one_line_error(capsys, [*base, "--profiles", "p99_nobody"])
    assert "unknown profile 'p99_nobody'" in err and "p00_nominal" in err
    err = _one_line_error(capsys, [*base, "--products", "salt,unicorn steak"])
    assert "unknown product 'unicorn steak'" in err
    err = _one_line_error(capsys, [*base, "--products", str(tmp_path / "draw.txt")])  # said "unknown product"
    assert f"--products {tmp_path / 'draw.txt'}: no such file" in err
    blocker = tmp_path / "a_file"
    blocker.write_text("")
    err = _one_line_error(
        capsys, ["sc", "generate", "--profiles-dir", str(PROFILES), "--out", str(blocker / "sub")]
    )
    assert "not a writable folder" in err
    err = _one_line_error(capsys, [*base, "--executions", "0"])
    assert "--executions" in err
    err = _one_line_error(capsys, [*base, "--catalogue", str(tmp_path / "missing.yaml")])
    assert "missing.yaml" in err
    assert not (tmp_path / "o").exists() or not any((tmp_path / "o").glob("*.csv"))


@pytest.mark.parametrize(
    ("old", "new", "message"),
    [
        (
            "materials: [glass]",
            "materials: [glas]",
            "injected[0].materials: no product of the catalogue is of material 'glas'; valid: aluminium, carton, foil, "
            "glass, metal, paper, plastic, produce",
        ),
        ("materials: [glass]", "shapes: [cylindre]", "'cylindre' is not a shape; valid: box, cylinder"),
    ],
)
def test_an_injected_failure_that_could_never_fire_is_refused(tmp_path, capsys, old, new, message):
    """A misspelt material or shape matched no product: the profile generated, and its injection never fired."""
    folder = tmp_path / "profiles"
    folder.mkdir()
    text = (PROFILES / "p08_transparent_blind.yaml").read_text(encoding="utf-8")
    assert old in text
    (folder / "p08_transparent_blind.yaml").write_text(text.replace(old, new), encoding="utf-8")
    argv = ["sc", "generate", "--profiles-dir", str(folder), "--out", str(tmp_path / "o"), "--no-progress"]
    err = _one_line_error(capsys, argv)
    assert "p08_transparent_blind.yaml" in err and message in err
    assert not (tmp_path / "o").exists() or not any((tmp_path / "o").glob("*.csv"))


def test_a_product_subset_without_glass_keeps_the_glass_profile(tmp_path, capsys, monkeypatch):
    """The materials are checked against the catalogue, not --products: a dairy-only run is not refused for it."""
    from scone_bt.benchmarks.self_confidence import batch

    def stop(*args: object, **kwargs: object) -> None:
        raise batch.ConfigError("checked")

    monkeypatch.setattr(batch, "generation_settings", stop)  # the step after the checks
    argv = [
        "sc",
        "generate",
        "--out",
        str(tmp_path / "o"),
        "--no-progress",
        "--products",
        "salt,sugar,rice,flour,pasta,butter,milk,brown sugar",
    ]
    argv += ["--profiles", "p08_transparent_blind"]
    assert _one_line_error(capsys, argv) == "scone-bench: checked"


@pytest.mark.parametrize("minutes", ["nan", "inf", "0", "-1"])
def test_max_minutes_must_be_finite_and_positive(tmp_path, capsys, minutes):
    base = ["sc", "generate", "--profiles-dir", str(PROFILES), "--out", str(tmp_path / "o"), "--no-progress"]
    err = _one_line_error(capsys, [*base, "--max-minutes", minutes])
    assert err == (
        f"scone-bench: --max-minutes {float(minutes)}: must be a finite number above 0 (leave it out: no limit)"
    )
    assert not (tmp_path / "o").exists() or not any((tmp_path / "o").glob("*.csv"))


def test_products_that_stand_on_no_tier_are_named_when_too_few_are_left(tmp_path, capsys):
    base = ["sc", "generate", "--profiles", "p00_nominal", "--out", str(tmp_path / "o"), "--no-progress"]
    err = _one_line_error(capsys, [*base, "--products", "tortillas,salt,rice paper"])
    assert err == (
        "scone-bench: --products: 1 product(s) fit the shelving (tortillas, rice paper stand on no shelf tier: "
        "too deep or too long), profile needs 6 per execution (objects_on_shelf); name more products"
    )


@pytest.mark.slow
def test_an_execution_ends_the_same_whatever_its_worker_ran_before(kitchen_cfg, robot_cfg):
    """Execution 1 of the slippery fingers at ``--seed 20`` (the peppermint extract, dropped in the carry) ended as a
    success when its worker had run execution 0 before it in a restocked kitchen: with ``--workers 2`` the pool's
    order decided the row. Each execution now gets a new kitchen, so a worker's history is invisible."""
    import dataclasses

    import scone_bt.benchmarks.self_confidence.generate as gen

    prof = load_profile(PROFILES / "p02_slippery_fingers.yaml")
    prof = dataclasses.replace(prof, seed=prof.seed + 20)
    saved = gen._WORKER
    try:
        gen._WORKER = gen._Worker()
        first = gen.run_execution(prof, 1, kitchen_cfg, robot_cfg)[0]
        gen.run_execution(prof, 0, kitchen_cfg, robot_cfg)
        after_another = gen.run_execution(prof, 1, kitchen_cfg, robot_cfg)[0]
    finally:
        gen._WORKER = saved
    assert first.object == "peppermint extract"
    assert after_another == first


# ----------------------------------------------------------------------- resuming only the same generation
@pytest.fixture
def fake_runs(monkeypatch) -> list:
    """`sc generate` without the simulation: each execution is a record of the robot and products it ran with."""
    from scone_bt.benchmarks.self_confidence.dataset import ExecutionRecord

    ran: list = []

    def imap(fn, tasks, engine=None, **_):
        def gen():
            for i, t in enumerate(tasks):
                ran.append(t)
                record = ExecutionRecord(
                    index=t.index,
                    action="Put salt on table",
                    object="salt",
                    success=True,
                    failure_stage=None,
                    seed=t.profile.execution_seed(t.index),
                    detail=f"{t.robot} {t.products}",
                )
                yield i, (t.profile.name, record, 0.0)

        return gen()

    monkeypatch.setattr("scone_bt.distributed.imap_tasks", imap)
    return ran


def _generate(out: Path, *extra: str) -> list[str]:
    return [
        "sc", "generate", "--profiles", "p00_nominal", "--profiles-dir", str(PROFILES), "--out", str(out),
        "--workers", "1", "--no-progress", *extra,
    ]  # fmt: skip


def test_another_seed_never_wipes_a_complete_dataset(tmp_path, fake_runs, capsys):
    out = tmp_path / "X"
    out.mkdir()
    shipped = (ROOT / "tools" / "data" / "sc" / "p00_nominal.csv").read_bytes()
    (out / "p00_nominal.csv").write_bytes(shipped)
    err = _one_line_error(capsys, _generate(out, "--executions", "2", "--seed", "1"))
    assert "p00_nominal.csv" in err and "another generation" in err
    assert "--seed 0, this run asks --seed 1" in err and "another --out, or --seed 0" in err
    assert fake_runs == [] and (out / "p00_nominal.csv").read_bytes() == shipped
    assert sorted(p.name for p in out.iterdir()) == ["p00_nominal.csv"]
    # the matching seed resumes it: nothing to run, nothing rewritten
    assert bench(_generate(out, "--executions", "2")) == 0
    assert fake_runs == [] and (out / "p00_nominal.csv").read_bytes() == shipped


@pytest.mark.parametrize(("seed", "shared"), [("1", ["p01_weak_gripper"]), ("20", [])])
def test_a_seed_that_repeats_another_profiles_draws_is_named(tmp_path, fake_runs, capsys, seed, shared):
    # profile seeds are consecutive (100, 101, ...): --seed 1 gives p00_nominal p01_weak_gripper's executions
    report = tmp_path / "summary.json"
    assert (
        bench([*_generate(tmp_path / "X", "--executions", "1", "--seed", seed), "--json", str(report)]) == 0
    )
    err = capsys.readouterr().err
    summary = json.loads(report.read_text())
    assert summary["profiles"]["p00_nominal"]["same_seeds_as"] == shared
    assert ("gives p00_nominal the seeds of p01_weak_gripper" in err) == bool(shared)
    log = json.loads((tmp_path / "X" / "generation.json").read_text())
    assert log["runs"][-1]["profiles"]["p00_nominal"]["same_seeds_as"] == shared


def test_a_partial_dataset_of_another_seed_is_not_dropped(tmp_path, fake_runs, capsys):
    out = tmp_path / "X"
    assert bench(_generate(out, "--executions", "3", "--seed", "2", "--max-minutes", "0.0000001")) == 1
    assert (
        "the seeds of p02_slippery_fingers" in capsys.readouterr().err
    )  # the note of that run, not an error
    partial = out / ".p00_nominal.partial.csv"
    before = partial.read_bytes()
    err = _one_line_error(capsys, _generate(out, "--executions", "3"))
    assert ".p00_nominal.partial.csv" in err and "--seed: it holds 2, this run asks 0" in err
    assert "or --seed 2 to resume" in err
    assert partial.read_bytes() == before and len(fake_runs) == 1


def test_a_resume_with_other_settings_is_refused_before_running(tmp_path, kitchen_cfg, fake_runs, capsys):
    out = tmp_path / "Y"
    names = [o.name for o in drawable_products(kitchen_cfg)[:8]]
    assert bench(_generate(out, "--executions", "1")) == 0
    final = out / "p00_nominal.csv"
    before, log = final.read_bytes(), (out / "generation.json").read_bytes()
    err = _one_line_error(
        capsys, _generate(out, "--executions", "2", "--arm", "iiwa7", "--products", ",".join(names))
    )
    assert "p00_nominal.csv" in err and "another generation" in err
    assert "--arm: it holds panda.yaml sha256:" in err and "this run asks iiwa7.yaml sha256:" in err
    assert f"--products: it holds all products, this run asks {names[0]}," in err
    assert final.read_bytes() == before and (out / "generation.json").read_bytes() == log
    assert len(fake_runs) == 1
    # an edited profile is another generation too
    profiles = tmp_path / "profiles"
    profiles.mkdir()
    text = (PROFILES / "p00_nominal.yaml").read_text()
    (profiles / "p00_nominal.yaml").write_text(text.replace("objects_on_shelf: 6", "objects_on_shelf: 5"))
    err = _one_line_error(capsys, [*_generate(out, "--executions", "2"), "--profiles-dir", str(profiles)])
    assert "the profile: it holds p00_nominal sha256:" in err and final.read_bytes() == before
    # the same settings resume: only row 1 runs, row 0 is kept
    assert bench(_generate(out, "--executions", "2")) == 0
    records = read_records(final)
    assert [r.index for r in records] == [0, 1] and {r.detail for r in records} == {"panda None"}
    assert [t.index for t in fake_runs] == [0, 1]
    recorded = json.loads((out / "generation.json").read_text())["generations"]["p00_nominal"]
    assert recorded["robot"].startswith("panda.yaml sha256:") and recorded["products"] is None
    assert recorded["seed"] == 0 and str(tmp_path) not in json.dumps(recorded)


def test_rows_beyond_executions_are_kept_when_the_file_is_rewritten(tmp_path, fake_runs):
    from scone_bt.benchmarks.self_confidence.dataset import ExecutionRecord, write_records

    out = tmp_path / "X"
    prof = load_profile(PROFILES / "p00_nominal.yaml")
    rows = [
        ExecutionRecord(i, "Put salt on table", "salt", True, None, prof.execution_seed(i))
        for i in (0, 1, 3, 4)
    ]
    write_records(out / ".p00_nominal.partial.csv", rows)
    assert bench(_generate(out, "--executions", "3")) == 0
    assert [t.index for t in fake_runs] == [2]
    assert [r.index for r in read_records(out / "p00_nominal.csv")] == [0, 1, 2, 3, 4]


@pytest.mark.parametrize(
    ("content", "message"),
    [
        ('{"runs": [', "not valid JSON (line 1"),
        ('{"runs": 3}', '"runs" must be a list of objects'),
        ("[]", "must be a JSON object"),
        ('{"runs": [], "generations": {"p00_nominal": {"robot": "x"}}}', "exactly the keys robot, kitchen"),
        (None, "directory"),
    ],
)
def test_a_damaged_generation_log_stops_the_run_before_any_execution(
    tmp_path, fake_runs, capsys, content, message
):
    out = tmp_path / "X"
    out.mkdir()
    log = out / "generation.json"
    if content is None:
        log.mkdir()
    else:
        log.write_text(content)
    err = _one_line_error(capsys, _generate(out, "--executions", "1"))
    assert str(log) in err and message in err
    assert fake_runs == [] and not list(out.glob("*.csv")) and not list(out.glob(".*.csv"))
    assert content is None or log.read_text() == content


def test_the_generation_log_is_replaced_whole_not_rewritten_in_place(tmp_path, fake_runs):
    out = tmp_path / "X"
    assert bench(_generate(out, "--executions", "1")) == 0
    log = out / "generation.json"
    first = log.read_text()
    os.link(log, tmp_path / "alias.json")  # a write in place would change the alias too
    assert bench(_generate(out, "--executions", "2")) == 0
    assert (tmp_path / "alias.json").read_text() == first
    assert [r["executions_run"] for r in json.loads(log.read_text())["runs"]] == [1, 1]
    assert not [p for p in out.iterdir() if p.name.endswith(".tmp")]


# ----------------------------------------------------------------------- the engine (--robot)
def test_a_generation_of_another_engine_is_not_resumed(tmp_path, fake_runs, capsys):
    os.environ.setdefault("MUJOCO_GL", "egl")  # before mujoco is first imported (it reads it then)
    pytest.importorskip("mujoco")
    out = tmp_path / "X"
    assert bench(_generate(out, "--executions", "1")) == 0
    final = out / "p00_nominal.csv"
    before = final.read_bytes()
    err = _one_line_error(capsys, _generate(out, "--executions", "2", "--robot", "mujoco"))
    assert "another generation" in err and "--robot: it holds sim, this run asks mujoco" in err
    assert final.read_bytes() == before and len(fake_runs) == 1
    # a log written before the engine was a setting holds PyBullet's rows: they resume under --robot sim
    log = json.loads((out / "generation.json").read_text())
    del log["generations"]["p00_nominal"]["backend"]
    (out / "generation.json").write_text(json.dumps(log))
    assert bench(_generate(out, "--executions", "2")) == 0
    assert [t.index for t in fake_runs] == [0, 1] and {t.engine for t in fake_runs} == {"sim"}


def test_robot_names_an_engine_the_generator_runs_on(tmp_path, fake_runs, capsys):
    err = _one_line_error(capsys, _generate(tmp_path / "X", "--robot", "panda"))
    assert "--robot names the robot backend" in err and "--arm panda" in err
    assert fake_runs == []


@pytest.mark.slow
def test_a_mujoco_execution_is_the_same_task_and_repeats_exactly(kitchen_cfg, robot_cfg):
    """Execution i is one task on either engine (products, slots, seeds); on MuJoCo a fresh kitchen each time."""
    os.environ.setdefault("MUJOCO_GL", "egl")  # before mujoco is first imported (it reads it then)
    pytest.importorskip("mujoco")
    import scone_bt.benchmarks.self_confidence.generate as gen

    prof = load_profile(PROFILES / "p00_nominal.yaml")
    pool = tuple(o for o in drawable_products(kitchen_cfg) if o.family in ("cans", "boxes", "bags"))
    saved = gen._WORKER
    try:
        gen._WORKER = gen._Worker()
        first, again = (
            gen.run_execution(prof, 1, kitchen_cfg, robot_cfg, pool=pool, engine="mujoco")[0]
            for _ in range(2)
        )
        bullet = gen.run_execution(prof, 1, kitchen_cfg, robot_cfg, pool=pool)[0]
    finally:
        gen._WORKER = saved
    assert again == first
    assert (first.object, first.seed, first.shelf_unit, first.slot) == (
        bullet.object,
        bullet.seed,
        bullet.shelf_unit,
        bullet.slot,
    )
    assert first.detected and abs(first.detected_width_m - bullet.detected_width_m) < 0.005


def test_the_log_records_whether_the_arm_slid_flat_packs_and_the_replay_reads_it(tmp_path, fake_runs):
    """generation.json's ``slide_pinch`` (the robot file's grasp.slide_pinch) is what the replay's gate reads
    (`replay_streams.slides_flat_packs`); a log written before it was a setting holds an arm without the skill."""
    from scone_bt.benchmarks.replay_streams import slides_flat_packs

    out = tmp_path / "X"
    assert bench(_generate(out, "--executions", "1")) == 0
    log = json.loads((out / "generation.json").read_text())
    assert log["generations"]["p00_nominal"]["slide_pinch"] is True  # robots/panda.yaml
    assert slides_flat_packs(out, ["p00_nominal", "p99_other"]) == [True, False]
    del log["generations"]["p00_nominal"]["slide_pinch"]
    (out / "generation.json").write_text(json.dumps(log))
    assert slides_flat_packs(out, ["p00_nominal"]) == [False]
    assert slides_flat_packs(tmp_path / "nothing", ["p00_nominal"]) == [False]
