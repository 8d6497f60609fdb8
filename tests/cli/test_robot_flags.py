"""--robot is the backend and --arm the robot file, in every command (scone-run, scone-bench, scone-scenario,
scone-study)."""

from __future__ import annotations

import argparse

import pytest

from scone_bt.cli import bench
from scone_bt.cli.run import build_parser as run_parser
from scone_bt.errors import SconeError
from scone_bt.robot import flags as robot_options
from scone_bt.robot import registry
from scone_bt.scenario import cli as scenario_cli
from scone_bt.study.cli import build_parser as study_parser


def _leaves(parser: argparse.ArgumentParser, path: str = "") -> dict[str, argparse.ArgumentParser]:
    subs = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
    if not subs:
        return {path: parser}
    out: dict[str, argparse.ArgumentParser] = {}
    for action in subs:
        for name, child in action.choices.items():
            out.update(_leaves(child, f"{path} {name}".strip()))
    return out


def _every_command() -> dict[str, argparse.ArgumentParser]:
    commands = {"scone-run": run_parser()}
    commands.update({f"scone-bench {k}": p for k, p in _leaves(bench._parser()).items()})
    commands.update({f"scone-study {k}": p for k, p in _leaves(study_parser()).items()})
    commands.update({f"scone-scenario {k}": p for k, p in _leaves(scenario_cli._parser()).items()})
    return commands


def _option(parser: argparse.ArgumentParser, flag: str) -> argparse.Action | None:
    return next((a for a in parser._actions if flag in a.option_strings), None)


def test_robot_is_a_backend_and_arm_a_robot_file_in_every_command() -> None:
    with_robot = []
    for name, parser in _every_command().items():
        robot, arm = _option(parser, "--robot"), _option(parser, "--arm")
        if robot is not None:
            with_robot.append(name)
            # a scenario command's default is None: each file's world.robot names its backend
            assert robot.default is None or robot.default in registry.BACKENDS, name
            assert "backend" in (robot.help or ""), name
        if arm is not None:
            assert robot is not None, f"{name}: --arm without --robot"
            # a scenario command's default is None: each file's world.arm names its robot file
            assert arm.default == ("panda" if robot.default is not None else None), name
    # the commands that build a robot: each has the backend flag
    for name in (
        "scone-run",
        "scone-bench episode",
        "scone-bench perception",
        "scone-bench sc generate",
        "scone-bench gate",
        "scone-bench scale",
        "scone-bench decisions",
        "scone-bench motion",
        "scone-bench physics",
        "scone-study session",
        "scone-study simulate",
        "scone-scenario run",
        "scone-bench scenarios",
    ):
        assert name in with_robot, name


def test_a_backend_added_to_the_registry_is_accepted_by_name(monkeypatch) -> None:
    monkeypatch.setitem(registry.BACKENDS, "other", registry.BACKENDS["sim"])
    assert robot_options.check_backend("other") == "other"
    with pytest.raises(
        SconeError, match=r"^--robot 'nosuch': unknown robot backend; valid: mujoco, other, sim "
    ):
        robot_options.check_backend("nosuch")


def test_episodes_run_on_the_named_backend(monkeypatch, capsys) -> None:
    """scone-bench episode hands --robot to run_episode's backend factory and --arm to the robot file."""
    monkeypatch.setitem(registry.BACKENDS, "other", registry.BACKENDS["sim"])
    seen = []

    def capture(options, **kwargs):
        seen.append(options)
        raise SconeError("stop here")

    monkeypatch.setattr("scone_bt.episode.run_episode", capture)
    assert bench.main(["episode", "--robot", "other", "--arm", "iiwa7", "--recipes", "example:hummus"]) == 2
    assert "stop here" in capsys.readouterr().err
    assert seen[0].backend == "other" and seen[0].arm == "iiwa7"


