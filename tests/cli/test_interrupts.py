"""Ctrl-C at any moment of scone-run (issue 27): one line saying what was saved, exit status 130, no traceback,
and a store that is intact and holds what the line says. Real processes, real SIGINT."""

from __future__ import annotations

import contextlib
import os
import random
import re
import signal
import sqlite3
import subprocess
import sys
import time
from pathlib import Path

import pytest

SCONE_RUN = Path(sys.executable).parent / "scone-run"
LINE = re.compile(
    r"scone-run: interrupted; (?:nothing was stored.*|(?P<n>\d+) outcomes? of this run (?:is|are) in (?P<store>.+))"
)
RECORDING = re.compile(
    r".*; the recording so far is in (?P<path>\S+)(?P<kept> \(.+, the recording before it, is untouched\))?"
)

pytestmark = pytest.mark.skipif(not SCONE_RUN.is_file(), reason="scone-run is not installed beside Python")


def _sigint_as_from_a_terminal() -> None:
    """In the child before exec: SIGINT handled by default, as a terminal's shell starts a command. A runner started
    in the background (`cmd &` in a script) ignores SIGINT, an ignored signal stays ignored across exec, and a
    Ctrl-C before scone-run installs its handler would then be lost (the run went on to exit 0)."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def _sigint_ignored() -> None:
    """In the child before exec: SIGINT ignored, as `cmd &` in a script or nohup starts a command."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def _popen(argv: list[str], cwd: Path, preexec_fn: object = _sigint_as_from_a_terminal) -> subprocess.Popen:
    """``argv`` as its own process in ``cwd``, its output captured unbuffered."""
    return subprocess.Popen(
        argv,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env={**os.environ, "PYTHONUNBUFFERED": "1"},
        cwd=cwd,
        preexec_fn=preexec_fn,  # type: ignore[arg-type]
    )


def _run_argv(store: Path, recipe: str, max_ticks: int) -> list[str]:
    argv = [str(SCONE_RUN), "--recipe", recipe, "--distractors", "0", "--max-ticks", str(max_ticks)]
    return argv + ["--embedder", "onehot", "--experience", str(store)]


def _start(tmp_path: Path, store: Path, recipe: str, max_ticks: int = 400) -> subprocess.Popen:
    return _popen(_run_argv(store, recipe, max_ticks), tmp_path)


def _check(proc: subprocess.Popen, store: Path) -> int:
    """The exit status, the one line and the store agree; returns the number of outcomes the line names."""
    out, err = proc.communicate(timeout=120)
    assert proc.returncode == 130, (proc.returncode, err[-2000:])
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in err, err[-2000:]
    match = LINE.fullmatch(lines[0])
    assert match, lines[0]
    said = int(match["n"] or 0)
    if match["store"] is not None:
        assert Path(match["store"]).name == store.name
    if store.exists():
        with sqlite3.connect(f"file:{store}?mode=ro", uri=True) as conn:
            assert conn.execute("PRAGMA integrity_check").fetchone()[0] == "ok"
            assert conn.execute("SELECT COUNT(*) FROM outcomes").fetchone()[0] == said
    else:
        assert said == 0
    return said


def test_ctrl_c_at_random_points_says_what_was_saved(tmp_path):
    """Four runs at once, each interrupted at a seeded random moment of its first 2.5 s (imports, start-up)."""
    rng = random.Random(27)
    # from 0.4 s: before that the interpreter itself is starting (site, .pth files), where no code of ours runs
    delays = [rng.uniform(0.4, 2.5) for _ in range(4)]
    runs = [(delay, tmp_path / f"store{i}.db") for i, delay in enumerate(delays)]
    # a recipe that takes longer than every delay even alone with warm caches (the tiny one now ends in 1.6 s, and
    # a run that had ended exited 0 before its interrupt)
    procs = [(delay, store, _start(tmp_path, store, "example:tomato-pasta", 4000)) for delay, store in runs]
    t0 = time.monotonic()
    for delay, _store, proc in sorted(procs, key=lambda r: r[0]):
        time.sleep(max(0.0, delay - (time.monotonic() - t0)))
        proc.send_signal(signal.SIGINT)
    for _delay, store, proc in procs:
        _check(proc, store)


@pytest.mark.slow
def test_ctrl_c_after_an_outcome_counts_it(tmp_path):
    """Interrupted once the first outcome was printed: the line counts what the store holds (here at least it)."""
    store = tmp_path / "store.db"
    proc = _start(tmp_path, store, "example:hummus")
    assert proc.stdout is not None
    for line in proc.stdout:
        if line.lstrip().startswith(("+ success", "x failure")):
            time.sleep(0.5)  # the outcome is printed one behaviour before it is stored, in the same tick
            proc.send_signal(signal.SIGINT)
            break
    assert _check(proc, store) >= 1


@pytest.mark.slow
def test_ctrl_c_never_replaces_the_recording_a_save_would_overwrite(tmp_path):
    """--save over the last run's recording, interrupted once this run's recording has begun: the old file is
    untouched and the line names where this run's recording went (beside it)."""
    save = tmp_path / "run.rrd"
    before = b"RRF2" + b"the previous run" * 100
    save.write_bytes(before)
    argv = [str(SCONE_RUN), "--robot", "sim", "--headless", "--seed", "0", "--quiet", "--save", str(save)]
    proc = _popen(argv, tmp_path)
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and proc.poll() is None:
        begun = [p for p in tmp_path.glob(".run.rrd.*.rrd") if p.stat().st_size > 0]
        if begun:
            break
        time.sleep(0.05)
    time.sleep(0.3)
    proc.send_signal(signal.SIGINT)
    _out, err = proc.communicate(timeout=120)
    assert proc.returncode == 130 and "Traceback" not in err, err[-2000:]
    match = RECORDING.fullmatch(err.strip())
    assert match and match["kept"], err
    assert save.read_bytes() == before
    unfinished = tmp_path / "run.unfinished.rrd"
    assert Path(match["path"]) == unfinished and unfinished.read_bytes()[:3] == b"RRF"
    assert not list(tmp_path.glob(".run.rrd.*"))  # the temporary file became the unfinished recording


