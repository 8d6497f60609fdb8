"""The backend seam: a whole episode (the shipped tree, the real gate, relevance and κ̂, the simulated human) on a
backend with no simulator, `tests/episode/fake_backend.py`. Nothing of PyBullet, the simulated kitchen or the
simulated robot is imported for it: the episode sees the backend only through `Robot`, `World` and `Backend`."""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap
from dataclasses import replace
from pathlib import Path

import pytest

from scone_bt.behaviours import BehaviourOptions
from scone_bt.episode import EpisodeOptions, run_episode
from scone_bt.errors import ConfigError, UnknownNameError
from scone_bt.motion.types import FailureStage
from tests.episode.fake_backend import FakeScript, fake_backend

ROOT = Path(__file__).resolve().parents[2]

# What only the simulated backend may load: a fake episode that loads any of them is welded to the simulator.
# (The shelf's pure stocking geometry, which the episode plans with, is scone_bt.stocking.)
SIMULATOR_MODULES = (
    "pybullet",
    "pybullet_utils",
    "scone_bt.world",
    "scone_bt.world.kitchen",
    "scone_bt.world.visuals",
    "scone_bt.robot.sim",
)

_EPISODE = textwrap.dedent(
    """
    import json, sys
    from scone_bt.behaviours import BehaviourOptions
    from scone_bt.episode import EpisodeOptions, run_episode
    from scone_bt.motion.types import FailureStage
    from tests.episode.fake_backend import FakeScript, fake_backend

    built = []
    script = FakeScript(outcomes={"olive oil": (FailureStage.GRASP,)})
    options = EpisodeOptions(seed=0, behaviour=BehaviourOptions(seed=0, cache_dir=sys.argv[1]))
    summary = run_episode(options, printer=lambda line: None, backend=fake_backend(script, built))
    loaded = sorted(m for m in sys.modules if m in sys.argv[2:])
    print(json.dumps({
        "summary": summary.deterministic_part(),
        "loaded": loaded,
        "closed": built[0].robot.closed,
        "set_up": built[0].set_up,
        "advances": built[0].world.advances,
    }))
    """
)


def _options(tmp_path: Path, **behaviour: object) -> EpisodeOptions:
    return EpisodeOptions(seed=0, behaviour=BehaviourOptions(seed=0, cache_dir=tmp_path, **behaviour))


def _fake_episode(cache_dir: Path, watched: tuple[str, ...]) -> dict:
    """The fake episode in a fresh interpreter (this test session has imported most modules already): its
    summary and which of `watched` it loaded."""
    done = subprocess.run(
        [sys.executable, "-c", _EPISODE, str(cache_dir), *watched],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )
    assert done.returncode == 0, done.stderr[-3000:]
    return json.loads(done.stdout.strip().splitlines()[-1])


def test_a_whole_episode_runs_on_a_fake_backend_without_the_simulator(tmp_path) -> None:
    out = _fake_episode(tmp_path, SIMULATOR_MODULES)
    assert out["loaded"] == [], f"the fake episode loaded the simulator's modules: {out['loaded']}"
    summary = out["summary"]
    # the real tree decided, acted and learnt: successes, the scripted failure, and help where κ̂ fell
    assert summary["completed"] and all(summary["needed_on_table"].values())
    assert summary["decisions"] >= summary["attempted"] + summary["help_requests"]
    assert summary["successes"] >= 1 and summary["failures_by_stage"] == {"grasp": 1}
    assert summary["attempted"] == summary["successes"] + summary["failures"] + summary["takeovers"]
    assert any("ACT" in line for line in summary["decision_log"])
    # the episode went through the backend's protocols: set up, the world's clock, closed at the end
    assert out["set_up"] and out["closed"] and out["advances"] == summary["control_ticks"]


def test_a_seeded_fake_episode_repeats_exactly(tmp_path) -> None:
    runs = [
        run_episode(
            _options(tmp_path), printer=lambda _line: None, backend=fake_backend()
        ).deterministic_part()
        for _ in range(2)
    ]
    assert runs[0] == runs[1] and runs[0]["successes"] >= 1


def test_scripted_infeasibility_and_failures_reach_the_gate(tmp_path) -> None:
    built: list = []
    script = FakeScript(
        infeasible=frozenset({"salt"}),
        outcomes={"garlic": (FailureStage.GRASP, FailureStage.TRANSIT)},
    )
    summary = run_episode(_options(tmp_path), printer=lambda _line: None, backend=fake_backend(script, built))
    robot = built[0].robot
    assert "salt" not in robot.attempts, "a product the planner calls infeasible is never attempted"
    assert any("salt" in line and "infeasible" in line for line in summary.decision_log)
    assert summary.failures_by_stage.get("grasp") == 1
    assert summary.completed, "the human brings what the robot could not"


