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
