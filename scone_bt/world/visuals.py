"""How catalogue objects look in the simulator: a coloured body with the object's fiducial on its lid.

Each object is one rigid body whose visual is a compound of PyBullet primitives: the body (box or cylinder in the
catalogue's colour), a thin white cap on the lid, and an ArUco 6x6 marker (OpenCV's ``cv2.aruco.DICT_6X6_1000``:
1000 ids, the catalogue's ``marker_id``; AprilTag 36h11 has only 587, fewer than the catalogue's products) laid on
the cap. The marker is drawn as few rectangles as possible: either its black border plus its black data cells, or a
black square with its white data cells on top, whichever needs fewer; 999 of the 1000 ids fit PyBullet's 16
primitives per visual (the one that does not is `UNDRAWABLE_IDS`). Building the
marker from boxes instead of a texture keeps the scene free of image files and renders identically in every
PyBullet renderer. The collision shape is untouched.

The marker's layout (`config.markers.lid_marker`) lives with the catalogue because a detector needs it the way a
real robot needs the printed tag size: it is appearance knowledge, not simulator state.
"""

from __future__ import annotations

from functools import cache
from typing import TYPE_CHECKING

import numpy as np

from scone_bt.config import ObjectSpec
from scone_bt.config.catalogue import MARKER_DICTIONARY_SIZE, UNDRAWABLE_MARKER_IDS, Shape
from scone_bt.config.markers import (
    ARUCO_DICTIONARY,
    CAP_THICKNESS_M,
    INK_THICKNESS_M,
    LAYER_GAP_M,
    MARKER_CELLS,
    LidMarker,
    lid_marker,
)
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

DICTIONARY_SIZE = MARKER_DICTIONARY_SIZE
UNDRAWABLE_IDS = UNDRAWABLE_MARKER_IDS

_MAX_SHAPES = (
    16  # PyBullet's MAX_COMPOUND_COLLISION_SHAPES: at most this many primitives per visual shape array
)
_CAP_RGBA = (0.97, 0.97, 0.97, 1.0)
_INK_RGBA = (0.03, 0.03, 0.03, 1.0)


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
            [0, 0, sz / 2 + CAP_THICKNESS_M / 2],
            _CAP_RGBA,
            he=(sx / 2, sy / 2, CAP_THICKNESS_M / 2),
        )
    else:
        add(p.GEOM_CYLINDER, [0, 0, 0], spec.rgba, radius=sx / 2, length=sz)
        add(
            p.GEOM_CYLINDER,
            [0, 0, sz / 2 + CAP_THICKNESS_M / 2],
            _CAP_RGBA,
            radius=sx / 2,
            length=CAP_THICKNESS_M,
        )

    cell = marker.side / MARKER_CELLS
    black, white = marker_layers(spec.marker_id)
    if len(black) + len(white) + len(types) > _MAX_SHAPES:
        raise ConfigError(f"object {spec.name!r}: marker {spec.marker_id} needs too many primitives to draw")
    top = sz / 2 + marker.lift
    layers = ((black, _INK_RGBA, top - (LAYER_GAP_M if white else 0.0)), (white, _CAP_RGBA, top))
    for rects, rgba, surface in layers:
        for row, col, rows, cols in rects:
            # Column grows along +x, row grows along -y (see LidMarker).
            cx = (col + cols / 2) * cell - marker.side / 2
            cy = marker.side / 2 - (row + rows / 2) * cell
            add(
                p.GEOM_BOX,
                [cx, cy, surface - INK_THICKNESS_M / 2],
                rgba,
                he=(cols * cell / 2, rows * cell / 2, INK_THICKNESS_M / 2),
            )

    return bc.createVisualShapeArray(
        shapeTypes=types,
        halfExtents=half,
        radii=radii,
        lengths=lengths,
        rgbaColors=colours,
        visualFramePositions=frames,
    )
