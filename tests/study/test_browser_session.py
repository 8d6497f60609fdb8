"""A whole study session in a real browser: `scone-study session` runs as a participant's session would, and
headless Chromium at tablet size (1024×768) presses Start, answers a help request, takes over once and fills both
questionnaires; the researcher's page shows the person's estimated trust and shows it on the tablet, then hides it
again. Screenshots of each stage go to runs/browser-session/ (CI artifacts)."""

from __future__ import annotations

import json
import os
import socket
import subprocess
import sys
import time
import urllib.request
from pathlib import Path

import pytest

from scone_bt.study import MDMT_PERFORMANCE, TPS_HRI_14, StudyLog

ROOT = Path(__file__).resolve().parents[2]
RECIPE = Path(__file__).parent / "data" / "salted-yogurt.yaml"
SHOTS = ROOT / "runs" / "browser-session"
TOKEN = "tablet-token-2026"
VIEWPORT = {"width": 1024, "height": 768}


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def _wait_for_server(url: str, process: subprocess.Popen, log: Path, timeout_s: float = 300.0) -> None:
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if process.poll() is not None:
            pytest.fail(f"scone-study session exited with {process.returncode}:\n{log.read_text()[-3000:]}")
        try:
            with urllib.request.urlopen(
                urllib.request.Request(url, headers={"X-Session-Token": TOKEN}), timeout=2
            ) as r:
                if r.status == 200:
                    return
        except OSError:
            pass
        time.sleep(0.5)
    pytest.fail(f"the tablet server did not answer within {timeout_s:.0f} s:\n{log.read_text()[-3000:]}")


def _fits_the_screen(page, stage: str) -> None:
    """Nothing is cut off at tablet size: no horizontal overflow; then a screenshot of the stage."""
    overflow = page.evaluate(
        "() => document.documentElement.scrollWidth - document.documentElement.clientWidth"
    )
    assert overflow <= 0, f"{stage}: the page is {overflow} px wider than the screen"
    SHOTS.mkdir(parents=True, exist_ok=True)
    page.screenshot(path=str(SHOTS / f"{stage}.png"))


def _submit_reachable(page, name: str) -> None:
    """The questionnaire's Submit is on screen without scrolling (sticky), at the top and the bottom of the form."""
    for where in ("top", "bottom"):
        page.evaluate(f"() => window.scrollTo(0, {'0' if where == 'top' else 'document.body.scrollHeight'})")
        box = page.locator(f"#submit-{name}").bounding_box()
        assert box is not None and box["y"] >= 0 and box["y"] + box["height"] <= VIEWPORT["height"], (
            where,
            box,
        )
        assert box["height"] >= 44


def _answer(page, name: str, items, values) -> None:
    """Click each item's answer and check that the validation message follows (it counts what is left)."""
    page.click(f"#submit-{name}")  # nothing answered: the page refuses and says what is missing
    error = page.locator(f"#error-{name}")
    assert f"Please answer every item ({len(items)} left" in error.inner_text()
    heights = page.evaluate(
        f"() => [...document.querySelectorAll('#form-{name} .scale span')].map(s => s.getBoundingClientRect().height)"
    )
    assert min(heights) >= 44, f"answer chips {min(heights)} px high"
    for i, (item, value) in enumerate(zip(items, values, strict=True)):
        page.locator(f'fieldset[data-item="{item.key}"] input[value="{value}"] + span').click()
        left = len(items) - i - 1
        if left:
            assert f"({left} left" in error.inner_text()
            assert page.locator(f'fieldset[data-item="{item.key}"]').get_attribute("aria-invalid") == "false"
    assert error.inner_text() == ""  # cleared as the last item was answered


