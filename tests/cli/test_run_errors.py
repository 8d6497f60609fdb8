"""Bad input to scone-run: one line on stderr, exit status 2, no traceback."""

import sys

import pytest

from scone_bt.cli.run import main


@pytest.mark.parametrize(
    ("argv", "expected"),
    [
        (["--arm", "no_such_arm"], "panda"),
        (["--recipe", "example:nope"], "example:tomato-pasta"),
        (["--tree", "no_such_tree"], "assistive_cooking"),
        (["--confidence-threshold", "1.5"], "[0, 1]"),
    ],
)
def test_bad_arguments_give_one_line(argv, expected, capsys):
    assert main(["--robot", "sim", *argv]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("scone-run: error:") and expected in err
    assert "\n" not in err and "Traceback" not in err


def test_bad_backend_is_one_line_naming_the_backends(capsys):
    assert main(["--robot", "real"]) == 2
    err = capsys.readouterr().err
    assert (
        err
        == "scone-run: error: --robot 'real': unknown robot backend; valid: mujoco, sim (the robot file is --arm)\n"
    )


@pytest.mark.parametrize("robot_file", ["panda", "robots/panda.yaml", "mine.yml"])
def test_a_robot_file_given_to_robot_says_to_use_arm(robot_file, capsys):
    assert main(["--robot", robot_file]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"--robot {robot_file!r}" in err and f"--arm {robot_file}" in err
    assert "valid" not in err or "sim" in err


# ---------------------------------------------------------------------------------------------- issue 18: hostile input
import socket  # noqa: E402
import threading  # noqa: E402
from pathlib import Path  # noqa: E402

REPO = Path(__file__).resolve().parents[2]


def _one_line_error(argv, capsys) -> str:
    code = main(["--robot", "sim", "--quiet", "--max-ticks", "1", *argv])  # bounded if no error came
    out = capsys.readouterr()
    err = out.err.strip()
    assert code == 2, (code, err)
    assert err.startswith("scone-run: error:") and "\n" not in err and "Traceback" not in err, err
    assert out.out == ""  # nothing ran: no decision, no summary
    return err


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.mark.parametrize(
    ("argv", "expected"),
    [
        (["--seed", "-1"], "0..4294967295"),
        (["--seed", str(2**40)], "0..4294967295"),
        (["--ui-port", "99999"], "0..65535"),
        (["--ui", "--ui-port", "99999"], "0..65535"),
        (["--max-ticks", "0"], "1.."),
        (["--distractors", "-3"], "0 or more"),
        (["--takeover-probability", "nan"], "[0, 1]"),
        (["--relevance-threshold", "7"], "[-1, 1]"),
        (["--connect", "not-an-address"], "no port"),
        (["--connect", "ftp://127.0.0.1:9876"], "valid: rerun"),
        (["--distractors", "1000"], "available"),
        # a mistyped store URL was an SQLite file named "postgresq:/u@host/db" in the working folder
        (
            ["--experience", "postgresq://u@127.0.0.1:1/db"],
            "unknown URL scheme 'postgresq'; valid: postgresql://",
        ),
        (["--experience", "sqlite:///runs/x.db"], "unknown URL scheme 'sqlite'"),
    ],
)
def test_bad_values_are_one_line_errors(argv, expected, capsys):
    assert expected in _one_line_error(argv, capsys)


@pytest.mark.parametrize(
    ("argv", "expected"),
    [
        (
            ["--robot-id", "panda-2"],
            "--robot-id panda-2: it only applies to an outcome store; give --experience",
        ),
        (
            ["--learn-from", "fleet"],
            "--learn-from fleet: it only applies to an outcome store; give --experience",
        ),
        (["--profile", "p01"], "--profile p01: it labels the outcomes stored; give --experience"),
        (["--force"], "--force: it lets --save replace a file, and no --save was given"),
        (["--ui", "--takeover-probability", "0.5"], "--takeover-probability 0.5: with --ui the person"),
    ],
)
def test_an_option_this_run_would_not_read_is_refused(argv, expected, capsys):
    """One meaning per flag: these were accepted and ignored."""
    assert expected in _one_line_error(argv, capsys)


def test_a_default_typed_out_is_not_refused_as_unread():
    from scone_bt.cli.run import _check_flags_read, build_parser

    for argv in (["--learn-from", "self"], ["--ui", "--takeover-probability", "0"], ["--profile", ""]):
        _check_flags_read(build_parser().parse_args(argv))


@pytest.mark.parametrize(
    ("flag", "what", "valid"),
    [
        ("--arm", "robot", "iiwa7, panda"),
        ("--kitchen", "kitchen", "kitchen"),
        ("--tree", "tree", "assistive_cooking"),
    ],
)
def test_a_missing_file_path_is_named_as_a_missing_file(tmp_path, capsys, flag, what, valid):
    for missing in ("nofile.yaml", str(tmp_path / "nofile")):
        assert _one_line_error([flag, missing], capsys) == (
            f"scone-run: error: {flag} {missing}: no such file; give a {what} name (valid: {valid}) "
            f"or a path to a {what} YAML file"
        )


def test_connect_to_a_viewer_that_is_not_running_fails_fast(capsys):
    result: list[str] = []
    port = _free_port()
    worker = threading.Thread(
        target=lambda: result.append(_one_line_error(["--connect", f"127.0.0.1:{port}"], capsys))
    )
    worker.start()
    worker.join(60)
    assert not worker.is_alive(), "--connect to an address without a viewer hangs"
    assert "cannot reach a rerun viewer" in result[0]


def test_output_paths_are_checked_before_the_run(tmp_path, capsys):
    blocker = tmp_path / "a-file"
    blocker.write_text("keep me")
    err = _one_line_error(["--save", str(blocker / "run.rrd")], capsys)
    assert "is a file, not a folder" in err
    err = _one_line_error(["--experience", str(blocker / "x" / "exp.db")], capsys)
    assert "is a file, not a folder" in err
    assert "is a folder" in _one_line_error(["--save", str(tmp_path)], capsys)
    assert blocker.read_text() == "keep me" and sorted(p.name for p in tmp_path.iterdir()) == ["a-file"]


def _edited(tmp_path: Path, source: Path, old: str, new: str) -> Path:
    text = source.read_text()
    assert old in text
    out = tmp_path / source.name
    out.write_text(text.replace(old, new, 1))
    return out


@pytest.mark.parametrize(
    ("old", "new", "expected"),
    [
        (
            "name: RRTConnect",
            "name: NoSuchPlanner",
            "planner.name: unknown planner 'NoSuchPlanner'; valid: RRTConnect",
        ),
        ("rate_hz: 240", "rate_hz: 0", "control.rate_hz: Input should be greater than 0"),
        ("max_force: 40.0 ", "max_force: -5.0 ", "gripper.max_force: Input should be greater than 0"),
        ("finger_friction: 1.0", "finger_friction: -0.2", "gripper.finger_friction"),
        ("time_limit_s: 2.0", "time_limit_s: soon", "planner.time_limit_s: Input should be a valid number"),
    ],
)
def test_bad_robot_files_stop_before_the_robot_acts(tmp_path, capsys, old, new, expected):
    arm = _edited(tmp_path, REPO / "robots" / "panda.yaml", old, new)
    db = tmp_path / "exp.db"
    err = _one_line_error(["--arm", str(arm), "--experience", str(db)], capsys)
    assert expected in err and str(arm) in err
    assert not db.exists()  # a configuration error is not an outcome: nothing stored, nothing created


@pytest.mark.parametrize(
    ("old", "new", "expected"),
    [
        ("{seconds: 1.0}", "{seconds: soon}", "seconds: Input should be a valid number (got 'soon')"),
        ("{kind: ask}", "{kind: maybe}", "unknown decision kind 'maybe'; valid: act, ask"),
        ("confidence_threshold: 0.5", "confidence_threshold: high", "confidence_threshold"),
        ("max_failures_per_action: 1", "max_failures_per_action: many", "max_failures_per_action"),
        ("behaviour: AskForHelp", "behaviour: AskForHelp\n                  args: {x: 1}", "takes no args"),
    ],
)
def test_bad_tree_files_stop_before_the_first_tick(tmp_path, capsys, old, new, expected):
    tree = _edited(tmp_path, REPO / "trees" / "assistive_cooking.yaml", old, new)
    assert expected in _one_line_error(["--tree", str(tree)], capsys)


@pytest.mark.parametrize(
    ("content", "expected"),
    [
        ('{"ingredients": ["salt"], "steps": ["Salt it."]}'.encode("utf-16"), "UTF-16"),
        (bytes(range(128, 256)) * 4, "not UTF-8"),
        (b'{"ingredients": ["salt"], "steps": ["Salt it."], "step_ingredients": [5]}', "step_ingredients[0]"),
        (b'{"ingredients": ["salt"], "steps": ["Salt it."', "not valid JSON"),
        (b"", "not valid JSON"),
    ],
)
def test_bad_recipe_files_are_one_line_errors(tmp_path, capsys, content, expected):
    recipe = tmp_path / "recipe.json"
    recipe.write_bytes(content)
    assert expected in _one_line_error(["--recipe", str(recipe)], capsys)
    assert recipe.read_bytes() == content


@pytest.mark.slow
def test_a_planner_bug_stops_the_run_and_stores_nothing(tmp_path, capsys, monkeypatch):
    """A program error is not an outcome: the run stops with one line and the store holds no outcome of it."""
    import scone_bt.motion.system as system
    from scone_bt.experience import ExperienceStore

    def broken_planner(*args, **kwargs):  # a bug inside planning, as a crash in OMPL or our IK would be
        raise RuntimeError("simulated planner bug")

    monkeypatch.setattr(system, "plan_pick_and_place", broken_planner)
    db = tmp_path / "exp.db"
    argv = ["--robot", "sim", "--recipe", "example:hummus", "--distractors", "0", "--no-self-confidence"]
    code = main([*argv, "--experience", str(db), "--max-ticks", "600", "--seed", "3"])
    out = capsys.readouterr()
    err = out.err.strip()
    assert code == 3, (code, err, out.out[-500:])
    assert (
        err.startswith("scone-run: internal error: RuntimeError: simulated planner bug") and "\n" not in err
    )
    assert "failure at planning" not in out.out  # not reported as the robot's failure...
    with ExperienceStore(db) as store:
        assert len(store) == 0  # ...and not learnt from


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="the display check is X/Wayland's")
def test_gui_without_a_display_is_one_line_not_a_silent_exit(monkeypatch, capsys):
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    assert "--gui: no display to open PyBullet's window on" in _one_line_error(["--gui"], capsys)


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="the display check is X/Wayland's")
def test_viewer_without_a_display_names_viewer_not_connect(monkeypatch, capsys):
    """It used to spawn a viewer that died at once, wait 5 s, and blame --connect, a flag never given."""
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    err = _one_line_error(["--viewer"], capsys)
    assert "--viewer: no display to open rerun's viewer on" in err
    assert "--connect rerun+http" not in err


