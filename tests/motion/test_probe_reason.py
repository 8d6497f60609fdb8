"""The heft test's words (motion.probe.judge_probe): a mass is quoted only when the load can be a weight; otherwise
the robot says what its fingers sensed. The verdict (carry on or set back) does not depend on the words."""

from __future__ import annotations

import pytest

from scone_bt.motion.probe import ProbeReading, ProbeSettings, judge_probe

SETTINGS = ProbeSettings()


def test_fingers_pressing_on_a_product_quote_no_mass() -> None:
    # What the fingers felt on the egg roll wrappers (a 3 cm pack the fingertips landed on): 214 N pointing down,
    # all of it normal force, while the pack stayed on its shelf.
    reading = ProbeReading(
        held=True, load_n=214.6136, load_first_n=213.3194, grip_n=214.6786, seconds=0.89, pressed=True
    )
    carry, why = judge_probe(reading, SETTINGS)
    assert not carry
    assert why == "does not come up: my fingers press on it"
    assert " g)" not in why


def test_a_load_past_the_payload_is_not_called_a_weight() -> None:
    reading = ProbeReading(held=True, load_n=60.0, load_first_n=60.1, grip_n=80.0)  # 6 kg from a 3 kg arm
    carry, why = judge_probe(reading, SETTINGS)
    assert not carry and why == "is caught on something"


def test_a_load_no_friction_grip_could_carry_is_not_called_a_weight() -> None:
    reading = ProbeReading(held=True, load_n=12.0, load_first_n=12.0, grip_n=10.0)  # load over grip 1.2
    carry, why = judge_probe(reading, SETTINGS)
    assert not carry and why == "is caught on something"


def test_a_steady_plausible_load_near_the_friction_limit_is_quoted_as_a_mass() -> None:
    reading = ProbeReading(held=True, load_n=8.829, load_first_n=8.83, grip_n=16.0)  # 0.9 kg in an 8 N grip
    carry, why = judge_probe(reading, SETTINGS)
    assert not carry and why == "is too heavy for my grip (about 900 g)"


@pytest.mark.parametrize(
    ("first", "second", "pressed"),
    [
        (3.1, 2.4, False),  # sliding carries less and less
        (3.5695, 4.6781, False),  # grits, slippery fingers: the load rose, then it slipped out while lifting
        # the olive oil in an 8 N grip: left on its shelf by the lift, the fingers' friction pushes it down
        (3.1871, 3.0585, True),
    ],
)
def test_an_unsteady_load_is_a_slip_and_quotes_no_mass(first: float, second: float, pressed: bool) -> None:
    reading = ProbeReading(held=True, load_n=second, load_first_n=first, grip_n=16.0, pressed=pressed)
    assert judge_probe(reading, SETTINGS) == (False, "slips in my fingers")


def test_a_press_that_relaxes_is_a_press_not_a_slip() -> None:
    # The tzatziki: the fingertips on its lid pushed 235 N, then 164 N (all of it normal force), while it stayed put.
    reading = ProbeReading(held=True, load_n=163.79, load_first_n=235.38, grip_n=163.35, pressed=True)
    assert judge_probe(reading, SETTINGS) == (False, "does not come up: my fingers press on it")


def test_the_words_do_not_change_the_verdict() -> None:
    readings = [
        ProbeReading(held=True, load_n=2.0, load_first_n=2.001, grip_n=80.0),
        ProbeReading(held=True, load_n=2.0, load_first_n=2.001, grip_n=80.0, pressed=True),
        ProbeReading(held=False, load_n=0.0, load_first_n=0.0, grip_n=0.0),
        ProbeReading(held=True, load_n=214.6, load_first_n=213.3, grip_n=214.7),
        ProbeReading(held=True, load_n=214.6, load_first_n=213.3, grip_n=214.7, pressed=True),
    ]
    verdicts = [judge_probe(r, SETTINGS)[0] for r in readings]
    # the second: a steady load the fingers push down instead of carrying up does not come up with them
    assert verdicts == [True, False, False, False, False]


def test_a_payload_out_of_range_is_one_line() -> None:
    from scone_bt.errors import SconeError

    with pytest.raises(SconeError, match=r"^probe.payload_kg must be in \(0, 50\] \(kilograms\), got 0.0$"):
        ProbeSettings(payload_kg=0.0)


@pytest.mark.parametrize(
    ("load", "first", "grip"),
    [(float("nan"), 5.0, 40.0), (5.0, float("nan"), 40.0), (5.0, 5.0, float("nan"))],
)
def test_a_reading_the_sensors_could_not_give_sets_back(load: float, first: float, grip: float) -> None:
    """A NaN from a faulty sensor is not a steady load: it must never let the product be carried on."""
    carry, why = judge_probe(ProbeReading(True, load, first, grip), ProbeSettings())
    assert not carry and why == "cannot be felt: my finger sensors give no reading"


@pytest.mark.parametrize("drift", [None, 0.0])
def test_a_nan_load_sets_back_whatever_the_pads_say(drift: float | None) -> None:
    reading = ProbeReading(True, float("nan"), 5.0, 40.0, drift_mm=drift)
    assert judge_probe(reading, ProbeSettings()) == (
        False,
        "cannot be felt: my finger sensors give no reading",
    )


