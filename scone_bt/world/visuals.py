"""How catalogue objects look in the simulator: a coloured body with the object's fiducial on its lid.

Each object is one rigid body whose visual is a compound of PyBullet primitives: the body (box or cylinder in the
catalogue's colour), a thin white cap on the lid, and an ArUco 6x6 marker (OpenCV's ``cv2.aruco.DICT_6X6_1000``:
1000 ids, the catalogue's ``marker_id``; AprilTag 36h11 has only 587, fewer than the catalogue's products) laid on
the cap. The marker is drawn as few rectangles as possible: either its black border plus its black data cells, or a
black square with its white data cells on top, whichever needs fewer; 999 of the 1000 ids fit PyBullet's 16
primitives per visual (the one that does not is `UNDRAWABLE_IDS`). Building the
marker from boxes instead of a texture keeps the scene free of image files and renders identically in every
PyBullet renderer. The collision shape is untouched.

The marker's layout is public (`lid_marker`) because a detector needs it the way a real robot needs the printed
tag size: it is appearance knowledge, not simulator state.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache
from typing import TYPE_CHECKING

import numpy as np

from scone_bt.config import ObjectSpec
from scone_bt.config.catalogue import MARKER_DICTIONARY_SIZE, UNDRAWABLE_MARKER_IDS, Shape
from scone_bt.errors import ConfigError

if TYPE_CHECKING:
    from pybullet_utils.bullet_client import BulletClient

__all__ = [
    "ARUCO_DICTIONARY",
    "DICTIONARY_SIZE",
    "UNDRAWABLE_IDS",
    "MARKER_CELLS",
    "LidMarker",
    "lid_marker",
    "marker_cells",
    "marker_layers",
    "create_object_visual",
]

ARUCO_DICTIONARY = "DICT_6X6_1000"
"""The cv2.aruco dictionary the markers come from (ArUco 6x6, 1000 ids, up to 4 bits of error correction)."""
MARKER_CELLS = 8
"""Cells per marker side: 6 data bits plus a one-cell black border on each side."""
DICTIONARY_SIZE = MARKER_DICTIONARY_SIZE
UNDRAWABLE_IDS = UNDRAWABLE_MARKER_IDS

_CAP_THICKNESS = 0.0015  # metres: the white cap that carries the marker
# TinyRenderer tessellates a cylinder's flat end as a shallow cone (about 0.9 mm high at the centre), so the black
# cells float a little above the cap to stay visible on round lids too.
_INK_GAP = 0.001  # metres
_INK_THICKNESS = 0.0005  # metres
# White cells drawn over a black square sit this much higher, so the two never fight in the depth buffer.
_LAYER_GAP = 0.0003  # metres
_MAX_SHAPES = (
    16  # PyBullet's MAX_COMPOUND_COLLISION_SHAPES: at most this many primitives per visual shape array
)
_QUIET_FRACTION = 0.06  # white margin around the marker as a fraction of the lid's usable square
_MIN_QUIET = 0.0015  # metres
_CAP_RGBA = (0.97, 0.97, 0.97, 1.0)
_INK_RGBA = (0.03, 0.03, 0.03, 1.0)


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
    if not 0 <= spec.marker_id < DICTIONARY_SIZE or spec.marker_id in UNDRAWABLE_IDS:
        raise ConfigError(
            f"object {spec.name!r}: marker_id {spec.marker_id} is not a drawable {ARUCO_DICTIONARY} id"
            f" (valid: 0-{DICTIONARY_SIZE - 1} except {', '.join(map(str, sorted(UNDRAWABLE_IDS)))})"
        )
    sx, sy, sz = spec.size
    # The largest square on the lid: the whole short side of a box, the inscribed square of a disc.
    usable = min(sx, sy) if spec.shape == Shape.BOX else sx / np.sqrt(2.0)
    quiet = max(_QUIET_FRACTION * usable, _MIN_QUIET)
    return LidMarker(
        marker_id=spec.marker_id,
        side=float(usable - 2 * quiet),
        lift=_CAP_THICKNESS + _INK_GAP + _INK_THICKNESS + _LAYER_GAP,
        top_z=sz / 2,
    )


@cache
def marker_cells(marker_id: int) -> np.ndarray:
    """(8, 8) bool array, True where the marker is black; row 0 is the marker's top edge."""
    import cv2

    dictionary = cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, ARUCO_DICTIONARY))
    image = cv2.aruco.generateImageMarker(dictionary, marker_id, MARKER_CELLS)
    cells = image < 128
    cells.setflags(write=False)
    return cells


Rect = tuple[int, int, int, int]
"""A block of marker cells: (first row, first column, rows, columns)."""


