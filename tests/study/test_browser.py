"""Headless Chromium clicks through a help request, a take-over and the questionnaires on the tablet page."""

from __future__ import annotations

from scone_bt.events import ActStarted, DecisionMade, HelpRequested, Intervention
from scone_bt.gate.types import DecisionKind
from scone_bt.human import HumanOptions
from scone_bt.study import MDMT_PERFORMANCE, TPS_HRI_14, StudyLog
from scone_bt.study.ui import serve_tablet


def _tick_until(kitchen, human, condition, ticks: int = 200) -> None:
    for _ in range(ticks):
        if condition():
            return
        kitchen.advance(0.1)
        human.update()
    assert condition(), "the human did not act on the tablet's confirmation"


def test_help_takeover_and_questionnaire_in_chromium(kitchen, stocked, browser_page, tmp_path):
    page = browser_page
    log = StudyLog(tmp_path / "study.db")
    from scone_bt.study import plan_session

    sid = log.start_session(plan_session("P01", "A", 1))
    with serve_tablet("127.0.0.1", 0, "tablet-token-123") as server:
        human = server.human_factory(kitchen, stocked, HumanOptions(cook_time_s=0.2, patience_s=1e9), 0)
        on_event = server.chain(log.event_sink(sid))
        page.goto(server.url)
        page.wait_for_selector("#steps li.current")
        assert page.locator("#steps li").count() == len(stocked.steps)

        # --- help request: the robot waits until the participant taps "done"
        first, second = stocked.needed[0], stocked.needed[1]
        on_event(DecisionMade(0.0, 1, "step", f"Put {first} on table", 0.6, 0.21, DecisionKind.ASK))
        human.request_help(first)
        on_event(HelpRequested(0.0, f"Put {first} on table", first))
        done = page.locator(f'.request[data-object="{first}"] button.done')
        done.wait_for()
        assert "21 %" in page.locator("#confidence").inner_text()
        for _ in range(5):  # nothing happens before the participant confirms
            kitchen.advance(0.1)
            human.update()
        assert human.help_pending(first) and not kitchen.is_on_table(first)
        with page.expect_response("**/api/requests/*/done") as resp:
            done.click()
        assert resp.value.ok
        _tick_until(kitchen, human, lambda: not human.help_pending(first))
        assert kitchen.is_on_table(first) and human.help_given == 1
        page.locator(f'.request[data-object="{first}"]').wait_for(state="detached")

        # --- take-over: the button targets the robot's current action
        assert page.locator("#takeover").is_disabled()
        human.robot_busy(True)
        human.decide_takeover(second)
        on_event(ActStarted(0.0, f"Put {second} on table", second, 0.8))
        assert not human.wants_takeover(second)
        with page.expect_response("**/api/takeover") as resp:
            page.locator("#takeover:not([disabled])").click()
        assert resp.value.ok
        assert human.wants_takeover(second)  # what PickAndPlace polls; it then cancels its motion
        human.take_over(second)
        human.robot_busy(False)
        req = page.locator(f'.request[data-object="{second}"][data-kind="intervention"] button.done')
        with page.expect_response("**/api/requests/*/done"):
            req.click()
        _tick_until(kitchen, human, lambda: not human.is_fetching(second))
        assert kitchen.is_on_table(second) and human.interventions == 1
        intervention_events = [e for e in human.events if isinstance(e, Intervention)]
        assert [e.object_name for e in intervention_events] == [second]

        # --- questionnaires: MDMT then TPS-HRI, stored per item
        server.ask_questionnaires(lambda name, answers: log.record_responses(sid, name, answers))
        page.wait_for_selector("#form-mdmt")
        page.click("#submit-mdmt")  # incomplete: the page refuses and says why
        assert "Please answer every item" in page.locator("#error-mdmt").inner_text()
        for i, item in enumerate(MDMT_PERFORMANCE.items):
            value = "na" if i == 7 else str(i % 8)  # the page writes values as JSON numbers: "3", not "3.0"
            page.locator(f'.item[data-item="{item.key}"] input[value="{value}"] + span').click()
        with page.expect_response("**/api/questionnaires/mdmt"):
            page.click("#submit-mdmt")
        page.wait_for_selector("#form-tps_hri")
        for i, item in enumerate(TPS_HRI_14.items):
            page.locator(f'.item[data-item="{item.key}"] input[value="{10 * (i % 11)}"] + span').click()
        with page.expect_response("**/api/questionnaires/tps_hri"):
            page.click("#submit-tps_hri")
        page.locator("#thanks").wait_for(state="visible")
        assert server.wait_questionnaires(timeout=5)

    got = {(r.questionnaire, r.item): r.value for r in log.responses()}
    assert len(got) == 22
    assert got[("mdmt", "mdmt_meticulous")] is None  # "does not fit"
    assert got[("mdmt", "mdmt_predictable")] == 1.0
    assert got[("tps_hri", "tps_provide_feedback")] == 10 * (13 % 11)
    kinds = [e.kind for e in log.events(sid)]
    assert kinds == ["decision", "help_request", "act"]


def test_a_page_of_another_origin_cannot_take_over(browser_page, tmp_path):
    """In localhost mode a cross-site page in a real browser reaches neither /api/takeover nor /api/state."""
    import http.server
    import threading

    (tmp_path / "evil.html").write_text("<html><body>evil</body></html>")
    handler = lambda *a, **k: http.server.SimpleHTTPRequestHandler(*a, directory=str(tmp_path), **k)  # noqa: E731
    evil = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    threading.Thread(target=evil.serve_forever, daemon=True).start()
    try:
        with serve_tablet("127.0.0.1", 0, None) as server:
            server.state.set_acting("salt")  # the robot is acting: a take-over would be accepted
            page = browser_page
            page.goto(f"http://127.0.0.1:{evil.server_address[1]}/evil.html")
            target = f"http://127.0.0.1:{server.port}/api/takeover"
            page.evaluate(
                "url => fetch(url, {method: 'POST', mode: 'no-cors', body: 'x'}).catch(() => null)", target
            )
            page.wait_for_timeout(500)
            assert not server.state.wants_takeover("salt")  # refused: the Origin is not the tablet's
            # the same request from the tablet's own page is accepted
            page.goto(f"http://127.0.0.1:{server.port}/")
            status = page.evaluate("url => fetch(url, {method: 'POST'}).then(r => r.status)", target)
            assert status == 200 and server.state.wants_takeover("salt")
    finally:
        evil.shutdown()
