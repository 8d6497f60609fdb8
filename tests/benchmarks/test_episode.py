"""``scone-bench episode``: bad options are one line, before any episode runs."""

from __future__ import annotations

import pytest

from scone_bt.cli.bench import main


@pytest.mark.parametrize("ticks", ["0", "-5"])
def test_max_ticks_below_one_is_refused_before_an_episode_runs(monkeypatch, capsys, ticks):
    def never(*args: object, **kwargs: object) -> None:
        raise AssertionError("an episode ran")

    monkeypatch.setattr("scone_bt.episode.run_episode", never)
    assert main(["episode", "--max-ticks", ticks, "--quiet"]) == 2
    assert (
        capsys.readouterr().err == f"scone-bench: --max-ticks {ticks}: must be an integer in 1..1000000000\n"
    )


def test_an_unknown_robot_is_refused_before_an_episode_runs(monkeypatch, capsys):
    def never(*args: object, **kwargs: object) -> None:
        raise AssertionError("an episode ran")

    monkeypatch.setattr("scone_bt.episode.run_episode", never)
    assert main(["episode", "--arm", "nosuch", "--quiet"]) == 2
    assert capsys.readouterr().err == "scone-bench: --arm nosuch: unknown robot; valid: iiwa7, panda\n"
    # --robot is the backend in every command: a robot file there is told to use --arm
    assert main(["episode", "--robot", "panda", "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("scone-bench: --robot 'panda': --robot names the robot backend (mujoco, sim)")
    assert err.endswith("give the robot file with --arm panda\n") and err.count("\n") == 1


def test_an_unknown_recipe_is_refused_before_an_episode_or_its_progress_bar_starts(monkeypatch, capsys):
    """It failed inside the first episode, its line glued to the progress bar."""

    def never(*args: object, **kwargs: object) -> None:
        raise AssertionError("an episode ran")

    monkeypatch.setattr("scone_bt.episode.run_episode", never)
    assert main(["episode", "--recipes", "example:hummus,example:nosuch"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("scone-bench: --recipes: unknown example recipe 'nosuch'; valid: example:hummus"), (
        err
    )
    assert err.count("\n") == 1 and "episodes:" not in err
