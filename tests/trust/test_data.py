"""The vendored human trust ratings (Soh et al.) and the loader's one-line errors."""

from __future__ import annotations

from pathlib import Path

import pytest

from scone_bt.errors import UnknownNameError
from scone_bt.trust.data import TrustDataError, load_tasks, load_trust_data


def test_vendored_files_load() -> None:
    house = load_trust_data("household")
    drive = load_trust_data("driving")
    assert (house.participants, drive.participants) == (32, 31)
    assert house.tasks[1].text == "Pick and Place glass" and house.tasks[1].label == "A-5"
    assert drive.tasks[12].text == "Navigating T-junction on a clear road"
    first = house.records[0]  # the file's first row: 5,5,3,6,7,7,5,4,4,6,2,8,5,1
    assert first.before == (5, 5, 3) and first.after == (7, 5, 4) and first.observed_ratings == (6, 7)
    assert first.observed == (4, 6) and first.predicted == (2, 8, 5) and first.success
    assert sum(r.success for r in house.records) == 16  # half saw successes, half failures


def _write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "ratings.csv"
    path.write_text(text)
    return path


HEADER = "C1_rating,D1_rating,E1_rating,A_rating,B_rating,C2_rating,D2_rating,E2_rating,A_ID,B_ID,C_ID,D_ID,E_ID,B_SF\n"
GOOD = "5,5,3,6,7,7,5,4,4,6,2,8,5,1\n"


def test_missing_column_names_file_row_and_column(tmp_path: Path) -> None:
    path = _write(tmp_path, HEADER.replace(",E2_rating", "") + "5,5,3,6,7,7,5,4,6,2,8,5,1\n")
    with pytest.raises(
        TrustDataError, match=r"ratings\.csv: row 0 \(header\), missing column\(s\) E2_rating;"
    ):
        load_trust_data("household", path)


def test_rating_out_of_range(tmp_path: Path) -> None:
    path = _write(tmp_path, HEADER + GOOD + "5,5,3,6,7,8,5,4,4,6,2,8,5,1\n")
    with pytest.raises(TrustDataError, match=r"row 2, column C2_rating: rating 8 is outside 1-7"):
        load_trust_data("household", path)


def test_unknown_task_id(tmp_path: Path) -> None:
    path = _write(tmp_path, HEADER + "5,5,3,6,7,7,5,4,4,6,2,13,5,1\n")
    with pytest.raises(TrustDataError, match=r"row 1, column D_ID: unknown task id 13; valid: 1, 2, .*, 12$"):
        load_trust_data("household", path)


def test_bad_outcome_and_non_integer(tmp_path: Path) -> None:
    with pytest.raises(TrustDataError, match=r"row 1, column B_SF: 2 is not 0"):
        load_trust_data("household", _write(tmp_path, HEADER + GOOD[:-2] + "2\n"))
    with pytest.raises(TrustDataError, match=r"row 1, column A_rating: 'x' is not an integer"):
        load_trust_data("household", _write(tmp_path, HEADER + "5,5,3,x,7,7,5,4,4,6,2,8,5,1\n"))


def test_unknown_domain_lists_valid_ones() -> None:
    with pytest.raises(UnknownNameError, match="valid: driving, household"):
        load_trust_data("kitchen")
    with pytest.raises(UnknownNameError, match="valid: driving, household"):
        load_tasks("kitchen")
