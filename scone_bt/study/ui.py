"""The tablet web UI: a FastAPI app served by uvicorn in a background thread.

`serve_tablet(host, port, token)` is what `scone-run --ui` and `scone-study session` call. It binds to localhost by
default; any other address requires a session token, which every request must carry (``?token=`` on the page URL,
the page then sends it as the ``X-Session-Token`` header).
"""

from __future__ import annotations

import asyncio
import contextlib
import hmac
import ipaddress
import json
import math
import threading
import time
from collections.abc import Callable, Sequence
from importlib import resources
from typing import Any

from scone_bt.errors import SconeError
from scone_bt.events import (
    ActOutcome,
    ActStarted,
    DecisionMade,
    Event,
    EventSink,
    HelpRequested,
    ProbeAborted,
    TakeOver,
)
from scone_bt.gate.types import DecisionKind
from scone_bt.study.questionnaires import QUESTIONNAIRES, Questionnaire
from scone_bt.study.tablet import AlreadySubmittedError, TabletHuman, TabletState
from scone_bt.study.trust_view import TrustView
from scone_bt.study.ui_args import MIN_TOKEN_LENGTH, add_ui_arguments

__all__ = [
    "TabletServer",
    "serve_tablet",
    "build_app",
    "LOCAL_HOSTS",
    "UIError",
    "add_ui_arguments",
    "tablet_from_args",
    "RequestGuard",
    "MAX_BODY_BYTES",
    "DRAIN_BYTES",
    "BODY_TIMEOUT_S",
    "reachable_address",
]

LOCAL_HOSTS = ("127.0.0.1", "localhost", "::1")
MAX_BODY_BYTES = 16 * 1024
"""Largest request body accepted (a questionnaire's answers are well under 1 kB): a larger Content-Length gets 413
unread; a larger chunked body gets 413 once it passed this, after the rest of it was read (up to DRAIN_BYTES)."""
DRAIN_BYTES = 1024 * 1024
"""Most bytes of a refused streamed body (chunked, past MAX_BODY_BYTES) read and dropped before the 413 goes out: a
client still sending when the answer and the close came would read a connection reset instead of the 413."""
BODY_TIMEOUT_S = 3.0
"""A write request's whole body (as many bytes as its Content-Length says) must arrive within this many seconds;
a shorter body gets 400 and is not handed to the endpoint (a tablet sends under 1 kB in one packet)."""
_WRITE_METHODS_EXEMPT = ("GET", "HEAD", "OPTIONS")


_STATUS = {
    DecisionKind.ACT: "deciding",
    DecisionKind.ASK: "asking",
    DecisionKind.CLARIFY: "asking which",
    DecisionKind.IDLE: "waiting",
}
"""What the tablet says the robot is doing after each kind of decision."""


def _finite(value: float | None) -> float | None:
    return None if value is None or not math.isfinite(value) else value


class UIError(SconeError):
    """The tablet server cannot start as asked."""


def _is_local(host: str) -> bool:
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


def _host_name(host_header: str) -> str:
    """The host part of a Host header ("[::1]:8765" → "::1", "localhost:80" → "localhost")."""
    h = host_header.strip().lower()
    if h.startswith("["):
        return h[1 : h.find("]")] if "]" in h else h
    return h.rsplit(":", 1)[0] if h.count(":") == 1 else h


def _origin_host(origin: str) -> str | None:
    """The host[:port] of an Origin header, or None for "null" and malformed values."""
    from urllib.parse import urlsplit

    try:
        parts = urlsplit(origin.strip())
    except ValueError:
        return None
    return parts.netloc.lower() if parts.scheme in ("http", "https") and parts.netloc else None


