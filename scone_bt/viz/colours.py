"""The recording's colours (RGBA, 0-255), in one place so that each drawer's look is chosen alike."""

from __future__ import annotations

from collections.abc import Sequence

__all__ = [
    "GATE_COLOURS",
    "PALETTE",
    "SCENE_COLOURS",
    "SHELF_COLOUR",
    "STATUS_COLOURS",
    "rgba255",
]

STATUS_COLOURS = {
    "SUCCESS": (46, 160, 67, 255),
    "FAILURE": (218, 54, 51, 255),
    "RUNNING": (230, 165, 20, 255),
    "INVALID": (140, 140, 140, 255),
}
"""A behaviour's status → its colour in the tree view."""
GATE_COLOURS = {"act": (46, 160, 67, 255), "ask": (230, 120, 20, 255), "idle": (140, 140, 140, 255)}
"""The gate's decision kind → its colour on the timeline."""
SCENE_COLOURS = {"pedestal": (77, 77, 77, 255), "table": (140, 102, 64, 255), "floor": (225, 225, 225, 255)}
"""A static box of the kitchen → its colour (other boxes are shelving)."""
SHELF_COLOUR = (191, 184, 166, 255)
PALETTE = [
    (31, 119, 180),
    (255, 127, 14),
    (44, 160, 44),
    (214, 39, 40),
    (148, 103, 189),
    (140, 86, 75),
    (227, 119, 194),
    (23, 190, 207),
]
"""Detections are coloured by track id, cycling through these (RGB)."""


def rgba255(rgba: Sequence[float]) -> tuple[int, int, int, int]:
    """An RGBA colour in 0-1 (clipped) as 0-255 integers."""
    r, g, b, a = (int(round(255 * max(0.0, min(1.0, float(c))))) for c in rgba)
    return r, g, b, a
