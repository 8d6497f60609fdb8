"""The fiducial on each product's lid: which ArUco dictionary, how big, how high above the lid.

Appearance knowledge, not simulator state: a detector needs it the way a real robot needs the printed tag's size,
and the simulator (`world.visuals`) draws the marker from the same layout. The marker stands on a thin white cap;
its black cells float a little above the cap (so they stay visible on the shallow cone TinyRenderer makes of a
cylinder's flat end), and white cells drawn over a black square sit a little higher still.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from scone_bt.config.catalogue import MARKER_DICTIONARY_SIZE, UNDRAWABLE_MARKER_IDS, ObjectSpec, Shape
from scone_bt.errors import ConfigError

__all__ = [
    "ARUCO_DICTIONARY",
    "CAP_THICKNESS_M",
    "INK_GAP_M",
    "INK_THICKNESS_M",
    "LAYER_GAP_M",
    "MARKER_CELLS",
    "LidMarker",
    "lid_marker",
]

ARUCO_DICTIONARY = "DICT_6X6_1000"
"""The cv2.aruco dictionary the markers come from (ArUco 6x6, 1000 ids, up to 4 bits of error correction)."""
MARKER_CELLS = 8
"""Cells per marker side: 6 data bits plus a one-cell black border on each side."""

CAP_THICKNESS_M = 0.0015
"""The white cap that carries the marker."""
INK_GAP_M = 0.001
"""The black cells float this far above the cap."""
INK_THICKNESS_M = 0.0005
"""Thickness of a drawn cell."""
LAYER_GAP_M = 0.0003
"""White cells drawn over a black square sit this much higher, so the two never fight in the depth buffer."""
_QUIET_FRACTION = 0.06  # white margin around the marker as a fraction of the lid's usable square
_MIN_QUIET_M = 0.0015


@dataclass(frozen=True)
class LidMarker:
    """Where an object's fiducial sits, in the object's body frame.

    Attributes:
        marker_id: ArUco DICT_6X6_1000 id.
        side: Side length of the marker including its black border, metres.
        lift: Height of the printed surface above the object's top face, metres.
        top_z: Height of the top face above the body origin (the body's centre), metres.

    The marker is centred on the lid; its image x axis (corner 0 → corner 1) points along the body's +x axis and
    its image y axis (corner 0 → corner 3) along the body's -y axis, so a camera above reads the body's yaw.
    """

    marker_id: int
    side: float
    lift: float
    top_z: float


def lid_marker(spec: ObjectSpec) -> LidMarker:
    """The marker layout on one catalogue object's lid.

    Raises:
        ConfigError: If the marker id is outside the dictionary.
    """
    if not 0 <= spec.marker_id < MARKER_DICTIONARY_SIZE or spec.marker_id in UNDRAWABLE_MARKER_IDS:
        raise ConfigError(
            f"object {spec.name!r}: marker_id {spec.marker_id} is not a drawable {ARUCO_DICTIONARY} id"
            f" (valid: 0-{MARKER_DICTIONARY_SIZE - 1} except {', '.join(map(str, sorted(UNDRAWABLE_MARKER_IDS)))})"
        )
    sx, sy, sz = spec.size
    # The largest square on the lid: the whole short side of a box, the inscribed square of a disc.
    usable = min(sx, sy) if spec.shape == Shape.BOX else sx / np.sqrt(2.0)
    quiet = max(_QUIET_FRACTION * usable, _MIN_QUIET_M)
    return LidMarker(
        marker_id=spec.marker_id,
        side=float(usable - 2 * quiet),
        lift=CAP_THICKNESS_M + INK_GAP_M + INK_THICKNESS_M + LAYER_GAP_M,
        top_z=sz / 2,
    )
