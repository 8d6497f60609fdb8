"""Bad input to scone-study and scone-bench study-analysis: one line naming the file, the flag and what is valid,
before any participant is simulated, any robot acts or any sampling starts; no file changed, nothing lost."""

from __future__ import annotations

import json
import sqlite3

import pytest

from scone_bt.errors import SconeError
from scone_bt.study import StudyLog, plan_session
from scone_bt.study.cli import main


def _one_line_error(capsys) -> str:
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    return err.strip()


# ------------------------------------------------------------------------------------------- simulate --memory
def test_simulate_memory_in_a_missing_folder_is_made_and_the_db_kept(tmp_path, capsys):
    db, memory = tmp_path / "sim2.db", tmp_path / "missingdir" / "mem.json"
    argv = ["simulate", "--participants", "2", "--fast", "--db", str(db), "--memory", str(memory)]
    assert main(argv) == 0, capsys.readouterr().err
    assert db.is_file() and json.loads(memory.read_text())["participants_run"] == 2


def test_simulate_memory_under_a_file_is_refused_before_the_run(tmp_path, capsys):
    (tmp_path / "afile").write_text("keep\n")
    db, memory = tmp_path / "sim.db", tmp_path / "afile" / "mem.json"
    assert main(["simulate", "--participants", "2", "--fast", "--db", str(db), "--memory", str(memory)]) == 2
    err = _one_line_error(capsys)
    assert err.startswith(f"scone-study: error: --memory {memory}:") and "is a file, not a folder" in err
    assert not db.exists() and (tmp_path / "afile").read_text() == "keep\n"


@pytest.mark.parametrize(
    "content", ['{"contrasts": [], "data": "SIMULATED"}\n', "not json at all\n"], ids=["json", "text"]
)
def test_simulate_memory_never_replaces_a_file_that_is_not_its_report(tmp_path, capsys, content):
    db, memory = tmp_path / "sim.db", tmp_path / "results.json"
    memory.write_text(content)
    assert main(["simulate", "--participants", "2", "--fast", "--db", str(db), "--memory", str(memory)]) == 2
    err = _one_line_error(capsys)
    assert err.startswith(f"scone-study: error: --memory {memory}:") and "not a memory report" in err
    assert "--force" not in err  # simulate has no --force: the message offers none
    assert memory.read_text() == content and not db.exists()


def test_simulate_memory_replaces_its_own_earlier_report(tmp_path, capsys):
    memory = tmp_path / "mem.json"
    for name in ("a.db", "b.db"):
        argv = [
            "simulate",
            "--participants",
            "2",
            "--fast",
            "--db",
            str(tmp_path / name),
            "--memory",
            str(memory),
        ]
        assert main(argv) == 0, capsys.readouterr().err
    assert json.loads(memory.read_text())["participants_run"] == 2


# ------------------------------------------------------------------------------------------- session design
def _study(path, sessions):
    """A real study log holding `sessions`: (participant, group, index, finished)."""
    with StudyLog(path) as log:
        for participant, group, index, finished in sessions:
            sid = log.start_session(plan_session(participant, group, index))
            if finished:
                log.end_session(sid, {})


def _session_rows(path) -> int:
    with sqlite3.connect(f"file:{path}?mode=ro", uri=True) as conn:
        return conn.execute("SELECT COUNT(*) FROM sessions").fetchone()[0]


@pytest.mark.parametrize(
    ("sessions", "argv", "expected"),
    [
        (
            [("P01", "A", 1, True)],
            ["--group", "A", "--session", "1"],
            "P01 already has session 1 (group A) in {db}; next: --session 2 --group A",
        ),
        (
            [("P01", "A", 1, True)],
            ["--group", "B", "--session", "2"],
            "P01 is in group A in {db} (session 1); next: --session 2 --group A",
        ),
        (
            [("P01", "A", 1, True)],
            ["--group", "B", "--session", "1"],
            "P01 is in group A in {db} (session 1); next: --session 2 --group A",
        ),
        (
            [("P01", "B", 1, True), ("P01", "B", 2, True)],
            ["--group", "B", "--session", "2"],
            "P01 already has both sessions (group B) in {db}; give a new participant id",
        ),
        (
            [("P02", "A", 1, True)],
            ["--group", "A", "--session", "2"],
            "P01 has no session 1 in {db}; next: --session 1 --group A or --group B",
        ),
        (
            [("P01", "A", 1, False)],
            ["--group", "A", "--session", "2"],
            "P01 has no finished session 1 in {db} (it was interrupted); next: --session 1 --group A",
        ),
    ],
    ids=[
        "repeat",
        "other-group",
        "other-group-session-1",
        "both-done",
        "session-2-first",
        "session-1-interrupted",
    ],
)
def test_a_session_that_breaks_the_crossover_is_refused_before_the_robot_acts(
    tmp_path, capsys, monkeypatch, sessions, argv, expected
):
    from scone_bt.study import ui

    def never(*args, **kwargs):
        raise AssertionError("the tablet was served: the session began")

    monkeypatch.setattr(ui, "serve_tablet", never)
    monkeypatch.delenv("SCONE_BT_DEBUG", raising=False)
    db = tmp_path / "S.db"
    _study(db, sessions)
    before = _session_rows(db)
    assert main(["session", "--db", str(db), "--participant", "P01", *argv, "--port", "0"]) == 2
    err = _one_line_error(capsys)
    assert err == "scone-study: error: " + expected.format(db=db)
    assert _session_rows(db) == before


