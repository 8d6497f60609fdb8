import json

import pytest

from scone_bt.study.cli import main


def test_simulate_fast_then_analyze_writes_labelled_outputs(tmp_path, capsys):
    db, out = tmp_path / "sim.db", tmp_path / "analysis"
    args = ["simulate", "--participants", "6", "--fast", "--db", str(db), "--analyze", str(out)]
    assert (
        main(
            [
                *args,
                "--chains",
                "1",
                "--tune",
                "60",
                "--draws",
                "60",
                "--cores",
                "1",
                "--models",
                "interventions",
                "--model",
                "extended",
            ]
        )
        == 0
    )
    text = capsys.readouterr().out
    assert (
        "SIMULATED study: 6 participants" in text
        and "NOTE: these results come from SIMULATED participants" in text
    )
    result = json.loads((out / "results.json").read_text())
    assert result["data"] == "SIMULATED" and result["options"]["rope"] == [-0.18, 0.18]
    assert {c["parameter"] for c in result["contrasts"]} == {"b_C", "b_G", "b_S"}
    assert all(c["decision"] in ("accept", "reject", "undecided") for c in result["contrasts"])
    assert (out / "fig3.png").stat().st_size > 10_000
    assert (out / "scores.csv").read_text().splitlines()[1].startswith("SIMULATED,")
    assert main(["export", "--db", str(db), "--out", str(tmp_path / "csv")]) == 0
    assert "SIMULATED data" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["analyze", "--db", "nowhere.db"], "study log not found"),
        (["session", "--db", "x.db", "--participant", "P1", "--group", "C", "--session", "1"], "valid: A, B"),
        (["simulate", "--participants", "1", "--fast", "--db", "y.db"], "at least 2 participants"),
        (
            [
                "simulate",
                "--participants",
                "4",
                "--fast",
                "--db",
                "z.db",
                "--analyze",
                "o",
                "--models",
                "sus",
            ],
            "valid: interventions, mdmt",
        ),
        (
            [
                "simulate",
                "--participants",
                "4",
                "--fast",
                "--db",
                "w.db",
                "--analyze",
                "o",
                "--rope",
                "0.2",
                "-0.2",
            ],
            "ROPE must be",
        ),
    ],
)
def test_errors_are_one_line(argv, message, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("scone-study: error:") and message in err and "\n" not in err


def test_a_store_url_of_another_scheme_is_refused_not_made_a_file(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    argv = ["session", "--db", "s.db", "--participant", "P01", "--group", "A", "--session", "1"]
    assert main([*argv, "--experience", "postgresq://lab@db/fleet"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "unknown URL scheme 'postgresq'; valid: postgresql://" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == []


@pytest.mark.parametrize("experience", ["same", "study-log"])
def test_a_store_that_cannot_be_one_is_refused_before_a_session_row_exists(tmp_path, capsys, experience):
    """--experience naming the study log itself, or another study log: one line, and no session recorded."""
    import sqlite3

    from scone_bt.study.log import StudyLog

    db = tmp_path / "s.db"
    StudyLog(db).close()
    other = tmp_path / "other.db"
    StudyLog(other).close()
    store = db if experience == "same" else other
    argv = ["session", "--db", str(db), "--experience", str(store), "--participant", "P01", "--group", "A"]
    assert main([*argv, "--session", "1", "--no-questionnaire"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("scone-study: error: --experience"), err
    assert ("is the --db input" if experience == "same" else "SQLite database of something else") in err
    for path in (db, other):
        with sqlite3.connect(f"file:{path}?mode=ro", uri=True) as conn:
            assert conn.execute("SELECT COUNT(*) FROM sessions").fetchone()[0] == 0


@pytest.mark.parametrize(
    ("argv", "flag"),
    [
        (["simulate", "--fast", "--seed", "-1"], "--seed -1"),
        (["simulate", "--fast", "--participants", "1000000000"], "--participants 1000000000"),
        (["simulate", "--fast", "--jobs", "0"], "--jobs 0"),
        (["simulate", "--fast", "--jobs", "-2"], "--jobs -2"),
        (["simulate", "--fast", "--condition-effect", "nan"], "--condition-effect nan"),
        (["simulate", "--fast", "--condition-effect", "inf"], "--condition-effect inf"),
        (["simulate", "--fast", "--analyze", "/proc/x"], "--analyze /proc/x"),
        (["simulate", "--fast", "--memory", "/proc/x"], "--memory /proc/x"),
        (["simulate", "--fast", "--jobs", "2", "--memory", "never.json"], "--memory"),
        # one meaning per flag: options this mode would not read were accepted and ignored
        (["simulate", "--steps", "3"], "--steps"),
        (["simulate", "--fast", "--recipe", "example:pancakes"], "--recipe"),
        (["simulate", "--fast", "--distractors", "3"], "--distractors"),
        (["simulate", "--fast", "--chains", "3"], "--chains"),
        (["simulate", "--fast", "--rope", "0.2", "-0.2"], "--rope"),
    ],
)
def test_bad_simulate_options_are_one_line_before_any_file(argv, flag, tmp_path, capsys):
    db = tmp_path / "sim.db"
    assert main([*argv, "--db", str(db)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith(f"scone-study: error: {flag}:")
    assert not db.exists()


def test_an_option_simulate_would_not_read_says_what_reads_it(tmp_path, capsys):
    for argv, why in (
        (["--steps", "3"], "only the synthetic episodes read it; give --fast"),
        (
            ["--fast", "--robot", "mujoco"],
            "only the physics episodes read it, and --fast runs synthetic ones",
        ),
        (["--fast", "--model", "extended"], "only the analysis reads it; give --analyze DIR"),
    ):
        assert main(["simulate", *argv, "--db", str(tmp_path / "sim.db")]) == 2
        assert why in capsys.readouterr().err
    # a default given explicitly is no other value: accepted
    from scone_bt.study.analysis import AnalysisOptions
    from scone_bt.study.cli import _check_simulate_flags_read, build_parser

    rope = [str(x) for x in AnalysisOptions.rope]
    args = build_parser().parse_args(["simulate", "--fast", "--rope", *rope, "--steps", "5", "--db", "x.db"])
    _check_simulate_flags_read(args)


def test_power_refuses_a_negative_seed(tmp_path, capsys):
    assert main(["power", "--seed", "-1", "--out", str(tmp_path / "p")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--seed -1:" in err
    assert not (tmp_path / "p").exists()


def test_session_off_localhost_names_this_commands_flags(tmp_path, capsys):
    db = tmp_path / "s.db"
    argv = ["session", "--db", str(db), "--participant", "P01", "--group", "A", "--session", "1"]
    assert main([*argv, "--host", "0.0.0.0"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--host 0.0.0.0:" in err and "--token" in err
    assert "--ui-" not in err and not db.exists()


def test_analyze_never_replaces_its_ratings_file_even_with_force(tmp_path, capsys):
    folder = tmp_path / "csv2"
    folder.mkdir()
    ratings = folder / "scores.csv"
    ratings.write_text("participant,rating\nP01,3\n")
    assert main(["analyze", "--ratings", str(ratings), "--out", str(folder), "--force"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert ratings.read_text() == "participant,rating\nP01,3\n"
    # the output check itself, as the analysis runs it before sampling (after reading the ratings)
    from scone_bt.errors import SconeError
    from scone_bt.study.cli import _check_analysis_out

    with pytest.raises(SconeError, match="--ratings input"):
        _check_analysis_out(folder, "--out", True, {"--ratings": [ratings]})


def test_analyze_into_a_folder_that_cannot_be_written_fails_before_sampling(tmp_path, monkeypatch, capsys):
    from scone_bt.study import analysis

    def never(*args, **kwargs):
        raise AssertionError("sampled")

    monkeypatch.setattr(analysis, "analyze", never)
    db = tmp_path / "sim.db"
    assert main(["simulate", "--fast", "--participants", "2", "--db", str(db)]) == 0
    capsys.readouterr()
    assert main(["analyze", "--db", str(db), "--out", "/sys/kernel/mm"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("scone-study: error: --out /sys/kernel/mm:")


def test_a_failed_simulation_leaves_no_file_behind(tmp_path, monkeypatch, capsys):
    from scone_bt.study import simulate

    def broken(*args, **kwargs):
        raise RuntimeError("boom")

    monkeypatch.setattr(simulate, "simulate_participant", broken)
    monkeypatch.delenv("SCONE_BT_DEBUG", raising=False)
    db = tmp_path / "sim.db"
    assert main(["simulate", "--fast", "--participants", "2", "--db", str(db)]) == 3
    assert "nothing was stored" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


def test_simulate_memory_samples_the_process_after_each_participant(tmp_path, capsys):
    db, report = tmp_path / "sim.db", tmp_path / "memory.json"
    assert main(["simulate", "--fast", "--participants", "7", "--db", str(db), "--memory", str(report)]) == 0
    capsys.readouterr()
    data = json.loads(report.read_text())
    assert data["mode"] == "fast" and data["participants"] == 7 and data["sessions_run"] == 14
    assert [r["participant"] for r in data["per_participant"]] == list(range(7))
    assert all(r["rss_mb"] > 0 and r["fds"] > 0 and r["threads"] > 0 for r in data["per_participant"])
    assert data["warmup_participants"] == 5 and data["rss_growth_mb_per_session"] is not None
    assert data["fd_growth"] == data["per_participant"][-1]["fds"] - data["per_participant"][4]["fds"]