# The grits in the motion benchmark's query 6 (seed 0): a 1.01 kg bag held fast in an 80 N grip while its neighbour
# (the ground pork) leans on it; the hand's load rises 1.6 % through the hold, the contacts stay put on the pads.
GRITS = dict(held=True, load_n=11.0575, load_first_n=10.8855, grip_n=80.0016, seconds=0.8917)


def test_a_load_that_changes_while_the_pads_hold_the_product_fast_is_carried_on() -> None:
    reading = ProbeReading(**GRITS, drift_mm=0.0)
    assert reading.unsteady > SETTINGS.max_unsteady
    assert judge_probe(reading, SETTINGS) == (True, "")


def test_a_load_that_changes_while_the_contacts_move_on_the_pads_is_a_slip() -> None:
    # The olive oil in an 8 N grip: left behind as the fingers rise, its contacts moved 1.3 mm on the pads.
    reading = ProbeReading(
        held=True, load_n=3.0585, load_first_n=3.1871, grip_n=16.0, pressed=True, drift_mm=1.395
    )
    assert judge_probe(reading, SETTINGS) == (False, "slips in my fingers")


def test_a_load_that_changes_by_more_than_a_push_is_a_slip_though_the_pads_hold_still() -> None:
    # The ghee with a weak gripper (the development streams regenerated with the pads read): its load fell 20 %
    # while the contacts' centre moved 0.2 mm, and it slipped out while lifting. A product pivoting in the grip
    # keeps its contacts where they were.
    reading = ProbeReading(held=True, load_n=2.454, load_first_n=3.073, grip_n=16.0, drift_mm=0.225)
    assert SETTINGS.max_pushed < reading.unsteady
    assert judge_probe(reading, SETTINGS) == (False, "slips in my fingers")


def test_a_finger_load_that_changes_while_the_wrist_carries_the_same_is_carried_on() -> None:
    # The rigatoni in the motion benchmark's query 31: the palm presses the box's top, so the fingers carry its
    # weight plus that push (25.9 → 22.7 N) while the whole hand carries its weight throughout (5.10 N).
    reading = ProbeReading(
        held=True, load_n=22.66, load_first_n=25.95, grip_n=80.0, wrist_load_n=5.101, wrist_load_first_n=5.104
    )
    assert reading.unsteady > SETTINGS.max_unsteady and reading.drift_mm is None
    assert judge_probe(reading, SETTINGS) == (True, "")


def test_a_slip_changes_the_wrists_load_too() -> None:
    reading = ProbeReading(
        held=True, load_n=2.454, load_first_n=3.073, grip_n=16.0, wrist_load_n=2.45, wrist_load_first_n=3.07
    )
    assert judge_probe(reading, SETTINGS) == (False, "slips in my fingers")
    nan_wrist = ProbeReading(True, 2.454, 3.073, 16.0, wrist_load_n=float("nan"), wrist_load_first_n=3.07)
    assert judge_probe(nan_wrist, SETTINGS)[0] is False  # a wrist that cannot be read is not "the same"


def test_without_the_pads_reading_an_unsteady_load_is_judged_as_before() -> None:
    """The recorded datasets have no drift (None): their replay must judge exactly as before the pads were read."""
    assert ProbeReading(**GRITS).drift_mm is None
    assert judge_probe(ProbeReading(**GRITS), SETTINGS) == (False, "slips in my fingers")


def test_a_changing_load_held_fast_but_past_the_friction_limit_is_not_quoted_as_a_mass() -> None:
    reading = ProbeReading(held=True, load_n=8.0, load_first_n=7.8, grip_n=16.0, drift_mm=0.0)  # traction 0.5
    assert judge_probe(reading, SETTINGS) == (False, "is caught on something")


def test_a_drift_threshold_out_of_range_is_one_line() -> None:
    from scone_bt.errors import SconeError

    with pytest.raises(
        SconeError, match=r"^probe.max_drift_mm must be in \(0, 20\] \(millimetres\), got 0.0$"
    ):
        ProbeSettings(max_drift_mm=0.0)
    with pytest.raises(SconeError, match=r"^probe.max_pushed must be in \(0, 1\], got 1.5$"):
        ProbeSettings(max_pushed=1.5)
    with pytest.raises(SconeError, match=r"^probe.in_place_m must be in \(0, 0.1\] \(metres\), got 0.5$"):
        ProbeSettings(in_place_m=0.5)


def test_a_product_that_does_not_come_up_with_the_fingers_is_set_back_however_steady_its_load() -> None:
    # The garlic in a 3 N grip with greasy pads (MuJoCo, the iiwa7): the fingers rose past it, their vertical force
    # on it pointing down, its load steady; carried on, it slipped out in the lift.
    garlic = ProbeReading(
        held=True,
        load_n=0.1711,
        load_first_n=0.1721,
        grip_n=6.0,
        pressed=True,
        drift_mm=8.646,
        drift_both_mm=6.558,
    )
    assert judge_probe(garlic, SETTINGS) == (False, "does not come up with my fingers")
    # The same steady load carried up by the fingers is carried on, whatever the pads read (many products move
    # on both pads and are carried: the nearer pad's drift is recorded, not judged).
    carried = ProbeReading(
        held=True, load_n=0.1711, load_first_n=0.1721, grip_n=6.0, drift_mm=8.646, drift_both_mm=6.558
    )
    assert judge_probe(carried, SETTINGS) == (True, "")