def test_the_next_session_of_the_design_is_accepted():
    from scone_bt.study.design import check_next_session
    from scone_bt.study.log import SessionRow

    def row(i, participant, group, index, ended):
        condition = plan_session(participant, group, index).condition.value
        return SessionRow(i, participant, group, index, condition, False, 0.0, ended, {}, None)

    log = [row(1, "P01", "A", 1, 1.0), row(2, "P02", "B", 1, None)]
    check_next_session(plan_session("P01", "A", 2), log, "S.db")  # the other condition, same group
    check_next_session(plan_session("P02", "B", 1), log, "S.db")  # an interrupted session is run again
    check_next_session(plan_session("P03", "B", 1), log, "S.db")  # a new participant, either group
    with pytest.raises(SconeError, match="P02 is in group B"):
        check_next_session(plan_session("P02", "A", 1), log, "S.db")


# ------------------------------------------------------------------------------------------- study-analysis --out
@pytest.mark.parametrize("case", ["under-a-file", "earlier-results"])
def test_study_analysis_checks_its_out_folder_before_simulating_or_sampling(
    tmp_path, capsys, monkeypatch, case
):
    from scone_bt.cli.bench import main as bench_main
    from scone_bt.study import analysis, simulate

    def never(*args, **kwargs):
        raise AssertionError("ran before --out was checked")

    monkeypatch.setattr(simulate, "simulate_study", never)
    monkeypatch.setattr(analysis, "analyze", never)
    if case == "under-a-file":
        (tmp_path / "afile").write_text("keep\n")
        out = tmp_path / "afile" / "x"
    else:
        out = tmp_path / "analysis"
        out.mkdir()
        (out / "results.json").write_text('{"earlier": true}\n')
    assert bench_main(["study-analysis", "--out", str(out)]) == 2
    err = _one_line_error(capsys)
    assert f"--out {out}" in err
    assert ("is a file" if case == "under-a-file" else "--force") in err
    if case == "earlier-results":
        assert (out / "results.json").read_text() == '{"earlier": true}\n'


# ------------------------------------------------------------------------------------------- messages
@pytest.mark.parametrize(
    ("flag", "value", "expected"),
    [
        ("--chains", "0", "--chains 0: must be 1 or more"),
        ("--draws", "0", "--draws 0: must be 10 or more"),
        ("--tune", "-5", "--tune -5: must be 0 or more"),
        ("--cores", "0", "--cores 0: must be 1 or more"),
    ],
)
def test_sampler_settings_name_the_flag_and_value(tmp_path, capsys, flag, value, expected):
    db = tmp_path / "sim.db"
    argv = ["simulate", "--participants", "2", "--fast", "--db", str(db), "--analyze", str(tmp_path / "a")]
    assert main([*argv, flag, value]) == 2
    assert _one_line_error(capsys) == f"scone-study: error: {expected}"
    assert not db.exists()


def test_study_analysis_sampler_settings_are_checked_before_simulating(capsys, monkeypatch):
    from scone_bt.cli.bench import main as bench_main
    from scone_bt.study import simulate

    def never(*args, **kwargs):
        raise AssertionError("simulated before the sampler settings were checked")

    monkeypatch.setattr(simulate, "simulate_study", never)
    assert bench_main(["study-analysis", "--chains", "0"]) == 2
    assert _one_line_error(capsys) == "scone-bench: --chains 0: must be 1 or more"


def test_simulate_unknown_recipe_is_the_only_line(tmp_path, capsys):
    db = tmp_path / "r.db"
    assert main(["simulate", "--participants", "2", "--db", str(db), "--recipe", "example:nope"]) == 2
    captured = capsys.readouterr()
    assert captured.out == "" and captured.err.count("\n") == 1
    assert "unknown example recipe 'nope'; valid: example:hummus" in captured.err
    assert not db.exists()


def test_export_of_a_folder_says_it_is_a_folder(tmp_path, capsys):
    folder = tmp_path / "somefolder"
    folder.mkdir()
    assert main(["export", "--db", str(folder), "--out", str(tmp_path / "csv")]) == 2
    assert _one_line_error(capsys) == f"scone-study: error: --db {folder}: is a folder; give a file path"


@pytest.mark.parametrize("participant", ["", "  "])
def test_an_empty_participant_id_is_quoted_once(tmp_path, capsys, participant):
    db = tmp_path / "s.db"
    argv = ["session", "--db", str(db), "--participant", participant, "--group", "A", "--session", "1"]
    assert main(argv) == 2
    err = _one_line_error(capsys)
    assert f"unknown participant id {participant!r}; valid: any non-empty text, e.g. P01" in err
    assert not db.exists()


@pytest.mark.parametrize(
    ("argv", "expected"),
    [
        (["--recipe", "example:nosuch"], "--recipe: unknown example recipe 'nosuch'; valid: example:hummus"),
        (["--arm", "nosuch"], "--arm: unknown robot 'nosuch'; valid: iiwa7, panda"),
        # with --fast the synthetic episodes read neither: another value is refused as not read
        (["--fast", "--recipe", "example:nosuch"], "--recipe: only the physics episodes read it"),
        (["--fast", "--arm", "nosuch"], "--arm: only the physics episodes read it"),
    ],
)
def test_simulate_checks_the_recipe_and_arm_before_any_participant(tmp_path, capsys, argv, expected):
    db = tmp_path / "s.db"
    assert main(["simulate", "--participants", "2", "--db", str(db), *argv]) == 2
    err = capsys.readouterr().err
    assert expected in err and err.count("\n") == 1, err
    assert not db.exists()
