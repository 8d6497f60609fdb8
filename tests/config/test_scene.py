"""The kitchen file's scene and cameras: bad values are one line naming the file, the key and what is allowed."""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
import yaml

from scone_bt.config import load_kitchen
from scone_bt.errors import ConfigError
from scone_bt.resources import data_dir


def _kitchen(tmp_path: Path, edit: Callable[[dict[str, Any]], None]) -> Path:
    doc = yaml.safe_load((data_dir("perception") / "kitchen.yaml").read_text())
    edit(doc)
    path = tmp_path / "kitchen.yaml"
    path.write_text(yaml.safe_dump(doc))
    return path


def _refused(path: Path, *parts: str) -> str:
    with pytest.raises(ConfigError) as err:
        load_kitchen(path)
    msg = str(err.value)
    assert "\n" not in msg and str(path) in msg
    for part in parts:
        assert part in msg, msg
    return msg


def test_committed_kitchen_loads():
    kitchen = load_kitchen("kitchen")
    assert kitchen.scene.place_spots and kitchen.camera.width == 640


@pytest.mark.parametrize(
    ("key", "value", "shown"),
    [
        ("width", 100000, "16 to 4096"),
        ("height", 100000, "16 to 4096"),
        ("width", 0, "16 to 4096"),
        ("fov_deg", 0.0, "fov_deg"),
        ("fov_deg", 400.0, "fov_deg"),
        ("near", -1.0, "near"),
        ("far", 0.01, "larger than near"),
        ("noise_std", 1e9, "noise_std"),
        ("depth_noise_std", 1e9, "depth_noise_std"),
        ("near", math.nan, "finite"),
    ],
)
def test_camera_size_and_range_are_bounded(tmp_path: Path, key: str, value: Any, shown: str):
    path = _kitchen(tmp_path, lambda d: d["cameras"][1].update({key: value}))
    _refused(path, "cameras[1]", shown)


@pytest.mark.parametrize(
    ("edit", "parts"),
    [
        (lambda d: d.update(lights=1), ("unknown key 'lights'", "valid: scene, cameras")),
        (lambda d: d["scene"].update(walls=1), ("scene: unknown key 'walls'", "place_spots")),
        (lambda d: d["cameras"][0].update(zoom=2), ("cameras[0]: unknown key 'zoom'", "fov_deg")),
        (lambda d: d["scene"].update(floor_z=math.nan), ("scene.floor_z", "finite")),
        (lambda d: d["scene"]["table"].update(size=[0.5, -0.5, 0.6]), ("scene.table.size", "> 0")),
        (lambda d: d["scene"].update(place_spots=[]), ("scene.place_spots", "at least one")),
        (  # accepted before: the human put products down 5 m from the table
            lambda d: d["scene"].update(place_spots=[[0.37, -0.3], [5.0, 5.0]]),
            ("scene.place_spots[1]: [5, 5] lies off the table", "x in [0.14, 0.7]"),
        ),
        (
            lambda d: d["scene"]["shelves"][0]["tiers"][0].update(slots=[0.2, 0.3, 0.2]),
            ("tiers[0].slots[2]", "tiers[0].slots[0]", "same slot position"),
        ),
        (lambda d: d["scene"]["shelves"][0]["tiers"][0].update(top_z=-1.0), ("top_z", "floor_z")),
    ],
)
def test_scene_refuses_unknown_keys_and_bad_geometry(tmp_path: Path, edit: Callable, parts: tuple[str, ...]):
    _refused(_kitchen(tmp_path, edit), *parts)


def _unit0(d: dict[str, Any]) -> dict[str, Any]:
    return d["scene"]["shelves"][0]


@pytest.mark.parametrize(
    ("edit", "parts"),
    [
        (
            lambda d: _unit0(d).update(span=[0.14, 1e9]),
            ("scene.shelves[0].span: every value must be in [-10, 10] metres, got [0.14, 1000000000.0]",),
        ),
        (
            lambda d: _unit0(d)["tiers"][1].update(center=1e9),
            ("scene.shelves[0].tiers[1].center: must be in [-10, 10], got 1000000000.0",),
        ),
        (lambda d: _unit0(d)["tiers"][0].update(top_z=50.0), ("tiers[0].top_z: must be in [-10, 10]",)),
        (
            lambda d: _unit0(d)["tiers"][0].update(slots=[0.2, -1e6]),
            ("tiers[0].slots: every value must be in",),
        ),
        (
            lambda d: _unit0(d)["tiers"][2].update(slots=[0.2, 0.9]),
            ("scene.shelves[0].tiers[2].slots[1]: 0.9 lies outside the unit's span [0.14, 0.66]",),
        ),
        (lambda d: _unit0(d).update(tier_depth=1e9), ("scene.shelves[0].tier_depth: must be in (0, 10]",)),
        (lambda d: _unit0(d).update(tier_depth=0.0), ("scene.shelves[0].tier_depth: must be in (0, 10]",)),
    ],
)
def test_shelf_geometry_is_bounded(tmp_path: Path, edit: Callable, parts: tuple[str, ...]):
    _refused(_kitchen(tmp_path, edit), *parts)


def _looking_along_up(d: dict[str, Any]) -> None:
    camera = d["cameras"][1]
    camera["up"] = [t - p for t, p in zip(camera["target"], camera["position"], strict=True)]


@pytest.mark.parametrize(
    ("edit", "parts"),
    [
        (_looking_along_up, ("cameras[1].up: camera 'shelf_left': ", "is parallel to its viewing direction")),
        (
            lambda d: d["cameras"][1].update(up=[0.0, 0.0, 0.0]),
            ("cameras[1].up: camera 'shelf_left': [0.0, 0.0, 0.0] is parallel",),
        ),
        (
            lambda d: d["cameras"][1].update(target=d["cameras"][1]["position"]),
            ("cameras[1].target: camera 'shelf_left' looks at its own position",),
        ),
        (lambda d: d["cameras"][1].update(fov_deg=175.0), ("cameras[1].fov_deg: must be in [1, 170]",)),
    ],
)
def test_a_camera_that_cannot_render_is_refused_at_load(
    tmp_path: Path, edit: Callable, parts: tuple[str, ...]
):
    _refused(_kitchen(tmp_path, edit), *parts)