class RequestGuard:
    """ASGI middleware that refuses a request before its body is read.

    In order: the Host header (in localhost mode only local names, against DNS rebinding), the session token
    (header or ``?token=``), the body size (Content-Length and the bytes actually received), and for writes the
    Origin (only same-origin browser requests; clients without an Origin, such as scripts, are not browsers).
    A write's body is then read whole before the endpoint runs: one that stops short of its Content-Length (the
    client went away, or sent less and waits) gets 400 within `body_timeout_s` and the endpoint never runs.
    """

    def __init__(
        self,
        app: Any,
        token: str | None,
        local_only: bool,
        max_body: int = MAX_BODY_BYTES,
        body_timeout_s: float = BODY_TIMEOUT_S,
    ) -> None:
        self.app = app
        self.token = token
        self.local_only = local_only
        self.max_body = max_body
        self.body_timeout_s = body_timeout_s

    async def _whole_body(self, receive: Any, send: Any, length: str | None) -> bytes | None:
        """The complete body of a write, or None once it was refused (400 short, 413 large) or the client left."""
        expected = int(length) if length is not None else None
        loop = asyncio.get_running_loop()
        deadline = loop.time() + self.body_timeout_s
        chunks: list[bytes] = []
        received = 0
        while True:
            try:
                message = await asyncio.wait_for(receive(), max(0.0, deadline - loop.time()))
            except TimeoutError:
                message = None
            if message is None or message["type"] == "http.disconnect":
                said = f"Content-Length {expected}" if expected is not None else "a chunked body"
                with contextlib.suppress(Exception):  # the client may be gone: nobody to answer
                    await self._refuse(
                        send,
                        400,
                        f"incomplete request body: {said}, {received} bytes arrived "
                        f"{'before the client closed' if message is not None else f'within {self.body_timeout_s:g} s'}",
                    )
                return None
            chunk = message.get("body", b"")
            received += len(chunk)
            if received > self.max_body:
                await self._drain(receive, message, deadline)
                await self._refuse(send, 413, f"request body larger than {self.max_body} bytes")
                return None
            chunks.append(chunk)
            if not message.get("more_body", False):
                break
        if (
            expected is not None and received != expected
        ):  # the HTTP layer checks this too; never trust one layer
            await self._refuse(send, 400, f"request body of {received} bytes, Content-Length said {expected}")
            return None
        return b"".join(chunks)

    @staticmethod
    async def _drain(receive: Any, message: dict, deadline: float) -> None:
        """Read and drop the rest of a refused body, up to DRAIN_BYTES and until `deadline` (the loop's clock).

        Closing a connection with unread bytes makes the kernel reset it, and the client, still sending, then loses
        the answer: a body a little too large is read to its end, so that the 413 arrives.
        """
        loop = asyncio.get_running_loop()
        dropped = 0
        while message.get("more_body", False) and dropped <= DRAIN_BYTES:
            try:
                message = await asyncio.wait_for(receive(), max(0.0, deadline - loop.time()))
            except TimeoutError:
                return
            if message["type"] == "http.disconnect":
                return
            dropped += len(message.get("body", b""))

    async def _refuse(self, send: Any, status: int, detail: str) -> None:
        import json

        body = json.dumps({"detail": detail}).encode()
        await send(
            {
                "type": "http.response.start",
                "status": status,
                "headers": [
                    (b"content-type", b"application/json"),
                    (b"content-length", str(len(body)).encode()),
                    (b"connection", b"close"),
                ],
            }
        )
        await send({"type": "http.response.body", "body": body})

    async def __call__(self, scope: dict, receive: Any, send: Any) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        headers = {k.decode("latin-1").lower(): v.decode("latin-1") for k, v in scope.get("headers", [])}
        host = headers.get("host", "")
        if self.local_only and _host_name(host) not in LOCAL_HOSTS:
            await self._refuse(send, 421, "this tablet server answers only to localhost, 127.0.0.1 or [::1]")
            return
        if self.token is not None:
            from urllib.parse import parse_qs

            query = parse_qs(scope.get("query_string", b"").decode("latin-1"))
            given = headers.get("x-session-token") or (query.get("token") or [""])[0]
            if not hmac.compare_digest(given.encode("utf-8", "replace"), self.token.encode()):
                await self._refuse(send, 403, "missing or wrong session token")
                return
        length = headers.get("content-length")
        if length is not None and (not length.isdigit() or int(length) > self.max_body):
            await self._refuse(send, 413, f"request body larger than {self.max_body} bytes")
            return
        if scope.get("method") not in ("GET", "HEAD", "OPTIONS"):
            origin = headers.get("origin")
            if origin is not None and _origin_host(origin) != host.lower():
                await self._refuse(send, 403, "cross-origin write refused")
                return
            if headers.get("sec-fetch-site", "same-origin") not in ("same-origin", "none"):
                await self._refuse(send, 403, "cross-site write refused")
                return
            body = await self._whole_body(receive, send, length)
            if body is None:
                return
            replayed = False

            async def replay() -> dict:
                nonlocal replayed
                if not replayed:
                    replayed = True
                    return {"type": "http.request", "body": body, "more_body": False}
                return await receive()  # later: the disconnect, when it comes

            await self.app(scope, replay, send)
            return
        received = 0
        refused = started = False

        async def limited_receive() -> dict:
            nonlocal received, refused
            message = await receive()
            if message["type"] == "http.request":
                received += len(message.get("body", b""))
                if received > self.max_body:
                    if not started and not refused:
                        refused = True
                        await self._refuse(send, 413, f"request body larger than {self.max_body} bytes")
                    return {"type": "http.disconnect"}  # the app stops reading; nothing of it is used
            return message

        async def tracking_send(message: dict) -> None:
            nonlocal started
            if refused:
                return  # the 413 went out already; the app's answer to a cut-off body is dropped
            if message["type"] == "http.response.start":
                started = True
            await send(message)

        await self.app(scope, limited_receive, tracking_send)


