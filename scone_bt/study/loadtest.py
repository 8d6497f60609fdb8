"""Load test of the tablet server: many tablets polling and submitting questionnaires against 127.0.0.1.

The server runs in this process, as in `scone-run --ui` (a uvicorn thread beside the episode), with a real StudyLog
in SQLite. The clients run in a second process (so their Python threads do not compete with the server for this
interpreter), each with a keep-alive HTTP connection: they poll `/api/state`, now and then press take-over, and
whenever questionnaires are shown they submit random answers. A coordinator thread opens round after round: a
session row, both questionnaires; the round ends when both are stored.

Exactly one submission per questionnaire and round may be acknowledged (200); every other must be refused (409).
Afterwards the log is reopened read-only and every acknowledged answer set is looked up by content:
`lost` counts acknowledged sets not stored, `duplicated` counts questionnaires stored with more than one
acknowledgement, `unacknowledged_stored` counts stored sets no client was told about.

    scone-bench tablet-load --clients 50 --duration 30
"""

from __future__ import annotations

import argparse
import functools
import json
import sys
import tempfile
import threading
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

from scone_bt.argparsing import DefaultsHelpFormatter, OneLineArgumentParser, path_arg
from scone_bt.reporting import emit_report

__all__ = ["LoadTestOptions", "LoadTestResult", "run_load_test", "register"]


@dataclass(frozen=True)
class LoadTestOptions:
    """What to run.

    Attributes:
        clients: Concurrent tablets (threads in the client process, one connection each).
        duration_s: Wall-clock length of the run, seconds.
        max_requests: Upper bound on requests over all clients (the run stops at whichever comes first).
        think_s: Each client waits uniformly in [0, think_s] seconds between requests (the page polls every 0.4 s).
        takeover_rate: Chance per poll that a client presses take-over (always refused: the robot is not acting).
        rng_seed: Seeds the clients' answers and timing, and the session token.
    """

    clients: int = 50
    duration_s: float = 30.0
    max_requests: int = 500_000
    think_s: float = 0.05
    takeover_rate: float = 0.05
    rng_seed: int = 0


@dataclass(frozen=True)
class LoadTestResult:
    """The figures of one run. Latencies are milliseconds, measured by the clients (request sent → body read)."""

    clients: int
    duration_s: float
    requests: int
    requests_by_endpoint: dict[str, int]
    statuses: dict[str, int]
    unexpected: int
    rounds: int
    submissions_attempted: int
    acknowledged: int
    refused: int
    stored: int
    lost: int
    duplicated: int
    unacknowledged_stored: int
    latency_ms: dict[str, dict[str, float]]
    requests_per_s: float
    errors: list[str] = field(default_factory=list)

    def to_json(self) -> dict[str, Any]:
        return asdict(self)


# ------------------------------------------------------------------------------------------------ client process
budget_lock = threading.Lock()  # guards the shared request budget of the client threads


def _percentiles(values: list[float]) -> dict[str, float]:
    import numpy as np

    if not values:
        return {"n": 0}
    a = np.asarray(values) * 1000.0
    return {
        "n": int(a.size),
        "p50": round(float(np.percentile(a, 50)), 2),
        "p95": round(float(np.percentile(a, 95)), 2),
        "p99": round(float(np.percentile(a, 99)), 2),
        "max": round(float(a.max()), 2),
    }


def _client(
    k: int, port: int, token: str, options: LoadTestOptions, deadline: float, budget: list[int], out: list
) -> None:
    import http.client

    import numpy as np

    rng = np.random.default_rng([options.rng_seed, k])
    headers = {"X-Session-Token": token, "Host": f"127.0.0.1:{port}"}
    conn = http.client.HTTPConnection("127.0.0.1", port, timeout=30)
    lock = budget_lock

    def request(method: str, path: str, body: bytes | None, kind: str) -> tuple[int, bytes]:
        nonlocal conn
        h = dict(headers)
        if body is not None:
            h["Content-Type"] = "application/json"
        t0 = time.perf_counter()
        try:
            conn.request(method, path, body=body, headers=h)
            r = conn.getresponse()
            data = r.read()
            status = r.status
        except (OSError, http.client.HTTPException) as exc:
            conn.close()
            conn = http.client.HTTPConnection("127.0.0.1", port, timeout=30)
            out.append(("error", kind, 0, time.perf_counter() - t0, f"{type(exc).__name__}: {exc}"))
            return 0, b""
        out.append(("req", kind, status, time.perf_counter() - t0, None))
        return status, data

    while time.time() < deadline:
        with lock:
            if budget[0] <= 0:
                break
            budget[0] -= 1
        status, data = request("GET", "/api/state", None, "state")
        if status == 200:
            state = json.loads(data)
            shown = state.get("questionnaires") or []
            if shown:
                q = shown[int(rng.integers(len(shown)))]
                answers = {
                    it["key"]: float(q["values"][int(rng.integers(len(q["values"])))]) for it in q["items"]
                }
                body = json.dumps(answers).encode()
                code, _ = request("POST", f"/api/questionnaires/{q['name']}", body, "submit")
                out.append(("submit", q["name"], code, 0.0, answers))
            elif rng.random() < options.takeover_rate:
                request("POST", "/api/takeover", None, "takeover")
        time.sleep(float(rng.uniform(0.0, options.think_s)))
    conn.close()


