"""``scone-bench soak``: twenty episodes in one process leave descriptors and threads where they were.

Memory slopes belong in the benchmark's JSON (docs/results/soak.json), not in a timed test: here only what must
hold exactly is checked.
"""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from scone_bt.benchmarks.soak import corpus_recipes
from scone_bt.cli.bench import main
from scone_bt.process_stats import slope


def test_slope_is_the_least_squares_fit():
    assert slope([1.0, 3.0, 5.0, 7.0]) == pytest.approx(2.0)
    assert slope([4.0, 4.0, 4.0]) == pytest.approx(0.0)
    assert slope([1.0]) is None


def test_the_recipes_are_drawn_with_the_seed_and_all_short():
    from scone_bt.recipes.recipe import load_recipe

    a, b = corpus_recipes(30, 7, 4), corpus_recipes(30, 7, 4)
    assert a == b and corpus_recipes(30, 8, 4) != a
    assert all(len(load_recipe(r).steps) <= 4 for r in a[:5])


def test_an_unknown_backend_is_one_line_before_an_episode_runs(monkeypatch, capsys):
    def never(*args: object, **kwargs: object) -> None:
        raise AssertionError("an episode ran")

    monkeypatch.setattr("scone_bt.episode.run_episode", never)
    assert main(["soak", "--robot", "nosuch", "--quiet"]) == 2
    assert capsys.readouterr().err == (
        "scone-bench: --robot 'nosuch': unknown robot backend; valid: mujoco, sim (the robot file is --arm)\n"
    )


def _soak_in_own_process(args: list[str], out) -> dict:
    """The soak's report from a process of its own, as a user runs it.

    Counted in the test worker's process, threads that earlier tests left winding down (a server's, a pool's) ended
    mid-soak: 22 threads after one episode and 21 after the next, with nothing of the soak's own changing.
    """
    done = subprocess.run([sys.executable, "-m", "scone_bt.cli.bench", *args], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr[-2000:]
    return json.loads(out.read_text())


@pytest.mark.slow
@pytest.mark.timeout(2400)  # 20 short episodes: about 2 min on an idle 2-core machine, 18 at a load of 25
def test_twenty_episodes_leave_descriptors_and_threads_flat(tmp_path):
    out = tmp_path / "soak.json"
    args = ["soak", "--episodes", "20", "--warmup", "5", "--max-steps", "3", "--distractors", "1", "--quiet"]
    report = _soak_in_own_process([*args, "--json", str(out)], out)
    assert report["episodes_run"] == 20 and report["episodes_completed"] == 20
    rows = report["per_episode"]
    assert len(rows) == 20 and [r["episode"] for r in rows] == list(range(20))
    # After the warm-up (the models loaded, the store opened once), every episode ends with the same descriptors
    # and threads: a kitchen, a planner thread or a file an episode left open would add one per episode.
    assert {r["fds"] for r in rows[5:]} == {rows[4]["fds"]}
    assert {r["threads"] for r in rows[5:]} == {rows[4]["threads"]}
    assert report["fd_growth"] == 0 and report["thread_growth"] == 0
    # Each episode's world was its own: bodies are the scene, the arm and that episode's products, nothing kept.
    assert all(r["bodies"] > 0 for r in rows) and all(r["constraints"] <= 1 for r in rows)
    assert rows[-1]["outcomes"] >= rows[0]["outcomes"] and report["store_bytes_per_outcome"] > 0


@pytest.mark.slow
@pytest.mark.timeout(1200)  # 3 short recorded episodes: under a minute on an idle 2-core machine
def test_recorded_episodes_leave_no_threads_behind(tmp_path):
    # Every recording's rerun streams kept two threads each (four a recording) until the recorder freed them.
    out = tmp_path / "soak.json"
    args = ["soak", "--episodes", "3", "--warmup", "1", "--max-steps", "3", "--distractors", "1", "--record"]
    report = _soak_in_own_process([*args, "--quiet", "--json", str(out)], out)
    rows = report["per_episode"]
    assert report["record"] and all(r["recording_bytes"] > 100_000 for r in rows)
    assert {r["threads"] for r in rows} == {rows[0]["threads"]} and report["thread_growth"] == 0
    assert {r["fds"] for r in rows} == {rows[0]["fds"]}
