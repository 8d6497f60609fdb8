"""scone_bt.checks: the small shared rules of the command lines' values."""

from __future__ import annotations

import pytest

from scone_bt.checks import check_at_least, comma_list
from scone_bt.errors import SconeError


@pytest.mark.parametrize("text", ["", " ", "10,,20", "10,", ",10"])
def test_a_comma_list_with_an_empty_item_is_refused(text):
    """`--n 10,,20` ran as [10, 20] and `--models ""` as every model."""
    with pytest.raises(SconeError, match=r"--n .*: a comma list with no empty item, e.g. 10,20"):
        comma_list(text, "--n", "10,20")


def test_a_comma_list_is_its_stripped_items():
    assert comma_list(" mdmt , trust", "--models", "mdmt") == ("mdmt", "trust")


def test_at_least_names_the_flag_and_the_bound():
    assert check_at_least(2, "--chains", 1) == 2
    with pytest.raises(SconeError, match=r"^--chains 0: must be 1 or more$"):
        check_at_least(0, "--chains", 1)


def test_power_and_simulate_refuse_an_empty_item_before_any_work(tmp_path, capsys):
    from scone_bt.study.cli import main

    db = tmp_path / "s.db"
    for argv in (
        ["power", "--n", "10,,20"],
        ["simulate", "--fast", "--db", str(db), "--analyze", str(tmp_path / "an"), "--models", ""],
    ):
        assert main(argv) == 2
        assert "a comma list with no empty item" in capsys.readouterr().err
    assert not db.exists()
