import json
import urllib.error
import urllib.request

import pytest

from scone_bt.study.ui import UIError, serve_tablet


def _get(url: str, headers: dict | None = None) -> tuple[int, dict | str]:
    req = urllib.request.Request(url, headers=headers or {})
    try:
        with urllib.request.urlopen(req, timeout=10) as r:
            body = r.read().decode()
            return r.status, json.loads(body) if r.headers.get("content-type", "").startswith(
                "application/json"
            ) else body
    except urllib.error.HTTPError as exc:
        return exc.code, exc.read().decode()


def _post(url: str, body: object | None = None, headers: dict | None = None) -> int:
    data = None if body is None else json.dumps(body).encode()
    req = urllib.request.Request(
        url, data=data or b"", method="POST", headers={"Content-Type": "application/json", **(headers or {})}
    )
    try:
        with urllib.request.urlopen(req, timeout=10) as r:
            return r.status
    except urllib.error.HTTPError as exc:
        return exc.code


def test_network_binding_needs_a_token():
    with pytest.raises(UIError, match="needs a session token"):
        serve_tablet("0.0.0.0", 0, None)
    with pytest.raises(UIError, match="at least 8 characters"):
        serve_tablet("127.0.0.1", 0, "short")


def test_token_is_enforced_and_api_answers():
    with serve_tablet("127.0.0.1", 0, "abcdefgh-123") as server:
        base = server.url.split("?")[0]
        assert server.url.endswith("?token=abcdefgh-123")
        assert _get(base + "api/state")[0] == 403
        assert _get(base + "api/state", {"X-Session-Token": "wrong-token"})[0] == 403
        status, page = _get(server.url)
        assert status == 200 and "Take over" in page
        status, state = _get(base + "api/state", {"X-Session-Token": "abcdefgh-123"})
        assert status == 200 and state["phase"] == "waiting" and state["can_take_over"] is False
        auth = {"X-Session-Token": "abcdefgh-123"}
        assert _post(base + "api/takeover", headers=auth) == 409  # the robot is not acting
        assert _post(base + "api/requests/salt/done", headers=auth) == 409  # nothing pending
        assert _post(base + "api/questionnaires/mdmt", {"mdmt_reliable": 3}, headers=auth) == 422


def test_localhost_without_token():
    with serve_tablet("127.0.0.1", 0, None) as server:
        assert "token" not in server.url
        assert _get(server.url + "api/state")[0] == 200


# ---------------------------------------------------------------------------------------------- hardening (issue 18)
import http.client  # noqa: E402
import socket  # noqa: E402
import threading  # noqa: E402
import time  # noqa: E402

from scone_bt.study import MDMT_PERFORMANCE, StudyLog, plan_session  # noqa: E402
from scone_bt.study.ui import MAX_BODY_BYTES  # noqa: E402

TOKEN = "abcdefgh-123"


def _raw(port: int, method: str, path: str, headers: dict, body: bytes = b"") -> tuple[int, str]:
    conn = http.client.HTTPConnection("127.0.0.1", port, timeout=10)
    conn.putrequest(method, path, skip_host=True, skip_accept_encoding=True)
    for k, v in headers.items():
        conn.putheader(k, v)
    if body:
        conn.putheader("Content-Length", str(len(body)))
    conn.endheaders(body or None)
    r = conn.getresponse()
    out = r.status, r.read().decode()
    conn.close()
    return out


def test_token_is_checked_before_the_body_is_read():
    with serve_tablet("127.0.0.1", 0, TOKEN) as server:
        # announce 28 MB and send none of it: an answer proves the server did not wait for (or read) the body
        with socket.create_connection(("127.0.0.1", server.port), timeout=10) as s:
            s.sendall(
                b"POST /api/questionnaires/mdmt HTTP/1.1\r\nHost: 127.0.0.1\r\n"
                b"Content-Type: application/json\r\nContent-Length: 28000000\r\n\r\n"
            )
            head = s.recv(4096).decode()
        assert head.startswith("HTTP/1.1 403"), head


def test_body_size_limit_announced_and_streamed():
    with serve_tablet("127.0.0.1", 0, TOKEN) as server:
        auth = {"Host": "127.0.0.1", "X-Session-Token": TOKEN, "Content-Type": "application/json"}
        big = b'{"mdmt_reliable": ' + b" " * (MAX_BODY_BYTES + 10) + b"3}"
        status, _ = _raw(server.port, "POST", "/api/questionnaires/mdmt", auth, big)
        assert status == 413
        # chunked, no Content-Length: the limit counts the bytes actually received. Several times over: the
        # server once answered and closed while the client was still sending, and the client read a connection
        # reset instead of the 413 (it now reads the rest of a body a little too large before answering).
        for _ in range(10):
            with socket.create_connection(("127.0.0.1", server.port), timeout=10) as s:
                s.sendall(
                    b"POST /api/questionnaires/mdmt HTTP/1.1\r\nHost: 127.0.0.1\r\nX-Session-Token: "
                    + TOKEN.encode()
                    + b"\r\nContent-Type: application/json\r\nTransfer-Encoding: chunked\r\n\r\n"
                )
                chunk = b" " * 8192
                for _ in range(4):
                    s.sendall(f"{len(chunk):x}\r\n".encode() + chunk + b"\r\n")
                    time.sleep(0.002)  # separate packets: the server answers between two of them
                s.sendall(b"0\r\n\r\n")
                head = s.recv(4096).decode()
            assert head.startswith("HTTP/1.1 413"), head


