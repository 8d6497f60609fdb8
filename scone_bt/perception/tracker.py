"""Keeps a stable id per object across ticks and a running record of how reliably it is seen.

Identity comes from the fiducial: a marker names exactly one catalogue object, so a name keeps its track id for the
whole episode even when the object is picked up, moved or hidden for a while. Each track keeps an exponentially
smoothed detection confidence in which a missed tick counts as zero, so objects that flicker in and out of view
score lower than objects seen every tick.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

from scone_bt.errors import ConfigError
from scone_bt.perception.types import Detection

__all__ = ["Track", "Tracker"]


@dataclass(frozen=True)
class Track:
    """What the tracker knows about one object.

    Attributes:
        track_id: Stable id (0, 1, 2, ... in order of first sighting).
        name: Catalogue name.
        position: Last detected top-face centre, world frame, metres.
        yaw: Last detected yaw, radians.
        confidence: Smoothed detection confidence in [0, 1]; a missed update counts as 0.
        first_seen: Simulated time of the first detection, seconds.
        last_seen: Simulated time of the latest detection, seconds.
        hits: Updates in which the object was detected.
        misses: Updates since the first sighting in which it was not.
    """

    track_id: int
    name: str
    position: tuple[float, float, float]
    yaw: float
    confidence: float
    first_seen: float
    last_seen: float
    hits: int
    misses: int


class Tracker:
    """Assigns stable track ids to detections, one update per perception tick.

    Args:
        smoothing: Weight of the newest observation in each track's confidence, in (0, 1].
    """

    def __init__(self, smoothing: float = 0.5) -> None:
        if not 0 < smoothing <= 1:
            raise ConfigError(f"tracker: smoothing must be in (0, 1], got {smoothing}")
        self.smoothing = smoothing
        self._tracks: dict[str, Track] = {}
        self._last_time: float | None = None

    @property
    def tracks(self) -> dict[str, Track]:
        """Every object seen so far, by name."""
        return dict(self._tracks)

    def update(self, detections: Sequence[Detection], sim_time: float) -> list[Detection]:
        """Fold one frame's detections into the tracks; returns them with their stable track ids.

        Args:
            detections: One frame's detections (at most one per name; the most confident wins otherwise).
            sim_time: Simulated time of the frame, seconds; must not go backwards.
        """
        if self._last_time is not None and sim_time < self._last_time:
            raise ConfigError(
                f"tracker: time went backwards ({sim_time} s after {self._last_time} s); call reset()"
            )
        self._last_time = sim_time
        best: dict[str, Detection] = {}
        for det in detections:
            if det.name not in best or det.confidence > best[det.name].confidence:
                best[det.name] = det
        a = self.smoothing
        for name, track in self._tracks.items():
            if name not in best:
                self._tracks[name] = replace(
                    track, confidence=(1 - a) * track.confidence, misses=track.misses + 1
                )
        out = []
        for name in sorted(best):
            det = best[name]
            known = self._tracks.get(name)
            if known is None:
                track = Track(
                    len(self._tracks), name, det.position, det.yaw, det.confidence, sim_time, sim_time, 1, 0
                )
            else:
                track = replace(
                    known,
                    position=det.position,
                    yaw=det.yaw,
                    confidence=a * det.confidence + (1 - a) * known.confidence,
                    last_seen=sim_time,
                    hits=known.hits + 1,
                )
            self._tracks[name] = track
            out.append(replace(det, track_id=track.track_id))
        return out

    def reset(self) -> None:
        """Forget every track (a new episode)."""
        self._tracks.clear()
        self._last_time = None
