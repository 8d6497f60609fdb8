"""The person's estimated trust on the tablet's study view: always on the researcher's page, on the participant's
tablet only while the researcher shows it; the switch's route takes only {"shown": true|false}."""

from __future__ import annotations

import pytest

from scone_bt.events import ActOutcome, DecisionMade
from scone_bt.gate.types import DecisionKind
from scone_bt.study.tablet import TabletState
from scone_bt.study.trust_view import RISK_WORDS, BlackboardOffer, TrustView
from scone_bt.study.ui import TabletServer, build_app

JAR, RICE = "Put the glass jar on table", "Put the bag of rice on table"
OFFER = {JAR: ("glass jar", 0.2), RICE: ("bag of rice", 0.9)}


@pytest.fixture(scope="module")
def online_trust():  # noqa: ANN201 - builds OnlineTrust objects on one fitted model (ζ loads once)
    from scone_bt.trust.estimate import OnlineTrust
    from scone_bt.trust.transfer import TransferModel, load_fitted

    model = TransferModel(load_fitted())
    return lambda: OnlineTrust(model)


def _decision(t: float, action: str = JAR, obj: str = "glass jar", kappa: float = 0.2) -> DecisionMade:
    return DecisionMade(t, 1, "Put the jar away.", action, 0.7, kappa, DecisionKind.ACT, object_name=obj)


@pytest.fixture
def server(online_trust):  # noqa: ANN001, ANN201 - a TabletServer whose view offers the jar and the rice
    view = TrustView(online_trust, offered=lambda decision: OFFER)
    with TabletServer("127.0.0.1", 0, None, trust_view=view) as running:
        running.state.start_episode(["Put the jar away."])
        yield running


@pytest.fixture
def client(server):  # noqa: ANN001, ANN201
    from fastapi.testclient import TestClient

    return TestClient(build_app(server.state, None), base_url="http://localhost")


def test_hidden_from_the_participant_until_the_researcher_shows_it(server, client) -> None:
    switched: list[bool] = []
    server.state.on_trust_view = switched.append
    server.on_event(_decision(1.0))

    participant = client.get("/api/state")
    assert participant.status_code == 200 and "trust" not in participant.json()
    assert "over-trust" not in participant.text and "bag of rice" not in participant.text
    researcher = client.get("/api/researcher/state").json()
    assert researcher["trust_shown"] is False
    rows = researcher["trust"]
    assert [(r["object"], r["confidence"], r["risk"]) for r in rows] == [
        ("glass jar", 0.2, "over"),  # the person likely trusts it (~0.7) far above κ̂ 0.2
        ("bag of rice", 0.9, ""),
    ]
    assert rows[0]["words"] == RISK_WORDS["over"] and 0.0 <= rows[1]["trust"] <= 1.0

    answer = client.post("/api/researcher/trust-view", json={"shown": True})
    assert answer.status_code == 200 and answer.json() == {"ok": True, "shown": True, "changed": True}
    shown = client.get("/api/state").json()
    assert (
        shown["trust"] == rows and "trust_shown" not in shown
    )  # the participant sees the rows, not the switch
    assert client.post("/api/researcher/trust-view", json={"shown": True}).json()["changed"] is False
    assert client.post("/api/researcher/trust-view", json={"shown": False}).json()["changed"] is True
    assert "trust" not in client.get("/api/state").json()
    assert switched == [True, False]  # each change once (the study session stores them)
    assert "trust" in client.get("/api/researcher/state").json()  # the researcher's page always has it


def test_updated_as_the_person_sees_outcomes(server) -> None:
    server.on_event(_decision(1.0))
    before = {r["object"]: r for r in server.state.snapshot(researcher=True)["trust"]}
    for t in (2.0, 3.0):
        server.on_event(ActOutcome(t, JAR, "glass jar", False, "grasp", 5.0))
    assert server.state.snapshot(researcher=True)["trust"] == list(before.values())  # until the next decision
    server.on_event(_decision(4.0))
    after = {r["object"]: r for r in server.state.snapshot(researcher=True)["trust"]}
    assert after["glass jar"]["trust"] < before["glass jar"]["trust"] - 0.1
    assert after["glass jar"]["risk"] == ""  # two drops seen: the person no longer over-trusts the jar
    assert after["bag of rice"]["risk"] == "under"  # a similar action failed, yet κ̂ is 0.9
    server.state.start_episode(["Next."])  # a new episode starts with no estimate; the switch stays as set
    assert server.state.snapshot(researcher=True)["trust"] == []


@pytest.mark.parametrize(
    "body",
    [
        b'{"shown": "true"}',
        b'{"shown": 1}',
        b'{"shown": null}',
        b"{}",
        b'{"shown": true, "also": 1}',
        b"[true]",
        b"true",
        b"not json",
        b"",
    ],
)
def test_the_switch_takes_only_a_boolean(client, server, body: bytes) -> None:
    answer = client.post(
        "/api/researcher/trust-view", content=body, headers={"Content-Type": "application/json"}
    )
    assert answer.status_code in (400, 422), answer.text
    assert answer.json()["detail"]
    assert server.state.trust_shown is False


def test_shown_from_the_start_when_asked(online_trust) -> None:
    from fastapi.testclient import TestClient

    state = TabletState(trust_shown=True)
    state.set_trust([{"object": "glass jar", "trust": 0.7, "confidence": 0.2, "risk": "over", "words": "w"}])
    client = TestClient(build_app(state, None), base_url="http://localhost")
    assert client.get("/api/state").json()["trust"][0]["object"] == "glass jar"
    page = client.get("/").text
    assert 'id="trust-card" class="hidden"' in page  # drawn only when the state carries rows
    assert 'id="trust-shown"' in client.get("/researcher").text


def test_the_blackboard_offer_is_every_scored_action_with_a_finite_kappa() -> None:
    import py_trees

    from scone_bt.affordances.types import Affordance
    from scone_bt.behaviours.base import Keys

    offer = BlackboardOffer()
    decision = _decision(1.0, kappa=0.3)
    assert offer(decision) == {JAR: ("glass jar", 0.3)}  # no tree: the decision's own action
    writer = py_trees.blackboard.Client(name="gate-test")
    for key in (Keys.CONFIDENCES, Keys.AFFORDANCES):
        writer.register_key(key=key, access=py_trees.common.Access.WRITE)
    try:
        writer.set(Keys.AFFORDANCES, [Affordance(n, t, None) for t, (n, _) in OFFER.items()])  # type: ignore[arg-type]
        writer.set(Keys.CONFIDENCES, {RICE: 0.8, JAR: 0.3, "Put the ghost on table": 0.5})
        assert offer(decision) == {RICE: ("bag of rice", 0.8), JAR: ("glass jar", 0.3)}  # the gate's order
        writer.set(Keys.CONFIDENCES, {RICE: float("nan"), JAR: 0.3})
        assert offer(decision) == {JAR: ("glass jar", 0.3)}
    finally:
        py_trees.blackboard.Blackboard.clear()
