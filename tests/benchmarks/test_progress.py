"""Benchmarks that run for more than a few seconds show progress on stderr; stdout stays the JSON report."""

from __future__ import annotations

import json
from types import SimpleNamespace

import pytest

from scone_bt.cli.bench import main
from tests.benchmarks.test_catalogue import _corpus


def _report(out: str) -> dict:
    return json.loads(out)  # the whole of stdout is the report


@pytest.mark.parametrize("quiet", [False, True])
def test_catalogue_shows_progress_unless_quiet(tmp_path, capsys, quiet) -> None:
    corpus, labels = _corpus(tmp_path)
    argv = [
        "catalogue",
        "--corpus",
        str(corpus),
        "--pdr-labels",
        str(labels),
        *(["--quiet"] if quiet else []),
    ]
    assert main(argv) == 0
    out, err = capsys.readouterr()
    assert _report(out)["recipes"] == 2
    assert ("recipes" in err and "stocking" in err) is not quiet
    assert err == "" if quiet else err


def _summary(recipe: str) -> SimpleNamespace:
    return SimpleNamespace(
        completed=True, steps_completed=1, steps_total=1, decisions=1, attempted=1, successes=1,
        help_requests=0, sim_time=10.0, wall_time=1.0, startup_to_first_decision_s=0.5, physics_steps=1,
        physics_steps_skipped=0, renders=1, wall_breakdown={"tree": 1.0}, cpu_breakdown={"tree": 1.0},
    )  # fmt: skip


@pytest.mark.parametrize("quiet", [False, True])
def test_episode_shows_which_episode_runs_unless_quiet(monkeypatch, capsys, quiet) -> None:
    import scone_bt.episode

    ran: list[str] = []

    def fake_run_episode(options, printer, **kwargs):  # noqa: ANN001, ANN003, ANN202
        ran.append(options.recipe)
        return _summary(options.recipe)

    monkeypatch.setattr(scone_bt.episode, "run_episode", fake_run_episode)
    argv = [
        "episode",
        "--recipes",
        "example:hummus,example:pancakes",
        "--no-cold",
        *(["--quiet"] if quiet else []),
    ]
    assert main(argv) == 0
    out, err = capsys.readouterr()
    assert ran == ["example:hummus", "example:pancakes"]
    assert [e["recipe"] for e in _report(out)["episodes"]] == ran
    assert ("episodes" in err and "example:pancakes" in err) is not quiet
    assert err == "" if quiet else err


@pytest.mark.parametrize("quiet", [False, True])
def test_core_shows_its_stages_unless_quiet(monkeypatch, capsys, tmp_path, quiet) -> None:
    import scone_bt.benchmarks.core as core
    from scone_bt.embedding import load_embedder

    onehot = load_embedder("onehot", tmp_path)
    monkeypatch.setattr(core, "load_embedder", lambda name, cache_dir: onehot)  # no model loads in a test
    monkeypatch.setattr(core, "mpnet_dir", lambda: None)
    monkeypatch.setattr(core, "ESTIMATORS", ("knn",))
    assert main(["core", "--quick", *(["--quiet"] if quiet else [])]) == 0
    out, err = capsys.readouterr()
    assert set(_report(out)["embedding"]) == {"minilm", "glove", "onehot"}
    assert ("core" in err and "recipe-aware path" in err) is not quiet
    assert err == "" if quiet else err