def _guarded_client(
    k: int, port: int, token: str, options: LoadTestOptions, deadline: float, budget: list[int], out: list
) -> None:
    """`_client`, whose failure is a record (`crash`) rather than a traceback printed by the thread."""
    try:
        _client(k, port, token, options, deadline, budget, out)
    except BaseException as exc:  # noqa: BLE001 - reported by run_load_test, which then fails the run
        text = " ".join(str(exc).split())[:200]
        out.append(("crash", "client", 0, 0.0, f"client {k}: {type(exc).__name__}: {text or '(no message)'}"))


def _run_clients(port: int, token: str, options: LoadTestOptions, start_at: float) -> list:
    """In the client process: all clients as threads; returns every request record (a failed client: `crash`)."""
    while time.time() < start_at:
        time.sleep(0.01)
    deadline = start_at + options.duration_s
    budget = [options.max_requests]
    records: list[list] = [[] for _ in range(options.clients)]
    threads = [
        threading.Thread(
            target=_guarded_client, args=(k, port, token, options, deadline, budget, records[k]), daemon=True
        )
        for k in range(options.clients)
    ]
    for t in threads:
        t.start()
    for k, t in enumerate(threads):
        t.join(options.duration_s + 60)
        if t.is_alive():
            records[k].append(("crash", "client", 0, 0.0, f"client {k}: still running after the run's end"))
    return [r for rs in records for r in rs]


def check_options(options: LoadTestOptions) -> None:
    """The options' ranges, before the server starts: one line naming the flag and what is allowed."""
    import math

    from scone_bt.checks import check_positive_int, check_range, check_seed
    from scone_bt.errors import SconeError

    check_positive_int(options.clients, "--clients", maximum=1000)
    if not (math.isfinite(options.duration_s) and 0 < options.duration_s <= 600):
        raise SconeError(f"--duration {options.duration_s}: must be a number of seconds in (0, 600]")
    check_positive_int(options.max_requests, "--max-requests")
    check_range(options.think_s, "--think", 0.0, 60.0)
    check_range(options.takeover_rate, "takeover_rate", 0.0, 1.0)
    check_seed(options.rng_seed)


# ------------------------------------------------------------------------------------------------ server side
def run_load_test(options: LoadTestOptions, db: Path | None = None) -> LoadTestResult:
    """Run the load test against a tablet server on 127.0.0.1 (a free port) and a fresh StudyLog."""
    import multiprocessing as mp
    from concurrent.futures import ProcessPoolExecutor

    import numpy as np

    from scone_bt.errors import SconeError
    from scone_bt.study.design import plan_session
    from scone_bt.study.log import StudyLog
    from scone_bt.study.questionnaires import QUESTIONNAIRES
    from scone_bt.study.ui import serve_tablet

    check_options(options)
    token = np.random.default_rng(options.rng_seed).bytes(12).hex()
    tmp = None
    if db is None:
        tmp = tempfile.TemporaryDirectory(prefix="scone-load-")
        db = Path(tmp.name) / "load.db"
    log = StudyLog(db)
    sessions: list[int] = []
    stop = threading.Event()
    errors: list[str] = []
    try:
        with serve_tablet("127.0.0.1", 0, token) as server:

            def coordinator() -> None:
                try:
                    while not stop.is_set():
                        sid = log.start_session(plan_session(f"L{len(sessions):04d}", "A", 1))
                        sessions.append(sid)
                        server.state.label = f"round {len(sessions)}"
                        server.ask_questionnaires(
                            functools.partial(log.record_responses, sid),
                            tuple(QUESTIONNAIRES.values()),
                        )
                        while not stop.is_set() and not server.wait_questionnaires(0.05):
                            pass
                        log.end_session(sid, {"load_test": True})
                except Exception as exc:  # reported in the result, never silently
                    errors.append(f"coordinator: {type(exc).__name__}: {exc}")

            worker = threading.Thread(target=coordinator, name="load-coordinator", daemon=True)
            worker.start()
            start_at = time.time() + 3.0  # the client process needs a moment to start
            with ProcessPoolExecutor(1, mp_context=mp.get_context("spawn")) as pool:
                records = pool.submit(_run_clients, server.port, token, options, start_at).result(
                    timeout=options.duration_s + 180
                )
            stop.set()
            worker.join(10)
        log.close()
        crashed = [r[4] for r in records if r[0] == "crash"]
        if crashed:
            more = f" (and {len(crashed) - 1} more)" if len(crashed) > 1 else ""
            raise SconeError(f"tablet-load: a client failed, the run is not valid: {crashed[0]}{more}")
        return _score(records, db, options, errors, set(QUESTIONNAIRES))
    finally:
        stop.set()
        if tmp is not None:
            tmp.cleanup()


