"""Where a recording is saved: its file, or beside it for a run that ended early (no rerun import here)."""

from __future__ import annotations

from pathlib import Path

__all__ = ["unfinished_path"]


def unfinished_path(save: Path) -> Path:
    """Where the recording of a run that ended early goes when `save` already exists: ``NAME.unfinished.rrd``
    beside it (an older unfinished recording there is replaced; a file there of another kind never is)."""
    from scone_bt.checks import is_output_kind

    stem, n = f"{save.stem}.unfinished", 1
    path = save.with_name(f"{stem}.rrd")
    while path.exists() and not is_output_kind(path, "rrd"):
        n += 1
        path = save.with_name(f"{stem}-{n}.rrd")
    return path
