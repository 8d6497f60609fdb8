"""Stable track ids and smoothed confidences over ticks."""

from __future__ import annotations

import pytest

from scone_bt.errors import ConfigError
from scone_bt.perception import UNTRACKED, Detection, Tracker


def det(name: str, confidence: float = 0.8, x: float = 0.5) -> Detection:
    return Detection(name, UNTRACKED, (x, 0.3, 0.1), 0.0, confidence, (0, 0, 10, 10))


def test_ids_are_stable_and_given_in_order_of_first_sighting():
    tracker = Tracker()
    first = tracker.update([det("salt"), det("flour")], 0.0)
    assert {d.name: d.track_id for d in first} == {"flour": 0, "salt": 1}
    second = tracker.update([det("sugar"), det("salt", x=0.2)], 1.0)
    assert {d.name: d.track_id for d in second} == {"salt": 1, "sugar": 2}
    third = tracker.update([det("flour")], 2.0)
    assert [d.track_id for d in third] == [0]


def test_missed_ticks_lower_the_track_confidence_not_the_detection():
    tracker = Tracker(smoothing=0.5)
    tracker.update([det("salt", 1.0)], 0.0)
    tracker.update([], 1.0)
    track = tracker.tracks["salt"]
    assert track.confidence == pytest.approx(0.5)
    assert (track.hits, track.misses, track.first_seen, track.last_seen) == (1, 1, 0.0, 0.0)
    (again,) = tracker.update([det("salt", 0.9, x=0.1)], 2.0)
    assert again.confidence == 0.9
    assert tracker.tracks["salt"].confidence == pytest.approx(0.7)
    assert tracker.tracks["salt"].position == (0.1, 0.3, 0.1)


def test_duplicate_names_keep_the_most_confident():
    (only,) = Tracker().update([det("salt", 0.4, x=0.1), det("salt", 0.9, x=0.2)], 0.0)
    assert only.confidence == 0.9 and only.position[0] == 0.2


def test_time_must_not_go_backwards_until_reset():
    tracker = Tracker()
    tracker.update([det("salt")], 5.0)
    with pytest.raises(ConfigError, match="reset"):
        tracker.update([], 4.0)
    tracker.reset()
    assert tracker.update([det("flour")], 0.0)[0].track_id == 0


def test_bad_smoothing_is_rejected():
    with pytest.raises(ConfigError, match="smoothing"):
        Tracker(smoothing=0.0)
