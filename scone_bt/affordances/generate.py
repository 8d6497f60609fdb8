"""From detections to affordances, using only the known shelf geometry (`SceneSpec.on_shelf`, the one
definition of "on the shelf")."""

from __future__ import annotations

from collections.abc import Sequence

from scone_bt.affordances.types import Affordance, action_text
from scone_bt.config import SceneSpec
from scone_bt.perception.types import Detection

__all__ = ["generate_affordances"]


def generate_affordances(detections: Sequence[Detection], scene: SceneSpec) -> list[Affordance]:
    """One "Put X on table" per distinct object seen on the shelf, most confident detection first."""
    best: dict[str, Detection] = {}
    for det in detections:
        if scene.on_shelf(det.position) and (
            det.name not in best or det.confidence > best[det.name].confidence
        ):
            best[det.name] = det
    return [Affordance(name, action_text(name), det) for name, det in sorted(best.items())]