def _rectangles(mask: np.ndarray) -> list[Rect]:
    """Cover the True cells with disjoint rectangles: row runs grown downwards, or the same on the transpose."""

    def cover(cells: np.ndarray) -> list[Rect]:
        rows, cols = cells.shape
        taken = np.zeros_like(cells)
        out = []
        for r in range(rows):
            c = 0
            while c < cols:
                if not cells[r, c] or taken[r, c]:
                    c += 1
                    continue
                start = c
                while c < cols and cells[r, c] and not taken[r, c]:
                    c += 1
                end = r + 1
                while end < rows and cells[end, start:c].all() and not taken[end, start:c].any():
                    end += 1
                taken[r:end, start:c] = True
                out.append((r, start, end - r, c - start))
        return out

    across = cover(mask)
    down = [(r, c, nr, nc) for c, r, nc, nr in cover(mask.T)]
    return across if len(across) <= len(down) else down


def marker_layers(marker_id: int) -> tuple[list[Rect], list[Rect]]:
    """The marker as (black rectangles, white rectangles drawn over them), in whole-marker cell coordinates.

    Either the black border (four bars) plus the black data cells and no white, or one black square plus the white
    data cells, whichever needs fewer primitives.
    """
    cells = marker_cells(marker_id)
    inner = cells[1:-1, 1:-1]
    n = MARKER_CELLS

    def shift(rects: list[Rect]) -> list[Rect]:
        return [(r + 1, c + 1, nr, nc) for r, c, nr, nc in rects]

    border: list[Rect] = [(0, 0, 1, n), (n - 1, 0, 1, n), (1, 0, n - 2, 1), (1, n - 1, n - 2, 1)]
    black_cells = shift(_rectangles(inner))
    white_cells = shift(_rectangles(~inner))
    if len(border) + len(black_cells) <= 1 + len(white_cells):
        return border + black_cells, []
    return [(0, 0, n, n)], white_cells


def create_object_visual(bc: BulletClient, spec: ObjectSpec) -> int:
    """Return a PyBullet visual shape id for the object: body, white cap and marker, one rigid visual."""
    import pybullet as p

    sx, sy, sz = spec.size
    marker = lid_marker(spec)
    types: list[int] = []
    half: list[list[float]] = []
    radii: list[float] = []
    lengths: list[float] = []
    colours: list[list[float]] = []
    frames: list[list[float]] = []

    def add(
        kind: int,
        position: list[float],
        rgba: tuple[float, ...],
        *,
        he=(0.0, 0.0, 0.0),
        radius=0.0,
        length=0.0,
    ):
        types.append(kind)
        half.append(list(he))
        radii.append(radius)
        lengths.append(length)
        colours.append(list(rgba))
        frames.append(position)

    if spec.shape == Shape.BOX:
        add(p.GEOM_BOX, [0, 0, 0], spec.rgba, he=(sx / 2, sy / 2, sz / 2))
        add(
            p.GEOM_BOX,
            [0, 0, sz / 2 + _CAP_THICKNESS / 2],
            _CAP_RGBA,
            he=(sx / 2, sy / 2, _CAP_THICKNESS / 2),
        )
    else:
        add(p.GEOM_CYLINDER, [0, 0, 0], spec.rgba, radius=sx / 2, length=sz)
        add(
            p.GEOM_CYLINDER,
            [0, 0, sz / 2 + _CAP_THICKNESS / 2],
            _CAP_RGBA,
            radius=sx / 2,
            length=_CAP_THICKNESS,
        )

    cell = marker.side / MARKER_CELLS
    black, white = marker_layers(spec.marker_id)
    if len(black) + len(white) + len(types) > _MAX_SHAPES:
        raise ConfigError(f"object {spec.name!r}: marker {spec.marker_id} needs too many primitives to draw")
    top = sz / 2 + marker.lift
    layers = ((black, _INK_RGBA, top - (_LAYER_GAP if white else 0.0)), (white, _CAP_RGBA, top))
    for rects, rgba, surface in layers:
        for row, col, rows, cols in rects:
            # Column grows along +x, row grows along -y (see LidMarker).
            cx = (col + cols / 2) * cell - marker.side / 2
            cy = marker.side / 2 - (row + rows / 2) * cell
            add(
                p.GEOM_BOX,
                [cx, cy, surface - _INK_THICKNESS / 2],
                rgba,
                he=(cols * cell / 2, rows * cell / 2, _INK_THICKNESS / 2),
            )

    return bc.createVisualShapeArray(
        shapeTypes=types,
        halfExtents=half,
        radii=radii,
        lengths=lengths,
        rgbaColors=colours,
        visualFramePositions=frames,
    )
