"""Storage faults: a read-only mount or a full disk is detected when a store is opened, never after an outcome;
concurrent writers lose nothing.

The read-only mount and the full disk are real (a private mount namespace with a read-only bind mount, a 4 MB
tmpfs filled to the last byte); where the test process may not create mounts, those tests skip and say why.
"""

from __future__ import annotations

import hashlib
import os
import shutil
import subprocess
import sys
import tempfile
import textwrap
import time
from pathlib import Path

import pytest

from scone_bt.experience import ExperienceStore
from scone_bt.experience.types import Outcome
from scone_bt.study import StudyLog, plan_session

UNSHARE = shutil.which("unshare")


def _can_mount(tmp_path: Path) -> bool:
    if UNSHARE is None:
        return False
    probe = tmp_path / "probe"
    probe.mkdir()
    r = subprocess.run(
        [UNSHARE, "-m", "sh", "-c", f"mount -t tmpfs -o size=64k tmpfs {probe}"],
        capture_output=True,
        timeout=30,
    )
    return r.returncode == 0


@pytest.fixture
def mounts(tmp_path):
    if not _can_mount(tmp_path):
        pytest.skip("cannot create a private mount namespace here (needs unshare and CAP_SYS_ADMIN)")
    return tmp_path


def _in_namespace(setup: str, code: str, timeout: float = 120) -> subprocess.CompletedProcess:
    """Run `code` in Python inside a private mount namespace after the shell commands `setup`."""
    script = Path(tempfile.gettempdir()) / f"scone-fault-{os.getpid()}-{time.time_ns()}.py"
    script.write_text(textwrap.dedent(code))
    try:
        return subprocess.run(
            [UNSHARE, "-m", "sh", "-c", f"{setup} && {sys.executable} {script}"],
            capture_output=True,
            text=True,
            timeout=timeout,
        )
    finally:
        script.unlink()


def _outcome(i: int) -> Outcome:
    return Outcome(
        time=1000.0 + i, action="Put salt on table", object_name="salt", embedder="minilm", success=i % 2 == 0
    )


def _digest(folder: Path) -> dict[str, str]:
    return {p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in sorted(folder.iterdir())}


def test_readonly_mount_is_reported_at_open_not_as_corrupt(mounts):
    folder = mounts / "ro"
    folder.mkdir()
    with ExperienceStore(folder / "exp.db") as store:
        store.append(_outcome(0))
    with StudyLog(folder / "study.db") as log:
        log.start_session(plan_session("P01", "A", 1))
    before = _digest(folder)
    r = _in_namespace(
        f"mount --bind {folder} {folder} && mount -o remount,ro,bind {folder}",
        f"""
        import sys
        from scone_bt.errors import SconeError
        from scone_bt.experience import ExperienceStore
        from scone_bt.study import StudyLog
        for opener in (lambda: ExperienceStore({str(folder / "exp.db")!r}), lambda: StudyLog({str(folder / "study.db")!r})):
            try:
                opener()
                print("OPENED")
            except SconeError as exc:
                print(exc)
        with StudyLog({str(folder / "study.db")!r}, readonly=True) as log:  # reading still works
            print("sessions", len(log.sessions()))
        from scone_bt.cli.run import main
        sys.exit(main(["--robot", "sim", "--experience", {str(folder / "exp.db")!r}, "--quiet"]))
        """,
    )
    lines = r.stdout.strip().splitlines()
    assert len(lines) == 3, (r.stdout, r.stderr)
    assert "read-only" in lines[0] and "corrupt" not in lines[0]
    assert "read-only" in lines[1] and "corrupt" not in lines[1]
    assert lines[2] == "sessions 1"
    assert (
        r.returncode == 2 and "read-only" in r.stderr and "Traceback" not in r.stderr
    )  # before the robot acts
    assert _digest(folder) == before


def test_full_disk_is_reported_at_open(mounts):
    folder = mounts / "full"
    folder.mkdir()
    r = _in_namespace(
        f"mount -t tmpfs -o size=4m tmpfs {folder}",
        f"""
        from pathlib import Path
        from scone_bt.errors import SconeError
        from scone_bt.experience import ExperienceStore
        from scone_bt.experience.types import Outcome
        folder = Path({str(folder)!r})
        with ExperienceStore(folder / "exp.db") as store:   # opened while there is room
            store.append(Outcome(1.0, "Put salt on table", "salt", "minilm", True))
        fh = open(folder / "filler", "wb", buffering=0)      # then the disk fills up
        try:
            while True:
                fh.write(b"\\0" * 4096)
        except OSError:
            pass
        try:
            fh.write(b"\\0")
        except OSError:
            pass
        for name in ("exp.db", "new.db"):
            try:
                ExperienceStore(folder / name)
                print("OPENED")
            except SconeError as exc:
                print(exc)
        """,
    )
    lines = r.stdout.strip().splitlines()
    assert len(lines) == 2, (r.stdout, r.stderr)
    assert all("disk full" in line for line in lines), lines


def test_concurrent_writers_lose_nothing(tmp_path):
    exp, study = tmp_path / "exp.db", tmp_path / "study.db"
    ExperienceStore(exp).close()
    with StudyLog(study) as log:
        sid = log.start_session(plan_session("P01", "A", 1))
    code = f"""
import sys
from scone_bt.experience import ExperienceStore
from scone_bt.experience.types import Outcome
from scone_bt.study import StudyLog
k = int(sys.argv[1])
store, log = ExperienceStore({str(exp)!r}), StudyLog({str(study)!r})
for i in range(40):
    store.append(Outcome(float(i), "Put salt on table", "salt", "minilm", True, context={{"writer": k, "i": i}}))
    log.record_event({sid}, "outcome", {{"writer": k, "i": i}})
print("done", k)
"""
    procs = [
        subprocess.Popen([sys.executable, "-c", code, str(k)], stdout=subprocess.PIPE, text=True)
        for k in range(3)
    ]
    outs = [p.communicate(timeout=300)[0] for p in procs]
    assert [p.returncode for p in procs] == [0, 0, 0], outs
    with ExperienceStore(exp) as store:
        pairs = sorted((o.context["writer"], o.context["i"]) for o in store.outcomes())
    assert pairs == sorted((k, i) for k in range(3) for i in range(40))
    with StudyLog(study, readonly=True) as log:
        events = sorted((e.data["writer"], e.data["i"]) for e in log.events(sid))
    assert events == pairs


def test_a_row_whose_context_is_not_json_is_quarantined_with_a_one_line_warning(tmp_path, capsys):
    import sqlite3

    db = tmp_path / "exp.db"
    with ExperienceStore(db) as store:
        store.append(_outcome(0))
        store.append(_outcome(1))
    with sqlite3.connect(db) as conn:  # damage made outside the program, e.g. by hand-editing
        conn.execute("UPDATE outcomes SET context = 'not json' WHERE time = 1001.0")
    before = hashlib.sha256(db.read_bytes()).hexdigest()
    with ExperienceStore(db) as store:
        assert [o.time for o in store.outcomes()] == [1000.0]
    warning = capsys.readouterr().err
    assert warning.count("\n") == 1 and "row 2 (context is not JSON)" in warning
    assert hashlib.sha256(db.read_bytes()).hexdigest() == before
