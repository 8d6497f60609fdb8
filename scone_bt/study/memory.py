"""``scone-study simulate --memory FILE``: the simulated study's process sampled after each participant.

A study runs dozens of sessions in one process: whatever a session leaves behind adds up. After each participant
(two sessions, each one episode) the process's resident memory, open file descriptors and OS threads are sampled,
as ``scone-bench soak`` samples after each episode; the report gives the memory slope per session after a warm-up
and the descriptors' and threads' growth.
"""

from __future__ import annotations

import gc
import os
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

__all__ = [
    "MemoryProbe",
    "ParticipantSample",
    "SESSIONS_PER_PARTICIPANT",
    "TARGET_MB_PER_SESSION",
    "WARMUP_PARTICIPANTS",
    "is_memory_report",
]

SESSIONS_PER_PARTICIPANT = 2
"""Each simulated participant runs two sessions (one per condition)."""
WARMUP_PARTICIPANTS = 5
"""Participants before the memory slope is fitted: ten sessions, the soak's ten-episode warm-up."""
TARGET_MB_PER_SESSION = 0.5
"""The soak's memory target (`scone_bt.benchmarks.soak.TARGETS`), per session: a session is one episode."""


_REPORT_KEYS = frozenset({"participants_run", "sessions_run", "rss_growth_mb_per_session", "per_participant"})
"""Keys every report of `MemoryProbe.report` has: an existing file with them is an earlier report (replaced)."""
_MAX_REPORT_BYTES = 64 << 20  # a report of 100 000 participants is about 10 MB


def is_memory_report(path: Path) -> bool:
    """Whether the existing file `path` is empty or a memory report of ``scone-study simulate --memory``: the only
    files ``--memory`` may replace (a JSON file of anything else, e.g. an analysis' results.json, is kept)."""
    import json

    try:
        if path.stat().st_size == 0:
            return True  # nothing to lose
        if path.stat().st_size > _MAX_REPORT_BYTES:
            return False
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError, RecursionError):  # unreadable, not UTF-8, not JSON
        return False
    return isinstance(data, dict) and data.keys() >= _REPORT_KEYS


@dataclass(frozen=True)
class ParticipantSample:
    """The process after one participant's sessions.

    Attributes:
        participant: Its index (0 first).
        rss_mb: Resident memory, MB (2**20 bytes).
        fds: Open file descriptors.
        threads: OS threads of the process.
        wall_s: Wall seconds since the study began.
    """

    participant: int
    rss_mb: float
    fds: int
    threads: int
    wall_s: float


@dataclass
class MemoryProbe:
    """Samples the process after each participant (`sample`), and reports (`report`).

    With ``path`` the report so far is written there after every participant, so a study stopped part way (hours
    of physics episodes) still leaves the samples it took (``participants_run`` says how many).
    """

    path: Path | None = None
    settings: dict[str, Any] = field(default_factory=dict)
    started: float = field(default_factory=time.perf_counter)
    samples: list[ParticipantSample] = field(default_factory=list)

    def sample(self, participant: int) -> None:
        from scone_bt.process_stats import process_sample

        gc.collect()  # what is still reachable is what the sample should see
        rss_mb, fds, threads = process_sample()
        wall = round(time.perf_counter() - self.started, 1)
        self.samples.append(ParticipantSample(participant, round(rss_mb, 2), fds, threads, wall))
        if self.path is not None:
            from scone_bt.checks import write_atomic
            from scone_bt.strict_json import dumps

            write_atomic(self.path, dumps(self.report(), indent=2) + "\n")

    def report(self) -> dict[str, Any]:
        """The JSON report: the settings (what was simulated), the slope and growths, the per-participant table."""
        from scone_bt.process_stats import slope

        if not self.samples:
            raise ValueError("no participant was sampled")
        warmup = min(WARMUP_PARTICIPANTS, len(self.samples) - 1)
        per_participant = slope([s.rss_mb for s in self.samples[warmup:]])
        per_session = None if per_participant is None else per_participant / SESSIONS_PER_PARTICIPANT
        base, last = self.samples[max(warmup - 1, 0)], self.samples[-1]
        target = TARGET_MB_PER_SESSION
        return {
            **self.settings,
            "participants_run": len(self.samples),
            "sessions_run": SESSIONS_PER_PARTICIPANT * len(self.samples),
            "warmup_participants": warmup,
            "rss_growth_mb_per_session": round(per_session, 4) if per_session is not None else None,
            "rss_growth_mb_per_participant": round(per_participant, 4)
            if per_participant is not None
            else None,
            "rss_mb_after_warmup": base.rss_mb,
            "rss_mb_last": last.rss_mb,
            "rss_mb_max": max(s.rss_mb for s in self.samples),
            "fd_growth": last.fds - base.fds,
            "thread_growth": last.threads - base.threads,
            "wall_s": last.wall_s,
            "cpu_count": os.cpu_count(),
            "targets": {"rss_growth_mb_per_session": target, "fd_growth": 0, "thread_growth": 0},
            "meets_targets": bool(
                per_session is not None
                and per_session <= target
                and last.fds <= base.fds
                and last.threads <= base.threads
            ),
            "per_participant": [asdict(s) for s in self.samples],
        }