def reachable_address(host: str) -> str:
    """An address a tablet can open for a server bound to `host` (not 0.0.0.0 or ::, which mean "every interface").

    For a wildcard bind this is the address of the interface that routes outwards (no packet is sent), else the
    host's own name's address, else 127.0.0.1.
    """
    import socket

    if host not in ("0.0.0.0", "::", ""):
        return host
    family = socket.AF_INET6 if host == "::" else socket.AF_INET
    probe = ("2001:db8::1", 9) if family == socket.AF_INET6 else ("192.0.2.1", 9)  # documentation addresses
    try:
        with socket.socket(family, socket.SOCK_DGRAM) as s:
            s.connect(probe)  # UDP connect only picks the route
            addr = s.getsockname()[0]
            if addr and not ipaddress.ip_address(addr).is_unspecified:
                return addr
    except OSError:
        pass
    try:
        addr = socket.gethostbyname(socket.gethostname())
        if not ipaddress.ip_address(addr).is_loopback:
            return addr
    except OSError:
        pass
    return "127.0.0.1"


def _schemas() -> tuple[Any, Any, Any]:
    from typing import Annotated

    from pydantic import BaseModel, ConfigDict, Field, TypeAdapter

    class NoFields(BaseModel):
        """A write that carries nothing (a button press): unknown keys are refused."""

        model_config = ConfigDict(extra="forbid", strict=True)

    class TrustSwitch(BaseModel):
        """The researcher's switch: show the estimated trust on the participant's tablet, or hide it."""

        model_config = ConfigDict(extra="forbid", strict=True)  # strict: no "true", no 1
        shown: bool

    answer = Annotated[float, Field(strict=True, allow_inf_nan=False)]  # strict: no "3", no true
    return TypeAdapter(NoFields), TypeAdapter(dict[str, answer | None]), TypeAdapter(TrustSwitch)


NO_FIELDS, ANSWERS, TRUST_SWITCH = _schemas()
"""The schemas of the write endpoints' bodies: a button press, a questionnaire's answers, the researcher's
trust switch."""


def _validated(schema: Any, raw: bytes, allow_empty: bool) -> Any:
    """`raw` parsed as JSON and validated by `schema`; HTTPException 400 (not JSON) or 422 (wrong shape)."""
    from fastapi import HTTPException
    from pydantic import ValidationError

    from scone_bt.config.schema import format_validation_error

    if allow_empty and not raw.strip():
        return None
    try:
        data = json.loads(raw, parse_constant=_no_constant)
    except (ValueError, RecursionError):
        raise HTTPException(status_code=400, detail="the request body is not JSON") from None
    try:
        return schema.validate_python(data)
    except ValidationError as exc:
        raise HTTPException(status_code=422, detail=format_validation_error(exc, "body")) from None


def _no_constant(name: str) -> None:
    raise ValueError(f"{name} is not JSON")  # Python's json accepts NaN and Infinity; JSON does not


def _page(name: str = "tablet.html") -> str:
    return resources.files("scone_bt.study").joinpath(f"static/{name}").read_text(encoding="utf-8")


def _body_dependencies() -> tuple[Any, Any, Any]:
    """FastAPI dependencies that read a write's body: a button press, a questionnaire's answers, the switch."""
    from fastapi import Request

    async def no_fields(request):  # noqa: ANN001, ANN202 - annotated below
        """The body of a button press: none, or the empty JSON object (nothing else is taken as a press)."""
        _validated(NO_FIELDS, await request.body(), allow_empty=True)

    async def answers_body(request):  # noqa: ANN001, ANN202 - annotated below
        """A questionnaire's answers: one JSON object of item keys to finite numbers or null."""
        return _validated(ANSWERS, await request.body(), allow_empty=False)

    async def switch_body(request):  # noqa: ANN001, ANN202 - annotated below
        """The researcher's switch: {"shown": true} or {"shown": false}, nothing else."""
        return _validated(TRUST_SWITCH, await request.body(), allow_empty=False).shown

    # FastAPI resolves annotations in this module's globals, where the lazily imported Request is not: the class
    # itself is given instead of its name.
    for dependency in (no_fields, answers_body, switch_body):
        dependency.__annotations__["request"] = Request
    return no_fields, answers_body, switch_body


