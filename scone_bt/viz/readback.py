"""Read a `.rrd` back with rerun's own chunk API: which entities it holds, which ticks, how many rows."""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from scone_bt.errors import ConfigError
from scone_bt.viz import paths as P

__all__ = ["RecordingSummary", "summarize_recording", "component_values", "body_poses"]


@dataclass(frozen=True)
class RecordingSummary:
    """What a recording contains.

    Attributes:
        application_id: rerun application id ("scone_bt").
        recording_id: The recording's id.
        entity_paths: Every entity path that holds data, e.g. "/world/robot/panda_link1".
        rows: Entity path → number of rows logged (static and temporal together).
        ticks: Distinct values of the `tick` timeline, ascending.
        has_blueprint: The file carries a default blueprint.
    """

    application_id: str
    recording_id: str
    entity_paths: frozenset[str]
    rows: dict[str, int]
    ticks: tuple[int, ...]
    has_blueprint: bool

    @property
    def num_ticks(self) -> int:
        return len(self.ticks)


def _reader(path: str | Path) -> Any:
    import rerun as rr

    if not Path(path).is_file():
        raise ConfigError(f"no recording at {path}")
    try:
        return rr.chunk.RrdReader(path)
    except Exception as exc:  # rerun raises its own types for foreign or truncated files
        raise ConfigError(f"{path} is not a readable .rrd recording ({exc})") from None


def summarize_recording(path: str | Path) -> RecordingSummary:
    """Summarise the first recording stored in an `.rrd` file."""
    reader = _reader(path)
    recordings = reader.recordings()
    if not recordings:
        raise ConfigError(f"{path} holds no recording")
    rows: Counter[str] = Counter()
    ticks: set[int] = set()
    for chunk in reader.stream(store=recordings[0]):
        if chunk.entity_path.startswith("/__"):  # rerun's own properties
            continue
        rows[chunk.entity_path] += chunk.num_rows
        if P.TICK in chunk.timeline_names:
            ticks.update(int(t) for t in chunk.to_record_batch().column(P.TICK).to_pylist() if t is not None)
    return RecordingSummary(
        application_id=recordings[0].application_id,
        recording_id=recordings[0].recording_id,
        entity_paths=frozenset(rows),
        rows=dict(rows),
        ticks=tuple(sorted(ticks)),
        has_blueprint=bool(reader.blueprints()),
    )


def component_values(path: str | Path, entity_path: str, component: str) -> list[tuple[int | None, Any]]:
    """(tick, value) for every temporal row of one component, e.g. ("/world/robot/panda_link0",
    "Transform3D:translation"); static rows have tick None."""
    out: list[tuple[int | None, Any]] = []
    for chunk in _reader(path).stream():
        if chunk.entity_path != entity_path:
            continue
        batch = chunk.to_record_batch()
        if component not in batch.schema.names:
            continue
        values = batch.column(component).to_pylist()
        tick_col = batch.column(P.TICK).to_pylist() if P.TICK in batch.schema.names else [None] * len(values)
        out.extend(zip(tick_col, values, strict=True))
    return sorted(out, key=lambda tv: -1 if tv[0] is None else tv[0])


def body_poses(path: str | Path) -> dict[str, list[tuple[int, tuple[float, float, float]]]]:
    """Frame id ("robot/panda_link1", "object/salt") → [(tick, world position in metres)], in tick order."""
    out: dict[str, list[tuple[int, tuple[float, float, float]]]] = {}
    for chunk in _reader(path).stream():
        if chunk.entity_path != f"/{P.POSES}":
            continue
        batch = chunk.to_record_batch()
        ticks = batch.column(P.TICK).to_pylist()
        frames = batch.column("Transform3D:child_frame").to_pylist()
        translations = batch.column("Transform3D:translation").to_pylist()
        for tick, frame, translation in zip(ticks, frames, translations, strict=True):
            out.setdefault(frame[0], []).append((int(tick), tuple(translation[0])))
    return {frame: sorted(rows) for frame, rows in out.items()}
