"""Anyone's data: the hand-written CSV files in tests/study/data are read, checked and analysed; bad files are
one-line errors naming file, row, column and what is allowed, raised before any sampling."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from scone_bt.study.cli import main
from scone_bt.study.ratings_csv import RatingsFileError, load_ratings_csv, parse_column_map

DATA = Path(__file__).parent / "data"
RATINGS, SESSIONS = DATA / "lab_ratings.csv", DATA / "lab_sessions.csv"
HEADER = "participant,condition,session,group,question,rating,categories"


def test_hand_written_files_load_with_design_scores_and_interventions():
    before = RATINGS.read_bytes()
    data = load_ratings_csv(RATINGS, SESSIONS)
    assert RATINGS.read_bytes() == before  # never modified
    assert data.questionnaires == ("percent", "trust7")
    assert len(data.ratings) == 47  # 48 rows, one skipped item (empty rating)
    assert set(data.ratings["n_categories"]) == {7, 11}
    assert data.available_models() == ("percent", "trust7", "trust", "interventions")
    s = data.sessions.set_index("session_id")
    assert len(s) == 12 and s.loc["L02/2", "condition"] == "on" and s.loc["L02/2", "interventions"] == 1
    assert s.loc["L01/1", "trust7"] == pytest.approx(5.0)  # mean of 5, 6, 4
    assert s.loc["L02/2", "trust7"] == pytest.approx(4.5)  # the skipped item is left out
    assert data.has_interventions and s["interventions"].sum() == 17
    assert not load_ratings_csv(RATINGS).has_interventions


def test_column_mapping_and_byte_order_mark(tmp_path):
    text = RATINGS.read_text().replace("participant,", "subject,", 1).replace(",rating,", ",answer,", 1)
    path = tmp_path / "renamed.csv"
    path.write_bytes(b"\xef\xbb\xbf" + text.encode())
    with pytest.raises(RatingsFileError, match=r"missing column 'participant'.*--columns participant=NAME"):
        load_ratings_csv(path)
    data = load_ratings_csv(path, columns=parse_column_map("participant=subject,rating=answer"))
    assert len(data.ratings) == 47
    with pytest.raises(RatingsFileError, match="unknown column 'subjekt'; valid: participant"):
        parse_column_map("subjekt=subject")


def _write(tmp_path: Path, rows: list[str], header: str = HEADER, name: str = "r.csv") -> Path:
    path = tmp_path / name
    path.write_text("\n".join([header, *rows]) + "\n")
    return path


GOOD = ["P1,on,1,A,q1,3,5", "P1,off,2,A,q1,2,5", "P2,off,1,B,q1,1,5", "P2,on,2,B,q1,4,5"]


@pytest.mark.parametrize(
    ("rows", "header", "message"),
    [
        (GOOD, "participant,condition,session,group,question,rating", r"missing column 'categories'"),
        (
            [*GOOD[:3], "P2,on,2,B,q1,5,5"],
            HEADER,
            r"r\.csv: row 5, column 'rating': 5 is outside the scale 0\.\.4 \(5 categories\)",
        ),
        ([*GOOD[:3], "P2,on,2,B,q1,2.5,5"], HEADER, r"row 5, column 'rating': '2\.5' is not a whole number"),
        ([*GOOD[:3], "P2,yes,2,B,q1,2,5"], HEADER, r"row 5, column 'condition': 'yes' is not one of off, on"),
        ([*GOOD[:3], "P2,on,3,B,q1,2,5"], HEADER, r"row 5, column 'session': '3' is not one of 1, 2"),
        ([*GOOD[:3], "P2,on,2,C,q1,2,5"], HEADER, r"row 5, column 'group': 'C' is not one of A, B"),
        (
            [*GOOD[:3], "P2,off,2,B,q1,2,5"],
            HEADER,
            r"participant 'P2' has condition off only; every participant needs both conditions",
        ),
        ([*GOOD, "P1,on,1,A,q1,2,5"], HEADER, r"row 6 repeats participant 'P1' session 1 question 'q1'"),
        ([*GOOD, "P1,on,1,A,q2,2,7"], HEADER, r"question 'q2' has 7 categories but 'q1' \(row 2\)"),
        (
            [*GOOD[:2], "P2,on,1,B,q1,1,5", "P2,off,2,B,q1,4,5"],
            HEADER,
            r"groups A and B both have the order on/off",
        ),
        (
            ["P1,on,1,A,q1,3,5", "P1,off,2,A,q1,2,5", "P2,on,1,A,q1,1,5", "P2,off,2,A,q1,4,5"],
            HEADER,
            r"column 'group': every participant is in group A \(order on/off, e\.g\. 'P1'\); the design needs "
            r"both groups A and B.*condition and session order are confounded",
        ),
        ([], HEADER, r"no data rows"),
    ],
)
def test_bad_ratings_are_one_line_errors(tmp_path, rows, header, message):
    path = _write(tmp_path, rows, header)
    with pytest.raises(RatingsFileError, match=message) as info:
        load_ratings_csv(path)
    assert "\n" not in str(info.value) and str(path) in str(info.value)


def test_one_group_only_is_refused_before_any_sampling(tmp_path, capsys):
    # Every participant in group B (off first): "on" is always session 2, so condition and session are aliased.
    rows = ["P1,off,1,B,q1,3,5", "P1,on,2,B,q1,4,5", "P2,off,1,B,q1,1,5", "P2,on,2,B,q1,2,5"]
    path = _write(tmp_path, rows, HEADER.replace(",group,", ",arm,"))
    with pytest.raises(
        RatingsFileError, match=r"column 'arm': every participant is in group B \(order off/on"
    ):
        load_ratings_csv(path, columns={"group": "arm"})
    out = tmp_path / "out"
    argv = ["analyze", "--ratings", str(path), "--columns", "group=arm", "--out", str(out)]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "needs both groups A and B" in err and str(path) in err and err.count("\n") == 1
    assert not out.exists()  # nothing was sampled or written


def test_wrong_encoding_and_bad_sessions(tmp_path):
    latin = tmp_path / "latin1.csv"
    latin.write_bytes((HEADER + "\nJos\xe9,on,1,A,q1,3,5\n").encode("latin-1"))
    with pytest.raises(RatingsFileError, match=r"latin1\.csv: not UTF-8 text \(byte 0xe9 on row 2\)"):
        load_ratings_csv(latin)
    nul = tmp_path / "nul.csv"
    nul.write_bytes(b"part\x00icipant,condition\n")  # the line printed "the header has  garbage"
    with pytest.raises(RatingsFileError, match=r"nul\.csv: contains NUL characters; it is not a text file"):
        load_ratings_csv(nul)
    ratings = _write(tmp_path, GOOD)
    header = "participant,condition,session,group,interventions"
    bad = _write(tmp_path, ["P1,on,1,A,0", "P1,off,2,A,-1"], header, "s.csv")
    with pytest.raises(RatingsFileError, match=r"s\.csv: row 3, column 'interventions': -1 < 0"):
        load_ratings_csv(ratings, bad)
    short = _write(tmp_path, ["P1,on,1,A,0", "P1,off,2,A,1", "P2,off,1,B,2"], header, "s2.csv")
    with pytest.raises(RatingsFileError, match=r"no interventions for P2 session 2"):
        load_ratings_csv(ratings, short)
    clash = _write(tmp_path, ["P1,off,1,A,0"], header, "s3.csv")
    with pytest.raises(RatingsFileError, match=r"but the ratings say condition on group A"):
        load_ratings_csv(ratings, clash)


def test_cli_analyses_the_hand_written_files_and_refuses_to_overwrite(tmp_path, capsys):
    out = tmp_path / "analysis"
    argv = ["analyze", "--ratings", str(RATINGS), "--sessions", str(SESSIONS), "--out", str(out)]
    quick = [
        "--chains",
        "1",
        "--tune",
        "100",
        "--draws",
        "100",
        "--cores",
        "1",
        "--models",
        "trust7,interventions",
    ]
    import arviz as az

    az._log.cache.clear()  # ArviZ shows each message once per process; a test before this one may have had it
    assert main([*argv, *quick, "--effect-prior-sd", "2.5"]) == 0
    # One chain: R-hat is NaN, without ArviZ's "Shape validation failed" line on stderr.
    assert "Shape validation failed" not in capsys.readouterr().err
    result = json.loads((out / "results.json").read_text())
    assert result["model"] == "paper" and result["data"] == "real"
    assert result["priors"]["effect_sd"] == 2.5 and result["priors"]["cutpoint_sd"] == 1.0
    assert result["sampler"]["chains"] == 1 and result["sampler"]["draws"] == 100
    assert {(c["model"], c["contrast"]) for c in result["contrasts"]} == {
        ("trust7", "condition"),
        ("trust7", "session"),
        ("interventions", "condition"),
        ("interventions", "session"),
    }
    # By hand, every participant rates the robot higher with self-confidence on and needs fewer interventions.
    assert result["contrasts"][0]["mean"] > 0 and result["contrasts"][2]["mean"] < 0
    assert (out / "fig3.png").stat().st_size > 10_000 and (out / "fig3.pdf").stat().st_size > 5_000
    capsys.readouterr()
    # A second run refuses before sampling; the earlier results are untouched.
    stamp = (out / "results.json").stat().st_mtime_ns
    assert main([*argv, *quick]) == 2
    err = capsys.readouterr().err
    assert "already holds results.json" in err and "--force" in err and err.count("\n") == 1
    assert (out / "results.json").stat().st_mtime_ns == stamp
    # Bad input is one line too, and names what exists.
    assert main([*argv[:-2], "--out", str(tmp_path / "o2"), "--models", "sus"]) == 2
    assert "valid: interventions, percent, trust, trust7" in capsys.readouterr().err
    assert main(["analyze", "--ratings", str(tmp_path / "none.csv"), "--out", str(tmp_path / "o3")]) == 2
    assert "none.csv: file not found" in capsys.readouterr().err