def _page_routes(app: Any) -> None:
    """The participant's page and the researcher's page."""
    from fastapi.responses import HTMLResponse

    page, researcher_page = _page(), _page("researcher.html")

    @app.get("/", response_class=HTMLResponse)
    def index() -> str:
        return page

    @app.get("/researcher", response_class=HTMLResponse)
    def researcher() -> str:
        """The researcher's page (behind the same token): the session's state and its own Start button."""
        return researcher_page


def _start_routes(app: Any, state: TabletState, no_fields: Any) -> None:
    """Start, from the participant's tablet or the researcher's page."""
    from fastapi import Depends, HTTPException

    def start(by: str) -> dict[str, Any]:
        if not state.start(by):
            detail = (
                f"the session was started already ({state.started_by})"
                if state.started_by
                else "the robot is not ready yet; Start is possible once it is"
            )
            raise HTTPException(status_code=409, detail=detail)
        return {"ok": True, "started_by": by}

    @app.post("/api/start", dependencies=[Depends(no_fields)])
    def participant_start() -> dict[str, Any]:
        return start("participant")

    @app.post("/api/researcher/start", dependencies=[Depends(no_fields)])
    def researcher_start() -> dict[str, Any]:
        return start("researcher")


def _episode_routes(app: Any, state: TabletState, no_fields: Any) -> None:
    """What the participant sees and does during the episode: the state, Done on a request, Take over."""
    from fastapi import Depends, HTTPException

    @app.get("/api/state")
    def get_state() -> dict[str, Any]:
        return state.snapshot()

    @app.post("/api/requests/{object_name}/done", dependencies=[Depends(no_fields)])
    def confirm(object_name: str) -> dict[str, Any]:
        if not state.confirm(object_name):
            raise HTTPException(status_code=409, detail=f"no pending request for {object_name!r}")
        return {"ok": True}

    @app.post("/api/takeover", dependencies=[Depends(no_fields)])
    def takeover() -> dict[str, Any]:
        name = state.request_takeover()
        if name is None:
            raise HTTPException(status_code=409, detail="the robot is not acting now")
        return {"ok": True, "object": name}


def _researcher_routes(app: Any, state: TabletState, switch_body: Any) -> None:
    """The researcher's view of the state (the estimated trust always in it) and the switch that shows or hides
    the estimate on the participant's tablet."""
    from fastapi import Depends

    @app.get("/api/researcher/state")
    def researcher_state() -> dict[str, Any]:
        return state.snapshot(researcher=True)

    @app.post("/api/researcher/trust-view")
    def trust_view(shown: bool = Depends(switch_body)) -> dict[str, Any]:  # noqa: B008
        changed = state.show_trust(shown)
        return {"ok": True, "shown": shown, "changed": changed}


def _questionnaire_routes(app: Any, state: TabletState, answers_body: Any) -> None:
    """A questionnaire's answers, stored once."""
    from fastapi import Depends
    from fastapi.responses import JSONResponse

    from scone_bt.errors import UnknownNameError
    from scone_bt.study.questionnaires import QuestionnaireError

    @app.post("/api/questionnaires/{name}")
    def submit(name: str, answers: dict[str, float | None] = Depends(answers_body)) -> Any:  # noqa: B008
        try:
            state.submit(name, answers)
        except AlreadySubmittedError as exc:
            return JSONResponse({"detail": str(exc)}, status_code=409)
        except (QuestionnaireError, UnknownNameError) as exc:
            return JSONResponse({"detail": str(exc)}, status_code=422)
        except SconeError as exc:  # the study log refused it (e.g. stored already by another process)
            return JSONResponse({"detail": str(exc)}, status_code=409)
        return {"ok": True}


def build_app(state: TabletState, token: str | None, local_only: bool = True) -> Any:
    """The FastAPI application over a TabletState, behind RequestGuard (Host, token, body size, Origin).

    Args:
        state: What the tablet shows and what the participant did.
        token: Session token every request must carry, or None (localhost only).
        local_only: Answer only requests whose Host is a local name (the server is bound to localhost).
    """
    from fastapi import FastAPI

    no_fields, answers_body, switch_body = _body_dependencies()
    app = FastAPI(title="SCONE-BT tablet", docs_url=None, redoc_url=None, openapi_url=None)
    app.add_middleware(RequestGuard, token=token, local_only=local_only)
    _page_routes(app)
    _start_routes(app, state, no_fields)
    _episode_routes(app, state, no_fields)
    _researcher_routes(app, state, switch_body)
    _questionnaire_routes(app, state, answers_body)
    return app


