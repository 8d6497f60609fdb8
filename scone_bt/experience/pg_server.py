"""A throwaway PostgreSQL server in a temporary folder (for tests and the fleet benchmark), stopped on exit.

PostgreSQL refuses to run as root, so when this process is root the server runs as the `postgres` user that
Debian's package creates (`runuser -u postgres`). It listens on 127.0.0.1 on a free port, trusts local
connections, and its folder is removed when it stops.

    with TemporaryPostgres() as pg:
        store = PostgresExperienceStore(pg.create_database("fleet"))
"""

from __future__ import annotations

import glob
import os
import shutil
import socket
import subprocess
import tempfile
from pathlib import Path

from scone_bt.errors import ExperienceStoreError

__all__ = ["TemporaryPostgres", "find_postgres_bin"]


def find_postgres_bin() -> Path | None:
    """The folder holding initdb and pg_ctl (Debian's /usr/lib/postgresql/<v>/bin, else PATH), or None."""
    found = sorted(glob.glob("/usr/lib/postgresql/*/bin/initdb"), key=lambda p: int(Path(p).parts[-3]))
    if found:
        return Path(found[-1]).parent
    initdb = shutil.which("initdb")
    return Path(initdb).parent if initdb else None


def _others_can_enter(folder: Path) -> bool:
    """Whether every folder from / down to `folder` lets other users through (o+x)."""
    folder = folder.resolve()
    return all(p.stat().st_mode & 0o001 for p in [folder, *folder.parents])


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


class TemporaryPostgres:
    """Start a private PostgreSQL server; `url` is its superuser URL.

    Raises:
        ExperienceStoreError: the binaries are missing, or initdb / pg_ctl failed (their output is included).
    """

    def __init__(self) -> None:
        found = find_postgres_bin()
        if found is None:
            raise ExperienceStoreError(
                "PostgreSQL server binaries (initdb, pg_ctl) not found; install Debian's postgresql package"
            )
        self.bin: Path = found
        self.folder: Path | None = None
        self.port = 0
        self.url = ""
        self._as: list[str] = []

    def _run(self, *args: str) -> None:
        proc = subprocess.run(
            [*self._as, *args], capture_output=True, text=True, timeout=120, cwd=str(self.folder)
        )
        if proc.returncode != 0:
            tail = (proc.stderr or proc.stdout).strip().splitlines()[-3:]
            raise ExperienceStoreError(f"{Path(args[0]).name} failed: {' | '.join(tail)}")

    def start(self) -> TemporaryPostgres:
        parent = Path(tempfile.gettempdir())
        if os.geteuid() == 0 and not _others_can_enter(parent):
            parent = Path(
                "/tmp"
            )  # e.g. TMPDIR under /root: the postgres user could not reach the data folder
        self.folder = Path(tempfile.mkdtemp(prefix="scone-pg-", dir=parent))
        if os.geteuid() == 0:
            import pwd

            try:
                user = pwd.getpwnam("postgres")
            except KeyError:
                raise ExperienceStoreError(
                    "running as root, and there is no 'postgres' user to run the server as"
                ) from None
            os.chown(self.folder, user.pw_uid, user.pw_gid)
            self._as = ["runuser", "-u", "postgres", "--"]
        data = self.folder / "data"
        self.port = _free_port()
        self._run(
            str(self.bin / "initdb"),
            "-D",
            str(data),
            "-A",
            "trust",
            "-U",
            "postgres",
            "-E",
            "UTF8",
            "--no-sync",
        )
        options = f"-p {self.port} -k {self.folder} -c listen_addresses=127.0.0.1 -c max_connections=50"
        self._run(
            str(self.bin / "pg_ctl"),
            "-D",
            str(data),
            "-o",
            options,
            "-l",
            str(self.folder / "log"),
            "-w",
            "start",
        )
        self.url = f"postgresql://postgres@127.0.0.1:{self.port}/postgres"
        return self

    def create_database(self, name: str) -> str:
        """Create database `name` (letters, digits, _); returns its URL."""
        import psycopg

        if not name.replace("_", "").isalnum():
            raise ExperienceStoreError(f"database name {name!r}: use letters, digits and _ only")
        with psycopg.connect(self.url, autocommit=True) as conn:
            conn.execute(f"CREATE DATABASE {name}")
        return f"postgresql://postgres@127.0.0.1:{self.port}/{name}"

    def stop(self) -> None:
        if self.folder is None:
            return
        try:
            if (self.folder / "data" / "postmaster.pid").exists():
                self._run(
                    str(self.bin / "pg_ctl"), "-D", str(self.folder / "data"), "-m", "immediate", "-w", "stop"
                )
        finally:
            shutil.rmtree(self.folder, ignore_errors=True)
            self.folder = None

    def __enter__(self) -> TemporaryPostgres:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()
