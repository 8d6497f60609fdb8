"""Perception: a simulated RGB-D camera, an ArUco marker detector with depth back-projection, and a tracker.

Typical use, once per decision::

    camera, detector, tracker = Camera(kitchen_cfg.camera), Detector(kitchen_cfg.catalogue), Tracker()
    frame = camera.capture(kitchen, rng)
    tracked = tracker.update(detector.detect(frame), frame.sim_time)
"""

from scone_bt.perception.camera import Camera
from scone_bt.perception.detector import UNTRACKED, Detector, DetectorOptions
from scone_bt.perception.observe import Observation, Observer
from scone_bt.perception.tracker import Track, Tracker
from scone_bt.perception.types import Detection, Frame

__all__ = [
    "Camera",
    "Detection",
    "Detector",
    "DetectorOptions",
    "Frame",
    "Observation",
    "Observer",
    "Track",
    "Tracker",
    "UNTRACKED",
]
