"""Perception: a pinhole RGB-D camera, an ArUco marker detector with depth back-projection, and a tracker.

A camera's images come from an `ImageSource` (the simulated kitchen renders them; a real robot's backend streams
them). Typical use, once per decision::

    camera, detector, tracker = Camera(kitchen_cfg.camera), Detector(kitchen_cfg.catalogue), Tracker()
    frame = camera.capture(kitchen, rng)                  # the kitchen is the camera's ImageSource
    tracked = tracker.update(detector.detect(frame), frame.sim_time)
"""

from scone_bt.perception.camera import Camera
from scone_bt.perception.detector import UNTRACKED, Detector, DetectorOptions
from scone_bt.perception.images import CameraImage, ImageSource
from scone_bt.perception.observe import Observation, Observer
from scone_bt.perception.tracker import Track, Tracker
from scone_bt.perception.types import Detection, Frame

__all__ = [
    "Camera",
    "CameraImage",
    "Detection",
    "Detector",
    "DetectorOptions",
    "Frame",
    "ImageSource",
    "Observation",
    "Observer",
    "Track",
    "Tracker",
    "UNTRACKED",
]