@pytest.mark.slow
def test_a_whole_session_in_chromium(browser_page, tmp_path):
    page = browser_page
    page.set_viewport_size(VIEWPORT)
    db, port, out = tmp_path / "study.db", _free_port(), tmp_path / "session.log"
    argv = [
        sys.executable, "-m", "scone_bt.study.cli", "session", "--db", str(db), "--participant", "P07",
        "--group", "B", "--session", "1", "--recipe", str(RECIPE), "--distractors", "0",
        "--port", str(port), "--token", TOKEN,
    ]  # fmt: skip
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    with out.open("w") as sink:
        process = subprocess.Popen(argv, cwd=ROOT, env=env, stdout=sink, stderr=subprocess.STDOUT)
    try:
        base = f"http://127.0.0.1:{port}/"
        _wait_for_server(base + "api/state", process, out)
        page.goto(f"{base}?token={TOKEN}")

        # --- the start gate: nothing happens until Start
        page.locator("#start:not([disabled])").wait_for(
            timeout=300_000
        )  # the robot is set up (models loaded)
        assert page.locator("#action").inner_text() == "Waiting to start"
        assert page.locator("#steps li").count() == 2
        _fits_the_screen(page, "1-waiting-to-start")
        with page.expect_response("**/api/start"):
            page.click("#start")
        researcher = page.context.new_page()  # the researcher's page, behind the same token
        researcher.set_viewport_size(VIEWPORT)
        researcher.goto(f"{base}researcher?token={TOKEN}")
        researcher.wait_for_function("document.getElementById('phase').textContent.includes('participant')")
        assert researcher.locator("#start").is_disabled()  # started already, by the participant

        # --- the person's estimated trust: on the researcher's page always, on the tablet once switched on
        researcher.locator("#trust tr").first.wait_for(timeout=120_000)  # the robot's first decision
        assert not researcher.locator("#trust-shown").is_checked()  # hidden from the participant by default
        assert "Hidden from the participant" in researcher.locator("#trust-note").inner_text()
        assert researcher.locator('#trust tr[data-object="yogurt"] td').count() == 4
        assert page.locator("#trust-card").is_hidden() and page.locator("#trust tr").count() == 0
        _fits_the_screen(researcher, "0-researcher-page")
        with researcher.expect_response("**/api/researcher/trust-view") as switched:
            researcher.click("#trust-shown")
        assert switched.value.ok and researcher.locator("#trust-shown").is_checked()
        page.locator('#trust-card #trust tr[data-object="yogurt"]').wait_for()  # the participant sees it now
        assert "%" in page.locator('#trust tr[data-object="yogurt"]').inner_text()

        # --- the control condition fails the yogurt three times, then asks: the card says why
        request = page.locator('.request[data-object="yogurt"][data-kind="help"]')
        request.wait_for(timeout=240_000)
        assert "I have failed three times with the yogurt." in request.locator(".why").inner_text()
        assert "confident" not in page.locator("#say").inner_text()  # κ̂ did not decide in this condition
        _fits_the_screen(page, "2-help-request")
        with page.expect_response("**/api/requests/*/done"):
            request.locator("button.done").click()
        with researcher.expect_response("**/api/researcher/trust-view"):
            researcher.click("#trust-shown")  # the researcher hides it again
        page.locator("#trust-card").wait_for(state="hidden")
        researcher.close()

        # --- the salt: announced with Take over for the window, before the arm moves
        takeover = page.locator("#takeover:not([disabled])", has_text="Take over: salt")
        takeover.wait_for(timeout=240_000)
        assert "before it moves" in page.locator("#window").inner_text()
        _fits_the_screen(page, "3-take-over-window")
        with page.expect_response("**/api/takeover") as taken:
            takeover.click()
        assert taken.value.ok
        brought = page.locator('.request[data-object="salt"][data-kind="intervention"]')
        brought.wait_for()
        _fits_the_screen(page, "4-after-take-over")
        with page.expect_response("**/api/requests/*/done"):
            brought.locator("button.done").click()

        # --- questionnaire 1 of 2 (MDMT): progress, validation, sticky Submit, touch targets
        page.wait_for_selector("#form-mdmt", timeout=120_000)
        assert page.locator("#progress").inner_text() == "Questionnaire 1 of 2"
        _submit_reachable(page, "mdmt")
        mdmt = ["na" if i == 7 else str(i % 8) for i in range(len(MDMT_PERFORMANCE.items))]
        _answer(page, "mdmt", MDMT_PERFORMANCE.items, mdmt)
        page.evaluate("() => window.scrollTo(0, 0)")
        _fits_the_screen(page, "5-questionnaire-1-of-2")
        with page.expect_response("**/api/questionnaires/mdmt"):
            page.click("#submit-mdmt")

        # --- questionnaire 2 of 2 (TPS-HRI)
        page.wait_for_selector("#form-tps_hri")
        assert page.locator("#progress").inner_text() == "Questionnaire 2 of 2"
        _submit_reachable(page, "tps_hri")
        tps = [str(10 * ((3 * i) % 11)) for i in range(len(TPS_HRI_14.items))]
        _answer(page, "tps_hri", TPS_HRI_14.items, tps)
        page.evaluate("() => window.scrollTo(0, document.body.scrollHeight)")
        _fits_the_screen(page, "6-questionnaire-2-of-2")
        with page.expect_response("**/api/questionnaires/tps_hri"):
            page.click("#submit-tps_hri")

        # --- the end: the page says so and stops polling
        page.locator("#thanks").wait_for(state="visible")
        assert "The session is over" in page.locator("#thanks").inner_text()
        polls: list[str] = []
        page.on("request", lambda r: polls.append(r.url) if "api/state" in r.url else None)
        page.wait_for_timeout(1500)
        assert polls == []
        _fits_the_screen(page, "7-session-over")
        assert process.wait(timeout=120) == 0, out.read_text()[-3000:]
    finally:
        if process.poll() is None:
            process.kill()
            process.wait()

    # --- what the study log holds
    log = StudyLog(db, readonly=True)
    try:
        (session,) = log.sessions()
        assert (session.participant, session.group, session.condition) == ("P07", "B", "off")
        assert session.info["takeover_window_s"] == 2.0 and session.ended is not None
        got = {(r.questionnaire, r.item): r.value for r in log.responses()}
        want = {
            ("mdmt", it.key): None if v == "na" else float(v)
            for it, v in zip(MDMT_PERFORMANCE.items, mdmt, strict=True)
        }
        want |= {("tps_hri", it.key): float(v) for it, v in zip(TPS_HRI_14.items, tps, strict=True)}
        assert got == want  # every stored answer is the one clicked (22 of 22)
        events = log.events(session.id)
        kinds = [e.kind for e in events]
        assert kinds[0] == "start" and events[0].data["by"] == "participant"
        assert session.info["trust_shown"] is False
        assert [e.data["shown"] for e in events if e.kind == "trust_view"] == [True, False]
        assert all(e.data["window_s"] == 2.0 for e in events if e.kind == "act")
        assert kinds.count("help_request") == 1 and kinds.count("takeover") == 1
        assert log.intervention_causes(session.id) == {"takeover": 1, "dropped": 0, "idle": 0, "by-hand": 0}
        assert session.summary["interventions"] == log.interventions(session.id) == 1
        said = json.dumps([e.data for e in events if e.kind == "decision"])
        assert "failure-limit" in said
    finally:
        log.close()
