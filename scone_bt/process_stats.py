"""The process's own resources (Linux /proc) and the slope of a series: what a soak samples and fits.

`scone-bench soak` samples after each episode and `scone-study simulate --memory` after each participant.
"""

from __future__ import annotations

import os

__all__ = ["process_sample", "slope"]


def _status_field(name: str) -> int:
    """A numeric field of /proc/self/status (the first number on its line)."""
    with open("/proc/self/status", encoding="ascii") as f:
        for line in f:
            if line.startswith(name + ":"):
                return int(line.split()[1])
    raise RuntimeError(f"/proc/self/status has no {name} line")


def process_sample() -> tuple[float, int, int]:
    """Resident memory (MB), open file descriptors and OS threads of this process (Linux /proc)."""
    rss_mb = _status_field("VmRSS") / 1024.0
    fds = len(os.listdir("/proc/self/fd")) - 1  # the listing's own descriptor
    return rss_mb, fds, _status_field("Threads")


def slope(values: list[float]) -> float | None:
    """Least-squares slope of ``values`` against their index (per step); None for fewer than two."""
    n = len(values)
    if n < 2:
        return None
    mean_x, mean_y = (n - 1) / 2.0, sum(values) / n
    num = sum((i - mean_x) * (v - mean_y) for i, v in enumerate(values))
    den = sum((i - mean_x) ** 2 for i in range(n))
    return num / den
