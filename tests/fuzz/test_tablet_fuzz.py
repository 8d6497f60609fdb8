"""Property-based fuzzing of every tablet endpoint over real HTTP (uvicorn on 127.0.0.1): random paths, methods,
headers, tokens and bodies (wrong types, huge numbers, NaN, unicode, deep nesting, random bytes).

Every answer is a known status with a JSON or HTML body, never a 500; nothing but a complete, valid questionnaire
is ever stored, and it is stored once.
"""

from __future__ import annotations

import http.client
import json
from urllib.parse import quote

import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from scone_bt.study import MDMT_PERFORMANCE, TPS_HRI_14, StudyLog, plan_session
from scone_bt.study.ui import serve_tablet

TOKEN = "fuzz-token-1234"
FUZZ = settings(
    derandomize=True,
    deadline=None,
    database=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture],
)
ALLOWED = {200, 400, 403, 404, 405, 409, 413, 421, 422}


@pytest.fixture(scope="module")
def tablet(tmp_path_factory):
    log = StudyLog(tmp_path_factory.mktemp("tablet") / "study.db")
    sid = log.start_session(plan_session("P01", "A", 1))
    server = serve_tablet("127.0.0.1", 0, TOKEN)
    server.state.start_episode(["Boil water.", "Cook pasta."], "fuzz")
    server.state.add_fetch("salt", "help")
    server.ask_questionnaires(lambda name, answers: log.record_responses(sid, name, answers))
    yield server, log
    server.close()
    log.close()


def _send(
    port: int, method: str, path: str, headers: dict[str, str], body: bytes | None
) -> tuple[int, bytes, str]:
    conn = http.client.HTTPConnection("127.0.0.1", port, timeout=15)
    try:
        conn.putrequest(method, path, skip_host=True, skip_accept_encoding=True)
        for k, v in headers.items():
            conn.putheader(k, v)
        if body is not None:
            conn.putheader("Content-Length", str(len(body)))
        conn.endheaders(body)
        r = conn.getresponse()
        return r.status, r.read(), r.headers.get("content-type", "")
    finally:
        conn.close()


JSON_VALUES = st.recursive(
    st.one_of(
        st.none(),
        st.booleans(),
        st.integers(min_value=-(2**80), max_value=2**80),
        st.floats(allow_nan=False, allow_infinity=False),
        st.text(max_size=30),
    ),
    lambda inner: st.one_of(
        st.lists(inner, max_size=4), st.dictionaries(st.text(max_size=20), inner, max_size=6)
    ),
    max_leaves=20,
)
ITEM_KEYS = [i.key for i in MDMT_PERFORMANCE.items] + [i.key for i in TPS_HRI_14.items]


@st.composite
def bodies(draw) -> bytes | None:
    kind = draw(st.sampled_from(["none", "json", "answers", "nan", "bytes", "deep"]))
    if kind == "none":
        return None
    if kind == "json":
        return json.dumps(draw(JSON_VALUES)).encode()
    if kind == "answers":  # the right shape, values and keys drawn widely
        keys = draw(st.lists(st.sampled_from([*ITEM_KEYS, "x", ""]), max_size=16, unique=True))
        values = st.one_of(
            st.integers(-3, 120), st.floats(allow_nan=False), st.none(), st.text(max_size=4), st.booleans()
        )
        return json.dumps({k: draw(values) for k in keys}).encode()
    if kind == "nan":
        return b'{"mdmt_reliable": NaN, "mdmt_capable": Infinity, "x": -Infinity}'
    if kind == "deep":
        return b"[" * draw(st.integers(100, 5000)) + b"]" * draw(st.integers(0, 10))
    return draw(st.binary(max_size=2048))


PATHS = st.one_of(
    st.sampled_from(
        [
            "/",
            "/api/state",
            "/api/takeover",
            "/api/requests/salt/done",
            "/api/questionnaires/mdmt",
            "/api/questionnaires/tps_hri",
            "/api/questionnaires/nope",
            "/docs",
            "/openapi.json",
        ]
    ),
    st.builds(lambda s: "/api/requests/" + quote(s, safe="") + "/done", st.text(max_size=40)),
    st.builds(lambda s: "/api/questionnaires/" + quote(s, safe=""), st.text(max_size=40)),
    st.builds(lambda s: "/" + quote(s, safe="/"), st.text(max_size=60)),
)


@settings(FUZZ, max_examples=200)
@given(
    method=st.sampled_from(["GET", "POST", "PUT", "DELETE", "PATCH", "HEAD", "OPTIONS"]),
    path=PATHS,
    token=st.one_of(
        st.just(TOKEN),
        st.just(None),
        st.text(st.characters(min_codepoint=33, max_codepoint=126), max_size=20),
    ),
    in_query=st.booleans(),
    origin=st.sampled_from([None, "http://evil.example", "null", "SELF"]),
    host=st.sampled_from(["SELF", "localhost", "evil.example", ""]),
    body=bodies(),
)
@example(
    method="POST",
    path="/api/questionnaires/mdmt",
    token=None,
    in_query=False,
    origin=None,
    host="SELF",
    body=b"x" * 30_000,
)
@example(
    method="POST",
    path="/api/takeover",
    token=TOKEN,
    in_query=False,
    origin="http://evil.example",
    host="SELF",
    body=None,
)
@example(
    method="GET", path="/api/state", token=TOKEN, in_query=False, origin=None, host="evil.example", body=None
)
@example(
    method="POST",
    path="/api/questionnaires/mdmt",
    token=TOKEN,
    in_query=False,
    origin=None,
    host="SELF",
    body=b"[" * 5000,
)
def test_every_endpoint_answers_with_a_known_status(
    tablet, fuzz_counts, method, path, token, in_query, origin, host, body
):
    server, log = tablet
    fuzz_counts["tablet endpoints"] = fuzz_counts.get("tablet endpoints", 0) + 1
    port = server.port
    headers = {"Host": f"127.0.0.1:{port}" if host == "SELF" else host}
    if token is not None and not in_query:
        headers["X-Session-Token"] = token
    if token is not None and in_query:
        path += ("&" if "?" in path else "?") + "token=" + quote(token)
    if origin is not None:
        headers["Origin"] = f"http://127.0.0.1:{port}" if origin == "SELF" else origin
    if body is not None:
        headers["Content-Type"] = "application/json"
    status, data, ctype = _send(port, method, path, headers, body)
    assert status in ALLOWED, (status, data[:200])
    if status == 400 and ctype.startswith("text/plain"):
        return  # uvicorn refused a malformed request line or header before the app saw it
    if method != "HEAD" and data:
        assert ctype.startswith(("application/json", "text/html")), ctype
        if ctype.startswith("application/json"):
            json.loads(data)
    if host not in ("SELF", "localhost"):
        assert status == 421  # DNS rebinding: refused whatever else the request carries
    elif token != TOKEN:
        assert status == 403  # before the body is looked at
    # stored answers are only ever complete questionnaires, each stored once
    stored: dict[str, int] = {}
    for r in log.responses():
        stored[r.questionnaire] = stored.get(r.questionnaire, 0) + 1
    assert all(
        n == len({"mdmt": MDMT_PERFORMANCE, "tps_hri": TPS_HRI_14}[q].items) for q, n in stored.items()
    )
    assert (
        _send(port, "GET", "/api/state", {"Host": f"127.0.0.1:{port}", "X-Session-Token": TOKEN}, None)[0]
        == 200
    )