def test_the_human_fetches_through_the_world(tmp_path) -> None:
    built: list = []
    # every attempt fails: whatever reaches the table, the human brought through World.place_on_table
    always = dict.fromkeys(
        ("salt", "spaghetti", "olive oil", "garlic", "crushed tomatoes", "parmesan"),
        (FailureStage.GRASP,) * 9,
    )
    summary = run_episode(
        _options(tmp_path),
        printer=lambda _line: None,
        backend=fake_backend(FakeScript(outcomes=always), built),
    )
    assert summary.successes == 0 and summary.failures >= 1
    assert summary.completed and built[0].world.on_table >= set(summary.needed_on_table)


def test_an_unknown_backend_is_refused_by_name(tmp_path) -> None:
    options = EpisodeOptions(backend="ros2")
    with pytest.raises(UnknownNameError, match="robot backend 'ros2'; valid: mujoco, sim"):
        run_episode(options, printer=lambda _line: None)


def test_a_backend_without_a_scene_cannot_be_recorded(tmp_path) -> None:
    built: list = []
    options = EpisodeOptions(
        seed=0, save=tmp_path / "run.rrd", behaviour=BehaviourOptions(cache_dir=tmp_path)
    )
    with pytest.raises(ConfigError, match="cannot be recorded"):
        run_episode(options, printer=lambda _line: None, backend=fake_backend(built=built))
    assert built[0].robot.closed, "the backend is released when the episode is refused"


def test_a_whole_episode_imports_no_scientific_stack_for_its_self_confidence(tmp_path) -> None:
    # κ̂'s logistic regression is numpy (confidence.logistic): scikit-learn, scipy and pandas cost ~1.5 s at the
    # first refit. The episode has outcomes of both kinds, so κ̂ is fitted. The first run fills the embedding cache
    # (a cold one loads the sentence model, which imports them all); the second runs from the warm cache.
    heavy = ("sklearn", "scipy", "pandas", "torch")
    _fake_episode(tmp_path, heavy)
    out = _fake_episode(tmp_path, heavy)
    assert out["summary"]["successes"] > 0 and out["summary"]["failures"] > 0, out["summary"]
    assert out["loaded"] == [], f"the episode imported {out['loaded']}"


def test_after_none_of_those_a_fetch_past_the_last_step_is_not_called_every_step_served(tmp_path) -> None:
    """The human says "none of those" to the cheese question: the robot is past the last step, yet still fetches
    the card's cheeses (needed later). Such a line names them as the card's items, not "(every step is served)"."""
    from scone_bt.behaviours.gate_steps import CARD_ITEMS_LEFT, EVERY_STEP_SERVED
    from scone_bt.human import ClarifyAnswer, HumanOptions

    lines: list[str] = []
    options = replace(
        _options(tmp_path),
        recipe=str(ROOT / "scenarios" / "recipes" / "cheddar-or-swiss.yaml"),
        human=HumanOptions(clarify_answer=ClarifyAnswer.NONE),
    )
    summary = run_episode(options, printer=lines.append, backend=fake_backend(FakeScript(), []))
    assert summary.clarifications == 1
    decisions = [line for line in lines if line.startswith("[step")]
    past = [line for line in decisions if CARD_ITEMS_LEFT in line]
    assert past and all("cheese on table" in line and "(needed later)" in line for line in past)
    assert all("(none)" in line for line in decisions if EVERY_STEP_SERVED in line)


def test_a_tree_file_whose_reader_ticks_before_any_writer_is_named_in_the_error(tmp_path) -> None:
    """The shipped tree without its ConfidenceGate: the error named the node and the key, not the file."""
    import yaml

    from scone_bt.behaviours.base import BlackboardError

    tree = yaml.safe_load((ROOT / "trees" / "assistive_cooking.yaml").read_text(encoding="utf-8"))

    def without_gate(node: dict) -> dict:
        if "children" in node:
            kids = [c for c in node["children"] if c.get("behaviour") != "ConfidenceGate"]
            node["children"] = [without_gate(c) for c in kids]
        return node

    tree["root"] = without_gate(tree["root"])
    path = tmp_path / "no-gate.yaml"
    path.write_text(yaml.safe_dump(tree, sort_keys=False), encoding="utf-8")
    options = replace(_options(tmp_path), tree=str(path))
    with pytest.raises(BlackboardError, match=rf"^{path}: .* before anything wrote it: .*\(ConfidenceGate\)"):
        run_episode(options, printer=lambda _line: None, backend=fake_backend())
