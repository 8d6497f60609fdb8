"""Each ratings/sessions CSV row is checked by a pydantic row model; a problem is one line: file, row, column, what."""

from __future__ import annotations

from pathlib import Path

import pytest

from scone_bt.study.ratings_csv import RatingsFileError, load_ratings_csv

HEADER = "participant,condition,session,group,question,rating,categories"
GOOD = ["P1,on,1,A,q1,3,5", "P1,off,2,A,q1,2,5", "P2,off,1,B,q1,1,5", "P2,on,2,B,q1,4,5"]
SESSIONS = "participant,condition,session,group,interventions"
GOOD_SESSIONS = ["P1,on,1,A,1", "P1,off,2,A,0", "P2,off,1,B,3", "P2,on,2,B,2"]


def _csv(path: Path, header: str, rows: list[str]) -> Path:
    path.write_text("\n".join([header, *rows]) + "\n")
    return path


@pytest.mark.parametrize(
    ("last", "message"),
    [
        (",on,2,B,q1,2,5", "row 5, column 'participant' is empty"),
        ("P2,on,2,B,,2,5", "row 5, column 'question' is empty"),
        ("P2,on,2,B,q1,1,1", "row 5, column 'categories': 1 categories; an ordinal scale has 2 or more"),
        (
            "P2,on,2,B,q1,2,x",
            "row 5, column 'categories': 'x' is not a whole number of categories (2 or more)",
        ),
        ("P2,on,2,B,q1,x,5", "row 5, column 'rating': 'x' is not a whole number from 0 to 4"),
        ("P2,on,2,B,q1,-1,5", "row 5, column 'rating': -1 is outside the scale 0..4 (5 categories)"),
        ("P2,on,2.0,B,q1,3,5", "row 5, column 'session': '2.0' is not one of 1, 2"),
    ],
)
def test_a_bad_ratings_row_names_its_row_and_column(tmp_path, last, message):
    path = _csv(tmp_path / "r.csv", HEADER, [*GOOD[:3], last])
    with pytest.raises(RatingsFileError) as err:
        load_ratings_csv(path)
    assert str(err.value).startswith(f"{path}: {message}") and "\n" not in str(err.value)


def test_spreadsheet_spellings_whole_numbers_and_skipped_items_are_read(tmp_path):
    rows = ["P1,ON,1,a,q1,3.0,5", "P1,Off,2,A,q1,,5.0", "P2,off,1,b,q1,1,5", "P2,on,2,B,q1,4,5"]
    data = load_ratings_csv(_csv(tmp_path / "r.csv", HEADER, rows))
    assert list(data.ratings["category"]) == [3, 1, 4]  # the empty rating is a skipped item
    assert set(data.ratings["condition"]) == {"on", "off"} and set(data.ratings["group"]) == {"A", "B"}
    assert set(data.ratings["n_categories"]) == {5}


@pytest.mark.parametrize(
    ("last", "message"),
    [
        ("P2,on,2,B,-1", "row 5, column 'interventions': -1 < 0; interventions are counts (0 or more)"),
        ("P2,on,2,B,1.5", "row 5, column 'interventions': '1.5' is not a whole number of interventions"),
        ("P2,on,2,B,", "row 5, column 'interventions': '' is not a whole number of interventions"),
        ("P2,maybe,2,B,1", "row 5, column 'condition': 'maybe' is not one of off, on"),
    ],
)
def test_a_bad_sessions_row_names_its_row_and_column(tmp_path, last, message):
    ratings = _csv(tmp_path / "r.csv", HEADER, GOOD)
    sessions = _csv(tmp_path / "s.csv", SESSIONS, [*GOOD_SESSIONS[:3], last])
    with pytest.raises(RatingsFileError) as err:
        load_ratings_csv(ratings, sessions)
    assert str(err.value).startswith(f"{sessions}: {message}") and "\n" not in str(err.value)


def test_a_renamed_column_is_named_as_the_file_names_it(tmp_path):
    path = _csv(tmp_path / "r.csv", HEADER.replace("rating", "answer"), [*GOOD[:3], "P2,on,2,B,q1,9,5"])
    with pytest.raises(RatingsFileError, match=r"row 5, column 'answer': 9 is outside the scale 0\.\.4"):
        load_ratings_csv(path, columns={"rating": "answer"})
