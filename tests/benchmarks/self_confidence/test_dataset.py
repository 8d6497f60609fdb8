"""The generator's CSV schema: the column contract, a lossless round trip, and one-line errors on bad files."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from scone_bt.benchmarks.self_confidence.dataset import (
    COLUMNS,
    CONTEXT_COLUMNS,
    ExecutionRecord,
    read_dataset,
    read_records,
    write_records,
)
from scone_bt.errors import ConfigError

CONTRACT = (
    "index, action, object, family, outcome, failure_stage, seed, detail, shelf_unit, shelf_tier, slot, "
    "clearance_m, neighbours, detected, detected_width_m, detected_height_m, width_m, height_m, mass_kg, material, "
    "detected_depth_m, detected_fill, depth_m, shape, probe_held, probe_load_n, probe_load_first_n, probe_grip_n, "
    "probe_s, probe_pressed, probe_drift_mm, probe_drift_both_mm, probe_wrist_load_n, probe_wrist_load_first_n, "
    "probe_in_place"
)


def _records() -> list[ExecutionRecord]:
    seen = ExecutionRecord(
        index=0,
        action="Put olive oil on table",
        object="olive oil",
        success=True,
        failure_stage=None,
        seed=10_000_000,
        detail="placed upright on the table",
        family="glass bottles",
        shelf_unit="front",
        shelf_tier=0,
        slot=3,
        clearance_m=0.0325,
        neighbours=2,
        detected=True,
        detected_width_m=0.0642,
        detected_height_m=0.2501,
        width_m=0.065,
        height_m=0.25,
        mass_kg=0.9,
        material="glass",
        detected_depth_m=0.0655,
        detected_fill=0.781,
        depth_m=0.065,
        shape="cylinder",
        probe_held=True,
        probe_load_n=8.8291,
        probe_load_first_n=8.8302,
        probe_grip_n=80.0,
        probe_s=0.8917,
        probe_pressed=False,
        probe_drift_mm=0.031,
        probe_drift_both_mm=0.012,
        probe_wrist_load_n=8.8291,
        probe_wrist_load_first_n=8.8302,
    )
    missed = dataclasses.replace(
        seen,
        index=1,
        success=False,
        failure_stage="perception",
        detail='target not detected, "3 products seen"',  # a comma and quotes survive the CSV
        detected=False,
        detected_width_m=None,
        detected_height_m=None,
        detected_depth_m=None,
        detected_fill=None,
        shelf_tier=2,
        clearance_m=0.5,
        **dict.fromkeys(("probe_held", "probe_load_n", "probe_load_first_n", "probe_grip_n", "probe_s")),
        **dict.fromkeys(("probe_pressed", "probe_drift_mm", "probe_drift_both_mm", "probe_wrist_load_n")),
        probe_wrist_load_first_n=None,
        probe_in_place=True,  # a probe's fingers closed beside it, and it still stood where it stood
    )
    return [missed, seen]  # written sorted by index


def test_columns_are_the_contract_in_order():
    assert ", ".join(COLUMNS) == CONTRACT
    assert set(CONTEXT_COLUMNS) <= set(COLUMNS)


def test_round_trip_keeps_every_field(tmp_path):
    path = write_records(tmp_path / "p.csv", _records())
    assert path.read_text().splitlines()[0] == CONTRACT.replace(", ", ",")
    back = read_records(path)
    assert back == sorted(_records(), key=lambda r: r.index)
    assert back[1].detected_width_m is None and back[1].detected_height_m is None
    assert "\n" not in back[1].detail


def test_dataset_carries_family_and_numeric_context(tmp_path):
    path = write_records(tmp_path / "p.csv", _records())
    (ds,) = read_dataset(path)
    assert ds.name == "p" and len(ds) == 2
    assert list(ds.success) == [True, False]
    assert ds.families == ("glass bottles", "glass bottles")
    assert ds.materials == ("glass", "glass") and ds.shelf_units == ("front", "front")
    assert set(ds.context) == set(CONTEXT_COLUMNS)
    assert ds.context["detected"].tolist() == [1.0, 0.0]
    assert ds.context["shelf_tier"].tolist() == [0.0, 2.0]
    assert ds.context["detected_width_m"][0] == pytest.approx(0.0642)
    assert math.isnan(ds.context["detected_width_m"][1])
    assert ds.context["mass_kg"].dtype == np.float64


def test_a_minimal_foreign_file_still_reads_without_context(tmp_path):
    path = tmp_path / "mine.csv"
    path.write_text("action,object,outcome\nPut salt on table,salt,1\nPut salt on table,salt,0\n")
    (ds,) = read_dataset(path)
    assert list(ds.success) == [True, False]
    assert ds.context == {} and ds.families == ("", "")


def test_an_old_generator_file_is_a_one_line_error(tmp_path):
    path = tmp_path / "p00.csv"
    path.write_text(
        "index,action,object,outcome,failure_stage,seed,detail\n0,Put salt on table,salt,success,,1,ok\n"
    )
    with pytest.raises(ConfigError, match=r"missing column 'family'.*delete it to regenerate") as err:
        read_records(path)
    assert "\n" not in str(err.value)


@pytest.mark.parametrize("text", ["just one line of my notes\n", "my,precious,data\n"])
def test_a_file_of_one_line_that_is_no_generator_header_is_refused_not_resumed(tmp_path, text):
    """Without rows the header alone says whose file it is: a generator run would write over it otherwise."""
    path = tmp_path / "p01_weak_gripper.csv"
    path.write_text(text)
    with pytest.raises(ConfigError, match=r"not a generator file of this version"):
        read_records(path)
    assert path.read_text() == text
    # A generator file cut short before its first row (the header alone) resumes from nothing; an empty one too.
    header = write_records(tmp_path / "p.csv", []).read_text()
    assert header.count("\n") == 1 and read_records(tmp_path / "p.csv") == []
    (tmp_path / "empty.csv").write_text("")
    assert read_records(tmp_path / "empty.csv") == []


def test_a_malformed_number_names_the_row_and_column(tmp_path):
    path = write_records(tmp_path / "p.csv", _records())
    text = path.read_text().replace(",0.0325,", ",wide,")
    path.write_text(text)
    with pytest.raises(ConfigError, match=r"row 2: clearance_m 'wide' is not a number"):
        read_records(path)


def test_a_file_without_the_later_shape_columns_is_still_read(tmp_path):
    path = write_records(tmp_path / "p.csv", _records())
    import csv

    rows = list(csv.reader(path.open(newline="")))
    with path.open("w", newline="") as f:
        csv.writer(f).writerows(r[:20] for r in rows)  # the previous schema: up to material
    back = read_records(path)
    assert back[1].detected_depth_m is None and back[1].shape == "" and back[1].material == "glass"


_PROBE = "probe_held,probe_load_n,probe_load_first_n,probe_grip_n,probe_s"


@pytest.mark.parametrize(
    ("reading", "message"),
    [
        ("2,1.2,1.2,20,0.9", "row 3: probe_held 2 must be 0 or 1 (empty: never held up)"),
        ("1,-1.2,1.2,20,0.9", "row 3: probe_load_n -1.2 must be a finite number ≥ 0 (or empty)"),
        ("1,1.2,1.2,inf,0.9", "row 3: probe_grip_n inf must be a finite number ≥ 0 (or empty)"),
        ("1,,1.2,20,0.9", "row 3: probe_load_n must be given exactly where probe_held is"),
        (",1.2,,,", "row 3: probe_load_n must be given exactly where probe_held is"),
    ],
)
def test_a_malformed_probe_reading_is_one_line_naming_file_row_column_and_range(tmp_path, reading, message):
    """What the replay turns into felt context (experience.felt) is checked where the file is known."""
    path = tmp_path / "p.csv"
    path.write_text(
        f"action,object,outcome,{_PROBE}\n"
        "Put salt on table,salt,1,1,1.2,1.2,20,0.9\n"
        f"Put salt on table,salt,0,{reading}\n"
        "Put salt on table,salt,0,,,,,\n"
    )
    with pytest.raises(ConfigError) as err:
        read_dataset(path)
    assert str(err.value).startswith(f"{path} {message}") and "\n" not in str(err.value)
    path.write_text(
        f"action,object,outcome,{_PROBE}\nPut salt on table,salt,1,1,1.2,1.2,20,0.9\nPut salt,salt,0,,,,,\n"
    )
    assert np.isnan(read_dataset(path)[0].context["probe_held"][1])  # never held up: every column empty


_SENSED = "probe_pressed,probe_drift_mm,probe_drift_both_mm,probe_wrist_load_n,probe_wrist_load_first_n,probe_in_place"


@pytest.mark.parametrize(
    ("row", "message"),
    [
        ("1,1.2,1.2,20,0.9,2,0.1,0.1,1.2,1.2,", "row 3: probe_pressed 2 must be 0 or 1 (or empty)"),
        ("1,1.2,1.2,20,0.9,0,-0.1,0.1,1.2,1.2,", "row 3: probe_drift_mm -0.1 must be a finite number ≥ 0"),
        (",,,,,,0.1,,,,1", "row 3: probe_drift_mm must be empty where probe_held is (nothing was felt)"),
        (",,,,,,,,,,0.5", "row 3: probe_in_place 0.5 must be 0 or 1 (or empty)"),
        (
            "1,1.2,1.2,20,0.9,0,0.1,0.1,1.2,1.2,1",
            "row 3: probe_in_place must be empty where probe_held is given",
        ),
    ],
)
def test_what_the_hand_sensed_beside_a_reading_is_checked_in_one_line(tmp_path, row, message):
    path = tmp_path / "p.csv"
    header = f"action,object,outcome,{_PROBE},{_SENSED}\n"
    good = "Put salt on table,salt,1,1,1.2,1.2,20,0.9,0,0.1,0.05,1.2,1.2,\n"
    path.write_text(f"{header}{good}Put salt on table,salt,0,{row}\n")
    with pytest.raises(ConfigError) as err:
        read_dataset(path)
    assert str(err.value).startswith(f"{path} {message}") and "\n" not in str(err.value)
    # unmeasured drift or wrist beside a reading, and a miss that stood in place: read
    path.write_text(
        f"{header}{good}Put salt on table,salt,0,1,1.2,1.2,20,0.9,1,,,,,\nPut salt,salt,0,,,,,,,,,,,1\n"
    )
    (ds,) = read_dataset(path)
    assert np.isnan(ds.context["probe_drift_mm"][1]) and ds.context["probe_pressed"][1] == 1.0
    assert ds.context["probe_in_place"].tolist()[2] == 1.0
