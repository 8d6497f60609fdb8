"""Any number of robots may create one SQLite store at once (issue 27): N real processes started together on a
path that does not exist yet each open it and write outcomes; none is refused and nothing is lost."""

from __future__ import annotations

import sqlite3
import subprocess
import sys
import textwrap
import time

from scone_bt.experience import ExperienceStore

WRITER = textwrap.dedent(
    """
    import sys, time
    from scone_bt.experience import ExperienceStore, Outcome

    path, robot, n, start = sys.argv[1], sys.argv[2], int(sys.argv[3]), float(sys.argv[4])
    while time.time() < start:  # every process opens at the same moment
        pass
    with ExperienceStore(path) as store:
        for k in range(n):
            store.append(Outcome(time=k, action=f"Put item{k} on table", object_name=f"item{k}",
                                 embedder="onehot", success=k % 2 == 0, robot_id=robot,
                                 outcome_id=f"{robot}:{k}"))
    print("ok")
    """
)


def test_many_processes_create_one_store_at_once(tmp_path):
    path = tmp_path / "new" / "fleet.db"  # neither the file nor its folder exists yet
    robots, per_robot = 8, 5
    start = str(time.time() + 3.0)  # after every interpreter has started and imported the store
    procs = [
        subprocess.Popen(
            [sys.executable, "-c", WRITER, str(path), f"robot{r}", str(per_robot), start],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        for r in range(robots)
    ]
    results = [(p.wait(120), *p.communicate()) for p in procs]
    refused = [(code, err.strip().splitlines()[-1:]) for code, _out, err in results if code != 0]
    assert refused == [], refused
    with sqlite3.connect(path) as conn:
        assert conn.execute("PRAGMA integrity_check").fetchone()[0] == "ok"
    with ExperienceStore(path) as store:
        ids = store.outcome_ids()
    assert ids == {f"robot{r}:{k}" for r in range(robots) for k in range(per_robot)}
    assert not list(path.parent.glob("*.lock"))  # the lock is on the folder: nothing left beside the store
