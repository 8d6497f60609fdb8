"""Where an episode's wall and CPU time goes: the loop's parts, a clock per part, an embedder timed under one."""

from __future__ import annotations

import time
from enum import StrEnum
from typing import Any

__all__ = ["LoopPart", "TimedEmbedder", "WallClock"]


class LoopPart(StrEnum):
    """A part of the episode loop whose wall and CPU time the summary reports (the breakdowns' keys)."""

    STARTUP = "startup"
    TREE = "tree"  # ticking the tree, less perception and embedding
    PERCEPTION = "perception"
    EMBEDDING = "embedding"
    PLANNING_WAIT = "planning_wait"  # simulated time held while the planner computes
    PHYSICS = "physics"
    HUMAN = "human"
    LOGGING = "logging"


class WallClock:
    """Wall and main-thread CPU seconds per part of the episode loop (``with clock(LoopPart.PHYSICS): ...``)."""

    def __init__(self) -> None:
        self.seconds: dict[LoopPart, float] = {}
        self.cpu_seconds: dict[LoopPart, float] = {}
        self._part = LoopPart.STARTUP
        self._since = self._cpu_since = 0.0

    def __call__(self, part: LoopPart) -> WallClock:
        self._part = part
        return self

    def __enter__(self) -> None:
        self._since, self._cpu_since = time.perf_counter(), time.thread_time()

    def __exit__(self, *exc: object) -> None:
        self.add(self._part, time.perf_counter() - self._since, time.thread_time() - self._cpu_since)

    def add(self, part: LoopPart, seconds: float, cpu_seconds: float = 0.0) -> None:
        self.seconds[part] = self.seconds.get(part, 0.0) + seconds
        self.cpu_seconds[part] = self.cpu_seconds.get(part, 0.0) + cpu_seconds


class TimedEmbedder:
    """An embedder whose `embed` calls count under "embedding" (a shared embedder itself stays unchanged)."""

    def __init__(self, inner: Any, clock: WallClock) -> None:
        self._inner = inner
        self._clock = clock

    def embed(self, texts: Any) -> Any:
        t, c = time.perf_counter(), time.thread_time()
        try:
            return self._inner.embed(texts)
        finally:
            self._clock.add(LoopPart.EMBEDDING, time.perf_counter() - t, time.thread_time() - c)

    def __getattr__(self, name: str) -> Any:
        return getattr(self._inner, name)
