"""The person's trust estimated online, with over- and under-trust risk."""

from __future__ import annotations

import pytest

from scone_bt.errors import SconeError
from scone_bt.events import ActOutcome, EventLog, HelpRequested, TrustEstimated
from scone_bt.trust.estimate import OnlineTrust, RiskOptions, classify_risk
from scone_bt.trust.transfer import TransferModel, load_fitted

JAR, BOTTLE, RICE = (
    "Put the glass jar on table",
    "Put the glass bottle on table",
    "Put the bag of rice on table",
)


@pytest.fixture(scope="module")
def model() -> TransferModel:
    return TransferModel(load_fitted())


def test_risk_rules() -> None:
    assert classify_risk(0.8, 0.3, 0.0) == "over"
    assert classify_risk(0.3, 0.8, 1.0) == "under"
    assert classify_risk(0.3, 0.8, 0.1) == ""  # κ̂ high but the person saw nothing like it fail: no evidence
    assert classify_risk(0.6, 0.5, 2.0) == ""
    with pytest.raises(SconeError, match="over_margin must be in"):
        RiskOptions(over_margin=2.0)


def test_events_in_estimates_out(model: TransferModel) -> None:
    online = OnlineTrust(model)
    offered = {BOTTLE: ("glass bottle", 0.2), RICE: ("bag of rice", 0.9)}
    first = online.estimate(1.0, offered)
    assert [e.object_name for e in first] == ["glass bottle", "bag of rice"]
    assert first[0].risk == "over" and first[1].risk == ""  # ~0.73 trust against κ̂ 0.2
    log = EventLog(online)
    log(HelpRequested(2.0, RICE, "bag of rice"))
    for t in (3.0, 4.0):
        log(ActOutcome(t, JAR, "glass jar", False, "grasp", 5.0))
    after = online.estimate(5.0, offered)
    assert (
        after[0].trust < first[0].trust and after[0].risk == ""
    )  # two failures of a glass jar: trust is low now
    assert after[1].risk == "under"  # similar failures seen, yet κ̂ 0.9 for the rice
    assert isinstance(after[1], TrustEstimated) and after[1].to_json()["object"] == "bag of rice"


def test_calibration_report_of_simulated_studies() -> None:
    from scone_bt.study.trust_bench import calibration

    report = calibration(participants=2, steps=2, seed=0)
    assert set(report) == {
        "self_confidence_off",
        "self_confidence_on",
        "trust_aware",
        "trust_aware_self_confidence_off",
    }
    assert report["trust_aware_self_confidence_off"]["warnings_spoken"] > 0
    for row in report.values():
        assert row["decisions"] >= row["acting_decisions"] and row["decisions"] >= 4
        for key in (
            "calibration_gap_estimate",
            "calibration_gap_person",
            "over_trust_rate",
            "under_trust_rate",
        ):
            assert 0.0 <= row[key] <= 1.0
    assert calibration(participants=2, steps=2, seed=0) == report  # seeded


def test_the_recording_gets_the_persons_trust_beside_kappa_and_risk_lines(model: TransferModel) -> None:
    from scone_bt.episode.snapshot import SnapshotBuilder

    events, lines = EventLog(), []
    builder = SnapshotBuilder(None, None, None, events, lines, trust=OnlineTrust(model))
    conf = {BOTTLE: 0.2, RICE: 0.9}
    by_text = {BOTTLE: "glass bottle", RICE: "bag of rice"}
    first = builder._person_trust(1.0, conf, by_text)
    assert set(first) == {"glass bottle", "bag of rice"} and lines[0].startswith(
        "over-trust risk: glass bottle"
    )
    events(ActOutcome(2.0, JAR, "glass jar", False, "grasp", 5.0))  # fed to the estimate at the next snapshot
    events(ActOutcome(3.0, JAR, "glass jar", False, "grasp", 5.0))
    after = builder._person_trust(4.0, conf, by_text)
    assert after["glass bottle"] < first["glass bottle"] and lines[-1].startswith(
        "under-trust risk: bag of rice"
    )
    assert len(events.events) == 2  # the estimate is drawn, never added to the episode's events