def _score(
    records: list, db: Path, options: LoadTestOptions, errors: list[str], names: set[str]
) -> LoadTestResult:
    from collections import Counter, defaultdict

    from scone_bt.study.log import StudyLog

    latency: dict[str, list[float]] = defaultdict(list)
    by_endpoint: Counter[str] = Counter()
    statuses: Counter[str] = Counter()
    expected = {"state": {200}, "submit": {200, 409}, "takeover": {409}}
    unexpected = 0
    acks: list[tuple[str, tuple]] = []
    attempted = refused = 0
    for kind, what, status, seconds, extra in records:
        if kind == "req":
            by_endpoint[what] += 1
            statuses[f"{what} {status}"] += 1
            latency[what].append(seconds)
            if status not in expected[what]:
                unexpected += 1
        elif kind == "error":
            by_endpoint[what] += 1
            statuses[f"{what} error"] += 1
            unexpected += 1
            if len(errors) < 10:
                errors.append(extra)
        elif kind == "submit":
            attempted += 1
            if status == 200:
                acks.append((what, tuple(sorted(extra.items()))))
            elif status == 409:
                refused += 1
    with StudyLog(db, readonly=True) as log:
        grouped: dict[tuple[int, str], dict[str, float | None]] = defaultdict(dict)
        rows: Counter[tuple[int, str]] = Counter()
        for r in log.responses():
            grouped[(r.session_id, r.questionnaire)][r.item] = r.value
            rows[(r.session_id, r.questionnaire)] += 1
        rounds = len(log.sessions())
    from scone_bt.study.questionnaires import get_questionnaire

    stored = Counter((q, tuple(sorted(a.items()))) for (_sid, q), a in grouped.items())
    ack_count = Counter(acks)
    lost = sum(max(0, n - stored.get(key, 0)) for key, n in ack_count.items())
    # a questionnaire stored twice in one session (more rows than items), or acknowledged more often than stored
    duplicated = sum(1 for (sid, q), n in rows.items() if n > len(get_questionnaire(q).items)) + sum(
        1 for key, n in ack_count.items() if n > 1 and stored.get(key, 0) < n
    )
    unack = sum(max(0, n - ack_count.get(key, 0)) for key, n in stored.items())
    total = sum(by_endpoint.values())
    return LoadTestResult(
        clients=options.clients,
        duration_s=options.duration_s,
        requests=total,
        requests_by_endpoint=dict(by_endpoint),
        statuses=dict(sorted(statuses.items())),
        unexpected=unexpected,
        rounds=rounds,
        submissions_attempted=attempted,
        acknowledged=len(acks),
        refused=refused,
        stored=sum(stored.values()),
        lost=lost,
        duplicated=duplicated,
        unacknowledged_stored=unack,
        latency_ms={k: _percentiles(v) for k, v in sorted(latency.items())},
        requests_per_s=round(total / options.duration_s, 1),
        errors=errors,
    )


# ------------------------------------------------------------------------------------------------ scone-bench
def _bench(args: argparse.Namespace) -> int:
    options = LoadTestOptions(
        clients=args.clients,
        duration_s=args.duration,
        max_requests=args.max_requests,
        think_s=args.think,
        rng_seed=args.seed,
    )
    t0, c0 = time.perf_counter(), time.process_time()
    result = run_load_test(options, args.db)
    out = {
        **result.to_json(),
        "wall_s": round(time.perf_counter() - t0, 2),
        "server_process_cpu_s": round(time.process_time() - c0, 2),
    }
    emit_report(out, args.json, indent=2, make_parent=True, force=bool(getattr(args, "force", False)))
    ok = (
        result.lost == 0
        and result.duplicated == 0
        and result.unacknowledged_stored == 0
        and not result.unexpected
    )
    return 0 if ok else 1


def register(subparsers: Any) -> None:
    """`scone-bench tablet-load`: the tablet server's load test (prints JSON; exit 1 if an answer was lost)."""
    p = subparsers.add_parser(
        "tablet-load",
        help="tablet server load test: concurrent clients poll and submit against 127.0.0.1; lost/duplicated answers, p95 latency",
        formatter_class=DefaultsHelpFormatter,
    )
    p.add_argument("--clients", type=int, default=50, help="concurrent tablets")
    p.add_argument("--duration", type=float, default=30.0, help="seconds")
    p.add_argument("--max-requests", type=int, default=500_000, help="bound on all requests together")
    p.add_argument("--think", type=float, default=0.05, help="max seconds a client waits between requests")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--db", type=path_arg, help="study log to write (default: a temporary file)")
    p.add_argument("--json", type=path_arg, metavar="FILE", help="also write the JSON here")
    p.set_defaults(func=_bench)


if __name__ == "__main__":  # pragma: no cover
    parser = OneLineArgumentParser(prog="tablet-load")
    register(parser.add_subparsers(dest="command", required=True))
    parsed = parser.parse_args(["tablet-load", *sys.argv[1:]])
    sys.exit(parsed.func(parsed))