def _check_listen(host: str, port: int) -> None:
    """Raise UIError, one line saying why, where the server could not listen on host:port (a name that does not
    resolve, a port in use, an address not on this machine); checked before uvicorn starts, which would log its
    own error line first."""
    import socket

    try:
        infos = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM, flags=socket.AI_PASSIVE)
    except (socket.gaierror, UnicodeError) as exc:
        why = exc.strerror if isinstance(exc, socket.gaierror) else str(exc)
        raise UIError(
            f"the tablet UI cannot listen on {host}:{port}: the host does not resolve ({why})"
        ) from None
    family, kind, proto, _, address = infos[0]
    with socket.socket(family, kind, proto) as probe:
        # As uvicorn binds: a port in TIME_WAIT is no obstacle.
        probe.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            probe.bind(address)
        except OSError as exc:
            why = (exc.strerror or str(exc)).lower()
            raise UIError(f"the tablet UI cannot listen on {host}:{port}: {why}") from None


class TabletServer:
    """A running tablet UI. Use `.human_factory` and `.on_event` with run_episode, `.url` for the tablet.

    Attributes:
        state: The shared state (tests and the session runner read it).
        trust_view: The person's estimated trust per action on offer, fed every event (the study view).
        url: The page's address, token included.
    """

    def __init__(
        self,
        host: str,
        port: int,
        token: str | None,
        state: TabletState | None = None,
        start_gate: bool = False,
        trust_shown: bool = False,
        trust_view: TrustView | None = None,
    ) -> None:
        import uvicorn

        if token is not None and len(token) < MIN_TOKEN_LENGTH:
            raise UIError(f"the session token must have at least {MIN_TOKEN_LENGTH} characters")
        if not _is_local(host) and token is None:
            raise UIError(
                f"serving the tablet UI on {host} makes it reachable from the network and needs a session token "
                f"(--ui-token, at least {MIN_TOKEN_LENGTH} characters); without one, use --ui-host 127.0.0.1"
            )
        self.state = state or TabletState(start_gate=start_gate, trust_shown=trust_shown)
        self.trust_view = trust_view or TrustView()
        self._why: dict[str, str] = {}  # item → the robot's words for its latest ASK decision about it
        self.token = token
        self.host = host
        if not 0 <= port <= 65535:
            raise UIError(f"port {port}: must be a TCP port in 0..65535 (0: any free port)")
        _check_listen(host, port)
        config = uvicorn.Config(
            build_app(self.state, token, local_only=_is_local(host)),
            host=host,
            port=port,
            # uvicorn's loggers propagate to the application's logging (scone-run --log-level), instead of
            # uvicorn installing its own handlers that print raw into the decision lines
            log_config=None,
            log_level=None,
            lifespan="off",
            access_log=False,
            limit_concurrency=256,  # beyond this, 503 rather than unbounded memory
            timeout_keep_alive=5,
            h11_max_incomplete_event_size=16 * 1024,  # headers larger than this are refused
        )
        self._server = uvicorn.Server(config)
        self._thread = threading.Thread(target=self._server.run, name="tablet-ui", daemon=True)
        self._thread.start()
        deadline = time.monotonic() + 15.0
        while not self._server.started:
            if not self._thread.is_alive() or time.monotonic() > deadline:
                self._server.should_exit = True
                raise UIError(
                    f"the tablet UI could not listen on {host}:{port} (port in use or address not available)"
                )
            time.sleep(0.02)
        self.port = int(self._server.servers[0].sockets[0].getsockname()[1])
        reach = reachable_address(host)
        shown = f"[{reach}]" if ":" in reach else reach
        query = f"?token={token}" if token else ""
        self.url = f"http://{shown}:{self.port}/" + query
        self.researcher_url = f"http://{shown}:{self.port}/researcher" + query

    # ----------------------------------------------------------------------------------------- episode hooks
    def human_factory(self, kitchen: Any, recipe: Any, options: Any, seed: int) -> TabletHuman:
        """run_episode's human_factory: a TabletHuman on this server's state (the trust model loads now, before
        Start)."""
        self.trust_view.load()
        return TabletHuman(kitchen, recipe, options, seed=seed, state=self.state)

    def on_event(self, event: Event) -> None:
        """run_episode's on_event: keep the tablet's view of the robot up to date, in plain words (`words`)."""
        from scone_bt.study.words import decision_words, feed_line, help_words

        s = self.state
        if isinstance(event, DecisionMade):
            said = decision_words(event)
            if event.verdict is DecisionKind.ASK and event.object_name:
                self._why[event.object_name] = help_words(event)
            s.set_robot(
                action=event.action,
                confidence=_finite(event.confidence),  # JSON has no NaN
                kind=event.verdict.value,
                status=_STATUS[event.verdict],
                say=said,
                rule=event.rule,
            )
        elif isinstance(event, ActStarted):
            s.set_robot(
                action=event.action,
                confidence=_finite(event.confidence),
                status="acting",
                say=f"I am fetching the {event.object_name}.",
                window_until=None,
            )
            if event.window_s > 0:
                s.announce(event.object_name, event.window_s, event.sim_time)
        elif isinstance(event, ActOutcome):
            s.set_robot(status="idle", say="")
        elif isinstance(event, TakeOver):
            s.set_robot(
                status="stopped",
                say=f"You took over: I stopped. Please bring the {event.object_name} to the table.",
                window_until=None,
            )
        elif isinstance(event, ProbeAborted):
            s.set_robot(status="idle")
            s.note(f"The robot hefted the {event.object_name} and set it back: {event.reason}.")
        elif isinstance(event, HelpRequested):
            why = event.reason or self._why.pop(event.object_name, "")
            s.set_robot(status="asking", say=why or f"Please bring the {event.object_name}.")
            s.explain_fetch(event.object_name, why)
        line = feed_line(event)
        if line:
            s.note(line)
        rows = self.trust_view(event)
        if rows is not None:
            s.set_trust([r.to_json() for r in rows])

    def chain(self, *sinks: EventSink) -> EventSink:
        """An on_event that feeds the tablet and the given sinks (e.g. a StudyLog's event_sink)."""

        def on_event(event: Event) -> None:
            for sink in sinks:
                sink(event)
            self.on_event(event)

        return on_event

    # ----------------------------------------------------------------------------------------- questionnaires
    def ask_questionnaires(
        self,
        on_submit: Callable[[str, dict[str, float | None]], None],
        questionnaires: Sequence[Questionnaire] = tuple(QUESTIONNAIRES.values()),
    ) -> None:
        """Show the questionnaires; on_submit(name, answers) stores each one (it runs in the web thread)."""
        self.state.finish_episode()
        self.state.ask(questionnaires, on_submit)

    def wait_questionnaires(self, timeout: float | None = None) -> bool:
        """Block until every questionnaire is submitted; False on timeout."""
        return self.state.questionnaires_done.wait(timeout)

    def close(self) -> None:
        self._server.should_exit = True
        self._thread.join(timeout=5.0)

    def __enter__(self) -> TabletServer:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def serve_tablet(
    host: str = "127.0.0.1",
    port: int = 8765,
    token: str | None = None,
    start_gate: bool = False,
    trust_shown: bool = False,
) -> TabletServer:
    """Start the tablet UI in a background thread (port 0 picks a free port); raises UIError when it cannot.

    With ``start_gate`` the episode waits until Start is pressed on the tablet or on the researcher's page
    (``/researcher``, behind the same token). ``trust_shown`` shows the person's estimated trust on the
    participant's tablet from the start (the researcher's page switches it; it always shows it itself).
    """
    return TabletServer(host, port, token, start_gate=start_gate, trust_shown=trust_shown)


def tablet_from_args(args: Any) -> TabletServer | None:
    """Start the tablet server when --ui was given (None otherwise); raises UIError with a one-line reason."""
    port = getattr(args, "ui_port", 8765)
    if not 0 <= port <= 65535:
        raise UIError(f"--ui-port {port}: must be a TCP port in 0..65535 (0: any free port)")
    if not getattr(args, "ui", False):
        if (
            getattr(args, "ui_token", None)
            or getattr(args, "ui_host", "127.0.0.1") != "127.0.0.1"
            or port != 8765
        ):
            raise UIError("--ui-host, --ui-port and --ui-token only apply with --ui")
        return None
    from scone_bt.extras import require

    require("study", "scone-run --ui (the tablet)", ("fastapi", "uvicorn"))
    return serve_tablet(args.ui_host, args.ui_port, args.ui_token)