@pytest.mark.parametrize("robot_id", ["", "   ", "panda 2", "x" * 65])
def test_a_robot_id_that_no_query_would_match_is_one_line(robot_id, capsys):
    """'   ' was stored as the robot's id in a shared store; '' silently meant the arm's name."""
    from scone_bt.cli.run import main

    with pytest.raises(SystemExit) as done:
        main(["--robot-id", robot_id, "--max-ticks", "1"])
    assert done.value.code == 2
    err = capsys.readouterr().err
    assert "--robot-id" in err and "1 to 64 letters, digits" in err and err.count("\n") == 1


@pytest.mark.parametrize(
    ("embedder", "expected"),
    [
        ("{dir}", "not a model directory (no modules.json or config.json, nor a fine-tuned head)"),
        ("finetuned:{dir}", "not a fine-tuned embedder (needs finetuned.json and head.safetensors)"),
    ],
)
def test_an_embedder_folder_the_loader_cannot_read_is_refused_before_the_kitchen(
    embedder, expected, tmp_path, capsys
):
    """It passed the check and failed after the kitchen was built and the episode's header printed."""
    err = _one_line_error(["--embedder", embedder.format(dir=tmp_path)], capsys)
    assert err.startswith("scone-run: error: --embedder") and expected in err


def test_a_fine_tuned_folder_is_an_embedder_with_or_without_its_prefix(tmp_path):
    """The loader reads a bare folder holding a fine-tuned head too (registry.load_embedder)."""
    from scone_bt.cli.run import _check_embedder

    for name in ("finetuned.json", "head.safetensors"):
        (tmp_path / name).write_text("{}")
    _check_embedder(str(tmp_path))
    _check_embedder(f"finetuned:{tmp_path}")