def test_a_run_started_with_sigint_ignored_keeps_ignoring_it(tmp_path):
    """`scone-run … &` in a script (or nohup) starts it with SIGINT ignored: a Ctrl-C meant for the terminal's
    foreground job neither stops this run nor prints an interrupted line (it took it once its handler was in)."""
    argv = [*_run_argv(tmp_path / "store.db", "example:hummus", 150), "--quiet"]
    proc = _popen(argv, tmp_path, preexec_fn=_sigint_ignored)
    for delay in (0.3, 1.0, 1.5):
        time.sleep(delay)
        if proc.poll() is None:
            proc.send_signal(signal.SIGINT)
    _out, err = proc.communicate(timeout=120)
    # 1: the run ended as --max-ticks cut it (scone-run's "stopped early"), not 130 (interrupted)
    assert proc.returncode == 1 and "interrupted" not in err, (proc.returncode, err[-2000:])


def _ends_interrupted(monkeypatch, capsys, fake_run) -> None:
    """scone-run's `main` around ``fake_run`` (in place of its work) returns 130 with the one line."""
    from scone_bt.cli import run

    monkeypatch.setattr(run, "_run", fake_run)
    assert run.main([]) == 130
    assert (
        capsys.readouterr().err.strip()
        == "scone-run: interrupted; nothing was stored (no --experience store)"
    )


def test_a_ctrl_c_that_something_swallowed_still_ends_the_run_as_interrupted(monkeypatch, capsys):
    """A KeyboardInterrupt raised inside a library's bare ``except:`` (an import under way) is lost there; the run
    must still end as interrupted, with the line and 130, not carry on to exit 0. (CI once saw a run exit 0 with
    nothing on stderr after its Ctrl-C.)"""
    from scone_bt.cli import run

    def swallowing_run(argv, parsed):
        with contextlib.suppress(BaseException):  # what a bare except does to the KeyboardInterrupt
            run._INTERRUPTS._handle(signal.SIGINT, None)
        assert run._INTERRUPTS.pending
        with pytest.raises(KeyboardInterrupt):  # the episode's next event raises it again
            run._checked(None)(object())
        return 0

    _ends_interrupted(monkeypatch, capsys, swallowing_run)
    assert not run._INTERRUPTS.pending  # handed back to the caller clean


def test_without_a_ctrl_c_the_event_check_passes_events_on() -> None:
    from scone_bt.cli import run

    seen: list[object] = []
    run._checked(seen.append)("event")
    run._checked(None)("event")
    assert seen == ["event"]


def test_a_ctrl_c_inside_an_import_is_deferred_to_the_next_event(monkeypatch, capsys):
    """Raised inside importlib's machinery a KeyboardInterrupt can be reported as "ignored" (the run went on to
    exit 0) or leave a module lock held (the next import waited forever): there it is only noted, and the next
    event raises it."""
    from types import SimpleNamespace

    from scone_bt.cli import run

    importing = SimpleNamespace(
        f_code=SimpleNamespace(co_filename="<frozen importlib._bootstrap>"),
        f_back=SimpleNamespace(f_code=SimpleNamespace(co_filename="/x/scone_bt/cli/run.py"), f_back=None),
    )
    inner = SimpleNamespace(f_code=SimpleNamespace(co_filename="/x/torch/__init__.py"), f_back=importing)

    def run_with_a_ctrl_c_in_an_import(argv, parsed):
        run._INTERRUPTS._handle(signal.SIGINT, inner)  # returns: nothing raised inside the import
        assert run._INTERRUPTS.pending
        run._checked(None)(object())  # the episode's first event raises it
        return 0

    _ends_interrupted(monkeypatch, capsys, run_with_a_ctrl_c_in_an_import)


@pytest.mark.slow
@pytest.mark.parametrize("started", [_sigint_as_from_a_terminal, _sigint_ignored])
def test_sigterm_ends_a_run_as_ctrl_c_does(tmp_path, started):
    """`kill` or `timeout` killed the run on the spot: no line, the recording not kept. Now SIGTERM is an
    interrupt, also for a job started with SIGINT ignored (`scone-run … &` in a script, then `kill $!`)."""
    store = tmp_path / "store.db"
    proc = _popen(_run_argv(store, "example:hummus", 400), tmp_path, preexec_fn=started)
    assert proc.stdout is not None
    for line in proc.stdout:
        if line.lstrip().startswith(("+ success", "x failure")):
            time.sleep(0.5)
            proc.send_signal(signal.SIGTERM)
            break
    assert _check(proc, store) >= 1


def test_sigterm_is_keyboard_interrupt_inside_the_block_only() -> None:
    from scone_bt.signals import terminate_as_interrupt

    before = signal.signal(signal.SIGTERM, signal.SIG_DFL)  # a test runner's worker may have its own
    try:
        with terminate_as_interrupt(), pytest.raises(KeyboardInterrupt):
            # never raised with the default action: that would kill the test process itself
            assert signal.getsignal(signal.SIGTERM) is not signal.SIG_DFL
            signal.raise_signal(signal.SIGTERM)
        assert signal.getsignal(signal.SIGTERM) is signal.SIG_DFL
    finally:
        signal.signal(signal.SIGTERM, before)
