"""scone-run's words match what it accepts (issue 27, part of 7), deadlines are stated in --help, and other
libraries' log lines go through --log-level, never raw into the decision lines."""

from __future__ import annotations

import logging
import socket
import threading

import pytest

from scone_bt.cli.run import build_parser, configure_logging, main
from scone_bt.errors import ExperienceStoreError
from scone_bt.experience.postgres import PostgresExperienceStore
from scone_bt.resources import data_dir


def _one_line(argv: list[str], capsys) -> str:  # noqa: ANN001
    assert main(["--quiet", "--max-ticks", "1", *argv]) == 2
    out = capsys.readouterr()
    assert out.out == ""  # refused before the header: the kitchen was not built
    err = out.err.strip()
    assert err.startswith("scone-run: error:") and "\n" not in err
    return err


def test_help_names_what_arm_accepts_and_states_the_deadlines():
    text = " ".join(build_parser().format_help().split())
    names = sorted(p.stem for p in data_dir("robots").glob("*.yaml"))
    assert f"robots/ ({', '.join(names)})" in text  # e.g. iiwa7, not "iiwa"
    assert "within 2 s" in text and "within 3 s" in text  # --connect: TCP and gRPC answer
    assert "within 10 s" in text  # --experience postgresql://
    assert "--log-level" in text and "--force" in text


@pytest.mark.parametrize(
    ("argv", "expected"),
    [
        (["--estimator", "knnn"], "did you mean knn"),
        (["--estimator", "eps-foo"], "eps-<name>"),
        (["--embedder", "minlm"], "valid: minilm"),
        (["--embedder", "finetuned:/no/such/dir"], "no such folder"),
    ],
)
def test_estimator_and_embedder_are_checked_before_the_kitchen(argv, expected, capsys):
    assert expected in _one_line(argv, capsys)


def test_valid_estimators_pass_the_check(capsys):
    from scone_bt.cli.run import _check_estimator

    for name in ("eps-knn", "grounded-knn", "knn-cal", "grounded-gp-cal", "xgboost"):
        _check_estimator(name)


def test_a_postgres_server_that_never_answers_is_an_error_within_the_deadline():
    srv = socket.socket()
    srv.bind(("127.0.0.1", 0))
    srv.listen(4)
    kept: list[socket.socket] = []
    threading.Thread(target=lambda: kept.append(srv.accept()[0]), daemon=True).start()
    url = f"postgresql://robot@127.0.0.1:{srv.getsockname()[1]}/scone"
    result: list[BaseException] = []

    def connect() -> None:
        try:
            PostgresExperienceStore(url, connect_timeout_s=2)
        except ExperienceStoreError as exc:
            result.append(exc)

    worker = threading.Thread(target=connect, daemon=True)
    worker.start()
    worker.join(60)
    srv.close()
    assert not worker.is_alive(), "hangs"
    assert result and "cannot connect" in str(result[0]) and "\n" not in str(result[0])


def test_uvicorn_lines_go_through_the_log_level(capsys):
    from scone_bt.study.ui import serve_tablet

    def garbage(port: int) -> None:
        with socket.create_connection(("127.0.0.1", port), timeout=10) as s:
            s.sendall(b"\x16\x03\x01 not http at all\r\n\r\n")
            s.recv(1024)

    try:
        configure_logging("WARNING")
        with serve_tablet("127.0.0.1", 0, None) as server:
            garbage(server.port)  # uvicorn logs the line before it answers 400
        err = capsys.readouterr().err
        lines = [line for line in err.splitlines() if "Invalid HTTP request" in line]
        assert lines == ["scone-run: warning: uvicorn.error: Invalid HTTP request received."], err
        configure_logging("ERROR")
        with serve_tablet("127.0.0.1", 0, None) as server:
            garbage(server.port)
        assert "Invalid HTTP request" not in capsys.readouterr().err
    finally:
        root = logging.getLogger()
        for handler in list(root.handlers):
            if type(handler).__name__ == "_StderrHandler":
                root.removeHandler(handler)
        root.setLevel(logging.WARNING)


def test_every_tree_default_the_help_states_is_the_tree_files() -> None:
    """--help says "(tree default: X)" for every decision option (one per tree parameter, derived from the
    model); X must be what the shipped tree file sets (it once named grounded-knn as the default estimator while
    the tree's was physical)."""
    import re

    import yaml

    from scone_bt.cli.tree_options import flag_of, option_fields
    from scone_bt.tree.build import load_tree_spec

    params = load_tree_spec().parameters
    dests = {flag_of(path): path for path, _ in option_fields()}
    stated = {}
    for action in build_parser()._actions:
        match = re.search(r"\(tree default: ([^)]+)\)", action.help or "")
        if match and action.option_strings:
            stated[action.option_strings[0]] = match.group(1)
    assert set(stated) == set(dests)
    for flag, path in dests.items():
        value = params[path[0]] if len(path) == 1 else params[path[0]][path[1]]  # probe: its section's key
        assert yaml.safe_load(stated[flag]) == value, flag  # as the tree file writes it


def test_a_recipe_that_needs_nothing_from_the_shelf_says_so(tmp_path, capsys):
    recipe = tmp_path / "water.yaml"
    recipe.write_text(
        "id: mine\ntitle: Just water\ningredients:\n  - 1 cup water\nsteps:\n  - Boil the water.\n"
    )
    assert main(["--recipe", str(recipe), "--max-ticks", "60", "--distractors", "0"]) == 0
    first = capsys.readouterr().out.splitlines()[0]
    assert first == "Just water: 1 steps, needs nothing from the shelf; distractors: none", first
