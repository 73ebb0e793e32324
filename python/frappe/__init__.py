# SPDX-License-Identifier: MIT
"""Frappe: fast detection of square fiducial markers (ArUco, AprilTag).

    import cv2, frappe
    grey = cv2.imread("markers.png", cv2.IMREAD_GRAYSCALE)
    detector = frappe.Detector("aruco_mip_36h12")
    for marker in detector.detect(grey):
        print(marker.id, marker.corners)          # corners: (4, 2) float32
        pose = frappe.estimate_pose(marker, 0.05, K, dist)  # 5 cm markers
        print(pose.tvec, pose.rotation_matrix)

See docs/python.md for the whole API and how it maps to cv2.aruco and
pupil-apriltags.
"""

from ._frappe import *  # noqa: F401,F403
from ._frappe import __version__  # noqa: F401
from . import _frappe

__all__ = [name for name in dir(_frappe) if not name.startswith("_")]