def test_localhost_mode_checks_host_and_origin():
    with serve_tablet("127.0.0.1", 0, None) as server:
        port = server.port
        # DNS rebinding: a page at evil.example resolved to 127.0.0.1 sends Host: evil.example
        assert _raw(port, "GET", "/api/state", {"Host": f"evil.example:{port}"})[0] == 421
        for host in (f"127.0.0.1:{port}", f"localhost:{port}", "localhost"):
            assert _raw(port, "GET", "/api/state", {"Host": host})[0] == 200
        same = {"Host": f"127.0.0.1:{port}"}
        # a cross-site POST does not reach /api/takeover; a same-origin one does (409: the robot is not acting)
        assert _raw(port, "POST", "/api/takeover", {**same, "Origin": "http://evil.example"})[0] == 403
        assert _raw(port, "POST", "/api/takeover", {**same, "Origin": "null"})[0] == 403
        assert _raw(port, "POST", "/api/takeover", {**same, "Sec-Fetch-Site": "cross-site"})[0] == 403
        assert _raw(port, "POST", "/api/takeover", {**same, "Origin": f"http://127.0.0.1:{port}"})[0] == 409
        assert _raw(port, "POST", "/api/takeover", same)[0] == 409  # scripts send no Origin


def test_a_questionnaire_is_stored_once_under_concurrent_submissions(tmp_path):
    log = StudyLog(tmp_path / "study.db")
    sid = log.start_session(plan_session("P01", "A", 1))
    with serve_tablet("127.0.0.1", 0, TOKEN) as server:
        server.ask_questionnaires(lambda name, answers: log.record_responses(sid, name, answers))
        base = server.url.split("?")[0]
        results: list[tuple[int, int]] = []
        barrier = threading.Barrier(12)

        def submit(k: int) -> None:
            answers = {item.key: float(k % 8) for item in MDMT_PERFORMANCE.items}
            barrier.wait()
            results.append((k, _post(base + "api/questionnaires/mdmt", answers, {"X-Session-Token": TOKEN})))

        threads = [threading.Thread(target=submit, args=(k,)) for k in range(12)]
        for t in threads:
            t.start()
        for t in threads:
            t.join(30)
        assert sorted(code for _, code in results) == [200] + [409] * 11
        (winner,) = [k for k, code in results if code == 200]
        stored = [r for r in log.responses() if r.questionnaire == "mdmt"]
        assert len(stored) == len(MDMT_PERFORMANCE.items)
        assert {r.value for r in stored} == {float(winner % 8)}  # the first answers stand, not the last
        # later, the same answers again: refused, not overwritten
        again = {item.key: 7.0 for item in MDMT_PERFORMANCE.items}
        assert _post(base + "api/questionnaires/mdmt", again, {"X-Session-Token": TOKEN}) == 409
    log.close()


def test_wildcard_bind_prints_a_reachable_url_and_bad_ports_are_refused():
    with serve_tablet("0.0.0.0", 0, TOKEN) as server:
        host = server.url.split("//", 1)[1].split(":", 1)[0]
        assert host != "0.0.0.0" and host
        status, _ = _get(
            server.url.split("?")[0].replace(host, "127.0.0.1") + "api/state", {"X-Session-Token": TOKEN}
        )
        assert status == 200
    with pytest.raises(UIError, match="0..65535"):
        serve_tablet("127.0.0.1", 99999, None)


def test_a_port_in_use_or_a_host_that_does_not_resolve_is_one_line_saying_which(caplog):
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        with pytest.raises(UIError) as err:
            serve_tablet("127.0.0.1", port, None)
    assert str(err.value) == f"the tablet UI cannot listen on 127.0.0.1:{port}: address already in use"
    with pytest.raises(UIError) as err:
        serve_tablet("nosuch.invalid", 8765, TOKEN)
    assert str(err.value).startswith(
        "the tablet UI cannot listen on nosuch.invalid:8765: the host does not resolve"
    )
    assert "\n" not in str(err.value)
    assert not [r for r in caplog.records if r.name.startswith("uvicorn")]  # uvicorn never started to say it


# ---------------------------------------------------------------------------------------------- issue 27: write bodies
def _acting_tablet(server) -> dict[str, str]:  # noqa: ANN001
    server.state.start_episode(["Season with salt."], "bodies")
    server.state.set_acting("salt")  # a valid press would now take the action over
    return {"Host": f"127.0.0.1:{server.port}", "X-Session-Token": TOKEN, "Content-Type": "application/json"}


