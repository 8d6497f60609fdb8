"""Object visuals: one rigid visual per object, with a decodable ArUco marker on the lid."""

from __future__ import annotations

from dataclasses import replace

import cv2
import numpy as np
import pytest

from scone_bt.errors import ConfigError
from scone_bt.world.visuals import (
    _MAX_SHAPES,
    ARUCO_DICTIONARY,
    DICTIONARY_SIZE,
    MARKER_CELLS,
    UNDRAWABLE_IDS,
    create_object_visual,
    lid_marker,
    marker_cells,
    marker_layers,
)


def test_every_marker_pattern_decodes_to_its_own_id():
    detector = cv2.aruco.ArucoDetector(
        cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, ARUCO_DICTIONARY))
    )
    for marker_id in range(DICTIONARY_SIZE):
        cells = np.where(marker_cells(marker_id), 0, 255).astype(np.uint8)
        image = np.pad(
            cv2.resize(cells, None, fx=10, fy=10, interpolation=cv2.INTER_NEAREST), 20, constant_values=255
        )
        _, ids, _ = detector.detectMarkers(image)
        assert ids is not None and ids.ravel().tolist() == [marker_id]


def test_markers_fit_on_their_lids(kitchen_cfg):
    for spec in kitchen_cfg.catalogue.objects:
        marker = lid_marker(spec)
        sx, sy, sz = spec.size
        reach = marker.side / 2 * np.sqrt(2) if spec.shape == "cylinder" else marker.side / 2
        assert reach < (sx / 2 if spec.shape == "cylinder" else min(sx, sy) / 2)
        assert marker.top_z == pytest.approx(sz / 2) and 0 < marker.lift < 0.005


def test_marker_id_outside_the_dictionary_is_a_config_error(kitchen_cfg):
    spec = replace(kitchen_cfg.catalogue.get("salt"), marker_id=DICTIONARY_SIZE)
    with pytest.raises(ConfigError, match="0-999"):
        lid_marker(spec)
    with pytest.raises(ConfigError, match="0-999 except"):
        lid_marker(replace(spec, marker_id=min(UNDRAWABLE_IDS)))


def test_marker_layers_paint_exactly_the_marker_within_pybullets_primitive_limit():
    for marker_id in range(DICTIONARY_SIZE):
        black, white = marker_layers(marker_id)
        painted = np.zeros((MARKER_CELLS, MARKER_CELLS), bool)
        for r, c, nr, nc in black:
            painted[r : r + nr, c : c + nc] = True
        for r, c, nr, nc in white:
            painted[r : r + nr, c : c + nc] = False
        assert (painted == marker_cells(marker_id)).all(), marker_id
        fits = 2 + len(black) + len(white) <= _MAX_SHAPES  # plus the body and the cap
        assert fits == (marker_id not in UNDRAWABLE_IDS), marker_id


def test_visual_is_one_body_with_body_cap_and_marker_cells(kitchen, kitchen_cfg):
    import pybullet as p

    for name in ("salt", "sugar"):
        spec = kitchen_cfg.catalogue.get(name)
        visual = create_object_visual(kitchen.bc, spec)
        body = kitchen.bc.createMultiBody(0.1, -1, visual)
        shapes = kitchen.bc.getVisualShapeData(body)
        assert shapes[0][2] == (p.GEOM_BOX if spec.shape == "box" else p.GEOM_CYLINDER)
        black, white = marker_layers(spec.marker_id)
        assert len(shapes) == 2 + len(black) + len(white)
        cell = lid_marker(spec).side / MARKER_CELLS
        # PyBullet reports a box's full extents: every marker box has the size of its block of cells.
        for shape, (_, _, rows, cols) in zip(shapes[2:], [*black, *white], strict=True):
            assert shape[3][0] == pytest.approx(cols * cell) and shape[3][1] == pytest.approx(rows * cell)
        assert all(s[1] == -1 for s in shapes)  # all on the base link: one rigid body