@pytest.mark.parametrize(
    ("argv", "says"),
    [
        (["perception", "--scenes", "1"], "it renders on sim (PyBullet) or mujoco"),
        (["sc", "generate", "--executions", "1"], "the generator runs on sim, mujoco"),
        (["scale", "--executions", "1"], "only --robot sim is supported"),
        (["motion", "--queries", "1"], "only --robot sim is supported"),
        (["physics", "--queries", "1"], "only --robot sim is supported"),
    ],
)
def test_benchmarks_that_build_an_engine_directly_refuse_another_backend(
    argv, says, monkeypatch, capsys
) -> None:
    monkeypatch.setitem(registry.BACKENDS, "other", registry.BACKENDS["sim"])
    assert bench.main([*argv, "--robot", "other"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--robot other" in err and says in err


@pytest.mark.parametrize("command", [["episode"], ["sc", "generate"], ["gate", "--no-replay"]])
def test_a_robot_file_given_to_robot_in_scone_bench_says_to_use_arm(command, capsys) -> None:
    assert bench.main([*command, "--robot", "robots/iiwa7.yaml"]) == 2
    err = capsys.readouterr().err
    assert err == (
        "scone-bench: --robot 'robots/iiwa7.yaml': --robot names the robot backend (mujoco, sim); "
        "give the robot file with --arm robots/iiwa7.yaml\n"
    )


def test_scone_study_robot_is_the_backend(tmp_path, capsys) -> None:
    from scone_bt.study.cli import main

    code = main(["simulate", "--db", str(tmp_path / "s.db"), "--participants", "2", "--robot", "panda"])
    assert code == 2
    err = capsys.readouterr().err
    assert "--robot 'panda'" in err and "--arm panda" in err and err.count("\n") == 1


def test_a_robot_file_given_to_robot_in_scone_scenario_says_to_use_arm(capsys) -> None:
    assert scenario_cli.main(["run", "scenarios/", "--robot", "robots/iiwa7.yaml"]) == 2
    err = capsys.readouterr().err
    assert err == (
        "scone-scenario: --robot 'robots/iiwa7.yaml': --robot names the robot backend (mujoco, sim); "
        "give the robot file with --arm robots/iiwa7.yaml\n"
    )


def test_scone_bench_scenarios_refuses_an_unknown_arm_in_one_line(capsys) -> None:
    assert bench.main(["scenarios", "--arm", "nosuch"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "nosuch" in err and "iiwa7, panda" in err


def _help(argv: list[str], build: object, capsys: pytest.CaptureFixture[str]) -> str:
    with pytest.raises(SystemExit):
        build().parse_args([*argv, "--help"])  # type: ignore[operator]
    return " ".join(capsys.readouterr().out.split())


def test_help_says_each_default_once_and_only_where_it_means_something(capsys) -> None:
    session = _help(["session"], study_parser, capsys)
    assert "(default: None)" not in session and "(default: False)" not in session
    assert session.count("(default: hidden;") == 1 and "(default: 8765)" in session
    motion = _help(["motion"], bench._parser, capsys)
    assert "the robot file is --arms" in motion  # the flag this benchmark has


def test_the_defaults_formatter_keeps_a_real_default_and_drops_the_noise() -> None:
    from scone_bt.argparsing import DefaultsHelpFormatter

    p = argparse.ArgumentParser(prog="x", formatter_class=DefaultsHelpFormatter)
    p.add_argument("--port", type=int, default=8765, help="port")
    p.add_argument("--db", required=True, help="log")
    p.add_argument("--token", default=None, help="token")
    p.add_argument("--fast", action="store_true", help="fast")
    p.add_argument("--out", default="x.db", help="file (default: a temporary file)")
    text = " ".join(p.format_help().split())
    assert "port (default: 8765)" in text and "log --token" in text and "token --fast" in text
    assert "fast --out" in text and text.count("default") == 2


@pytest.mark.parametrize(
    ("build", "argv"),
    [
        (run_parser, ["--seed", "abc"]),
        (bench._parser, ["gate", "--warmup", "x"]),
        (bench._parser, ["no-such-benchmark"]),
        (study_parser, ["session", "--db", "x.db"]),
        (scenario_cli._parser, ["run", "--jobs", "many"]),
    ],
)
def test_a_usage_error_is_one_line_in_every_command(build, argv, capsys) -> None:
    """argparse printed its whole usage block (9 to 23 lines) before the error."""
    with pytest.raises(SystemExit) as info:
        build().parse_args(argv)
    err = capsys.readouterr().err
    assert info.value.code == 2 and err.count("\n") == 1 and ": error: " in err, err
    assert err.endswith("(--help lists the options)\n")
