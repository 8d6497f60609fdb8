"""Perceive: one RGB-D capture → tracked detections."""

from __future__ import annotations

import py_trees

from scone_bt.behaviours.base import Keys, StageBehaviour

__all__ = ["Perceive"]


class Perceive(StageBehaviour):
    WRITES = (Keys.FRAME, Keys.DETECTIONS)

    def setup(self, **kwargs: object) -> None:
        from scone_bt.perception import Camera, Detector, Tracker

        cfg = self.services.kitchen_config
        self.camera = Camera(cfg.camera)
        self.detector = Detector(cfg.catalogue)
        self.tracker = Tracker()

    def update(self) -> py_trees.common.Status:
        kitchen = self.services.kitchen
        frame = self.camera.capture(kitchen, self.services.rng)
        detections = self.tracker.update(self.detector.detect(frame), frame.sim_time)
        self.write(Keys.FRAME, frame)
        self.write(Keys.DETECTIONS, detections)
        self.feedback_message = f"{len(detections)} objects detected"
        return py_trees.common.Status.SUCCESS
