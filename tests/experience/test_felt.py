"""What the heft test felt becomes execution context through one function (experience.felt), for the tree and the
replay alike; contexts and stores without it still load."""

from __future__ import annotations

import json
import math
import sqlite3

import numpy as np
import pytest

from scone_bt.confidence.physical import felt_features, physical_features
from scone_bt.errors import SconeError
from scone_bt.experience.felt import felt_context, felt_row, felt_values
from scone_bt.experience.types import CONTEXT_FIELDS, FELT_FIELDS, FELT_RANGES, ExecutionContext
from scone_bt.motion.probe import ProbeReading


def test_a_reading_becomes_the_felt_fields() -> None:
    held_fast = ProbeReading(True, 1.178, 1.1785, 20.0, 0.9)  # a 0.12 kg lemon
    v = felt_values(held_fast)
    assert v["felt_held"] is True and v["felt_traction"] == round(1.178 / 20.0, 6)
    assert v["felt_unsteady"] < 0.001 and math.isclose(v["felt_mass_kg"], 1.178 / 9.81, rel_tol=1e-5)
    lost = felt_values(ProbeReading(False, 0.0, 0.0, 0.0))
    assert lost == {"felt_held": False, "felt_traction": 10.0, "felt_unsteady": 1.0, "felt_mass_kg": 0.0}


def test_the_tree_and_the_replay_get_the_same_row() -> None:
    seen = ExecutionContext(
        shelf_tier=1, clearance_m=0.05, neighbours=2, detected=True, detected_width_m=0.06
    )
    reading = ProbeReading(True, 2.0, 2.3, 8.0, 0.9)
    after = felt_context(seen, reading)
    assert after is not None and after.shelf_tier == 1 and after.felt_held is True
    np.testing.assert_array_equal(after.vector(), felt_row(seen.vector(), reading))
    assert felt_context(seen, None) is seen  # not probed: unchanged
    assert np.isnan(seen.vector()[[CONTEXT_FIELDS.index(f) for f in FELT_FIELDS]]).all()


def test_a_stored_context_without_the_felt_fields_loads_as_not_probed() -> None:
    old = ExecutionContext.from_json({"shelf_tier": 0, "detected": True, "detected_width_m": 0.05})
    assert all(getattr(old, f) is None for f in FELT_FIELDS)
    after = felt_context(old, ProbeReading(True, 2.0, 2.0, 10.0))
    assert after is not None and ExecutionContext.from_json(after.to_json()) == after  # round trip


def test_physical_kappa_feels_nothing_where_nothing_was_probed() -> None:
    seen = ExecutionContext(shelf_tier=1, detected=True, detected_width_m=0.05)
    stray = ExecutionContext(shelf_tier=1, felt_traction=0.5)  # not probed (felt_held None): nothing is read
    assert felt_features(stray.vector()[None]).tolist() == [[0.0, 0.0, 0.0]]
    slipping = felt_context(seen, ProbeReading(True, 2.0, 2.4, 5.0))
    assert slipping is not None
    rows = np.stack([seen.vector(), slipping.vector()])
    F = felt_features(rows)
    assert F[0].tolist() == [0.0, 0.0, 0.0]
    # held, high traction, unsteady by 20 % (log scale × 3)
    assert F[1, 0] == 0.0 and F[1, 1] > 1.0 and F[1, 2] > 6.0
    # the perceived features do not change with what was felt
    P = physical_features(rows, 0.08)
    np.testing.assert_array_equal(P[0, :10], P[1, :10])


@pytest.mark.parametrize(
    ("stored", "message"),
    [
        ({"felt_traction": -0.5}, "felt_traction must be in [0, 10], got -0.5"),
        ({"felt_unsteady": 3.0}, "felt_unsteady must be in [0, 1], got 3.0"),
        ({"felt_mass_kg": math.nan}, "felt_mass_kg must be in [0, 10], got nan"),
        ({"felt_traction": "slips"}, "felt_traction must be float, got 'slips'"),
        ({"felt_held": 1}, "felt_held must be bool, got 1"),
        (
            {"felt_held": True, "felt_traction": 0.1},
            "felt_mass_kg, felt_unsteady missing beside felt_held, felt_traction (a probed context has every one "
            "of felt_held, felt_traction, felt_unsteady, felt_mass_kg, or none)",
        ),
    ],
)
def test_a_malformed_felt_value_is_one_line_naming_the_key_and_its_range(stored: dict, message: str) -> None:
    with pytest.raises(SconeError) as err:
        ExecutionContext.from_json(stored, "stored outcome 7: execution")
    assert str(err.value) == f"stored outcome 7: execution: {message}"


def test_the_caps_of_a_reading_are_the_ranges_a_store_accepts() -> None:
    wild = ProbeReading(True, 400.0, 1.0, 0.5)  # sliding out: a spike of ~40 kg on a grip of nothing
    after = felt_context(None, wild)
    assert after is not None and ExecutionContext.from_json(after.to_json()) == after
    assert {f: FELT_RANGES[f][1] for f in FELT_RANGES} == {
        "felt_traction": after.felt_traction,
        "felt_unsteady": after.felt_unsteady,
        "felt_mass_kg": after.felt_mass_kg,
    }


def test_a_store_row_with_a_malformed_felt_value_is_set_aside_in_one_line(tmp_path, capsys) -> None:
    from scone_bt.experience import ExperienceStore, Outcome

    path = tmp_path / "felt.sqlite"
    felt = felt_context(ExecutionContext(shelf_tier=1), ProbeReading(True, 2.0, 2.0, 10.0))
    with ExperienceStore(path) as store:
        for i in range(2):
            store.append(Outcome(1.0 + i, "Put honey on table", "honey", "minilm", True, execution=felt))
    bad = json.dumps({"execution": {"shelf_tier": 1, "felt_held": True, "felt_traction": 42.0}})
    with sqlite3.connect(path) as conn:
        conn.execute("UPDATE outcomes SET context = ? WHERE id = 2", (bad,))
    conn.close()
    with ExperienceStore(path) as store:
        assert [o.execution for o in store.outcomes()] == [
            felt
        ]  # the good row loads, the bad one is set aside
    warning = capsys.readouterr().err
    assert warning.count("\n") == 1 and str(path) in warning
    assert "row 2 (context execution: felt_traction must be in [0, 10], got 42.0)" in warning
