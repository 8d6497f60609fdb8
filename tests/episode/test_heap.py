"""Freed heap goes back to the operating system after an episode (glibc's malloc_trim; nothing elsewhere)."""

from __future__ import annotations

import platform

import numpy as np

from scone_bt.episode.heap import _malloc_trim, release_free_heap
from scone_bt.process_stats import process_sample


def test_release_free_heap_returns_what_small_freed_blocks_held():
    if platform.libc_ver()[0] != "glibc":
        assert release_free_heap() == 0.0
        return
    assert _malloc_trim() is not None
    # 100 kB blocks come from the heap (below malloc's mmap threshold); the last one kept pins the heap's top, so
    # only a trim gives the freed ones back.
    blocks = [np.ones(100_000 // 8) for _ in range(2_000)]
    keep = blocks[-1]
    del blocks
    before = process_sample()[0]
    assert release_free_heap() >= 0.0
    after = process_sample()[0]
    assert after < before - 50, (before, after)
    assert keep.sum() == 100_000 // 8