@pytest.mark.parametrize(
    ("body", "status"),
    [
        (b"{bad", 400),  # not JSON
        (b'{"mdmt_reliable": NaN}', 400),  # Python's json takes NaN; JSON does not
        (b"[]", 422),  # JSON, but not an object
        (b'{"object": "salt"}', 422),  # a key a press does not have
        (b"null", 422),
    ],
)
def test_a_malformed_press_takes_nothing_over(body, status):
    with serve_tablet("127.0.0.1", 0, TOKEN) as server:
        auth = _acting_tablet(server)
        assert _raw(server.port, "POST", "/api/takeover", auth, body)[0] == status
        assert _raw(server.port, "POST", "/api/requests/salt/done", auth, body)[0] == status
        assert server.state.takeover_object is None
        assert (
            _raw(server.port, "POST", "/api/takeover", auth, b"{}")[0] == 200
        )  # the same press, well formed
        assert server.state.takeover_object == "salt"


def test_a_body_shorter_than_its_content_length_takes_nothing_over():
    with serve_tablet("127.0.0.1", 0, TOKEN) as server:
        auth = _acting_tablet(server)
        head = "".join(f"{k}: {v}\r\n" for k, v in auth.items())
        request = f"POST /api/takeover HTTP/1.1\r\n{head}Content-Length: 100\r\n\r\n".encode() + b"{}"
        # the client sends 2 of 100 bytes and waits: refused once the body deadline passes, never taken over
        with socket.create_connection(("127.0.0.1", server.port), timeout=30) as s:
            s.sendall(request)
            chunks = []  # the head and the body may arrive in separate segments: read until the server closes
            while chunk := s.recv(4096):
                chunks.append(chunk)
            answer = b"".join(chunks).decode()
        assert answer.startswith("HTTP/1.1 400") and "incomplete request body" in answer, answer
        # the client sends 2 of 100 bytes and closes its side: refused (or just closed), never taken over
        with socket.create_connection(("127.0.0.1", server.port), timeout=30) as s:
            s.sendall(request)
            s.shutdown(socket.SHUT_WR)
            answer = s.recv(4096).decode()
        assert answer == "" or answer.startswith("HTTP/1.1 400"), answer
        assert server.state.takeover_object is None
        status, state = _raw(server.port, "GET", "/api/state", auth)
        assert status == 200 and json.loads(state)["can_take_over"] is True


def test_questionnaire_answers_are_checked_against_their_schema(tmp_path):
    log = StudyLog(tmp_path / "study.db")
    sid = log.start_session(plan_session("P01", "A", 1))
    with serve_tablet("127.0.0.1", 0, TOKEN) as server:
        server.ask_questionnaires(lambda name, answers: log.record_responses(sid, name, answers))
        auth = {
            "Host": f"127.0.0.1:{server.port}",
            "X-Session-Token": TOKEN,
            "Content-Type": "application/json",
        }
        good = {item.key: 3 for item in MDMT_PERFORMANCE.items}
        for body, status in (
            (b"{bad", 400),
            (
                json.dumps({**good, MDMT_PERFORMANCE.items[0].key: "3"}).encode(),
                422,
            ),  # a string, not a number
            (json.dumps({**good, MDMT_PERFORMANCE.items[0].key: True}).encode(), 422),  # a bool, not a number
            (json.dumps(list(good.values())).encode(), 422),
            (b"", 400),
        ):
            assert _raw(server.port, "POST", "/api/questionnaires/mdmt", auth, body)[0] == status, body
        assert log.responses() == []
        assert (
            _raw(server.port, "POST", "/api/questionnaires/mdmt", auth, json.dumps(good).encode())[0] == 200
        )
    log.close()


def test_the_start_gate_opens_once_from_the_tablet_or_the_researchers_page():
    with serve_tablet("127.0.0.1", 0, "abcdefgh-123", start_gate=True) as server:
        base, auth = server.url.split("?")[0], {"X-Session-Token": "abcdefgh-123"}
        assert _get(server.researcher_url)[0] == 200
        assert _get(base + "researcher")[0] == 403  # behind the same token
        state = server.state
        state.start_episode(["Boil water."])
        assert _get(base + "api/state", auth)[1]["can_start"] is False  # the robot is still being set up
        assert _post(base + "api/start", headers=auth) == 409
        state.ready_to_start()
        snap = _get(base + "api/state", auth)[1]
        assert snap["phase"] == "waiting" and snap["can_start"] is True and snap["started_by"] is None
        assert _post(base + "api/researcher/start", headers=auth) == 200
        assert _post(base + "api/start", headers=auth) == 409  # started already
        assert state.wait_start() == "researcher"
        snap = _get(base + "api/state", auth)[1]
        assert snap["phase"] == "episode" and snap["can_start"] is False
    with serve_tablet(
        "127.0.0.1", 0, None
    ) as server:  # no gate (scone-run --ui, --autostart): started at once
        assert server.state.wait_start() == "autostart" and _post(server.url + "api/start") == 409
