"""Object visuals: one rigid visual per object, with a decodable ArUco marker on the lid."""

from __future__ import annotations

from dataclasses import replace

import cv2
import numpy as np
import pytest

from scone_bt.errors import ConfigError
from scone_bt.world.visuals import MARKER_CELLS, create_object_visual, lid_marker, marker_cells


def test_every_marker_pattern_decodes_to_its_own_id():
    detector = cv2.aruco.ArucoDetector(cv2.aruco.getPredefinedDictionary(cv2.aruco.DICT_4X4_50))
    for marker_id in range(50):
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
    spec = replace(kitchen_cfg.catalogue.get("salt"), marker_id=50)
    with pytest.raises(ConfigError, match="0-49"):
        lid_marker(spec)


def test_visual_is_one_body_with_body_cap_and_marker_cells(kitchen, kitchen_cfg):
    import pybullet as p

    for name in ("salt", "sugar"):
        spec = kitchen_cfg.catalogue.get(name)
        visual = create_object_visual(kitchen.bc, spec)
        body = kitchen.bc.createMultiBody(0.1, -1, visual)
        shapes = kitchen.bc.getVisualShapeData(body)
        assert shapes[0][2] == (p.GEOM_BOX if spec.shape == "box" else p.GEOM_CYLINDER)
        black = int(marker_cells(spec.marker_id).sum())
        cell_area = (lid_marker(spec).side / MARKER_CELLS) ** 2
        # PyBullet reports a box's full extents; the black boxes together cover exactly the black cells.
        ink = sum(s[3][0] * s[3][1] for s in shapes[2:])
        assert ink == pytest.approx(black * cell_area, rel=1e-6)
        assert all(s[1] == -1 for s in shapes)  # all on the base link: one rigid body
