"""The tablet tells the participant why a heft test set a product back, in the robot's words, whether the fingers
felt it slip or κ̂ stayed unsure after feeling it (gate.after_probe), and then asks for it the same way."""

from __future__ import annotations

import pytest

from scone_bt.events import ActStarted, DecisionMade, HelpRequested, ProbeAborted
from scone_bt.gate.types import DecisionKind
from scone_bt.study.ui import TabletServer

OIL = "Put olive oil on table"


@pytest.mark.parametrize(
    "reason", ["the olive oil slips in my fingers", "I am not sure I can carry the olive oil"]
)
def test_a_set_back_reaches_the_tablet_in_the_robots_words(reason: str) -> None:
    def decision(t: float, kind: DecisionKind, **more: object) -> DecisionMade:
        return DecisionMade(t, 1, "Add oil.", OIL, 0.6, 0.5, kind, "now", (), "olive oil", **more)  # type: ignore[arg-type]

    with TabletServer("127.0.0.1", 0, None) as server:
        server.state.start_episode(["Add oil."])
        for event in (
            decision(0.5, DecisionKind.ACT, probe=True),
            ActStarted(0.5, OIL, "olive oil", 0.5),
            ProbeAborted(9.0, OIL, "olive oil", reason, 8.0, 0.9, 2.1),
            decision(9.1, DecisionKind.ASK, reason=f"{reason}: please bring it", rule="probe"),
            HelpRequested(9.1, OIL, "olive oil"),
        ):
            server.on_event(event)
        shown = server.state.snapshot()
    said = reason[0].upper() + reason[1:]
    assert shown["robot"]["status"] == "asking" and shown["robot"]["say"] == f"{said}: please bring it."
    assert f"The robot hefted the olive oil and set it back: {reason}." in shown["feed"]


def test_the_tablet_announces_a_heft_before_the_arm_lifts() -> None:
    heft = DecisionMade(
        0.5, 1, "Add oil.", OIL, 0.6, 0.5, DecisionKind.ACT, "now", (), "olive oil", probe=True
    )
    with TabletServer("127.0.0.1", 0, None) as server:
        server.state.start_episode(["Add oil."])
        server.on_event(heft)
        shown = server.state.snapshot()
    assert shown["robot"]["say"].startswith(
        "I am not sure about the olive oil: I will lift it a little first"
    )
