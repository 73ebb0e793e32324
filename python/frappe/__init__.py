# SPDX-License-Identifier: MIT
"""Frappe: fast detection of square fiducial markers (ArUco, AprilTag).

    import cv2, frappe
    grey = cv2.imread("markers.png", cv2.IMREAD_GRAYSCALE)
    detector = frappe.Detector("aruco_mip_36h12")
    for marker in detector.detect(grey):
        print(marker.id, marker.corners)          # corners: (4, 2) float32
        pose = frappe.estimate_pose(marker, 0.05, K, dist)  # 5 cm markers
        print(pose.tvec, pose.rotation_matrix)

The host's side of a robot's marker stream is `frappe.stream` (pure Python:
it imports without the compiled detector). See docs/python.md for the whole
API and how it maps to cv2.aruco and pupil-apriltags.
"""

try:
    from ._frappe import *  # noqa: F401,F403
    from ._frappe import __version__  # noqa: F401
    from . import _frappe

    __all__ = [name for name in dir(_frappe) if not name.startswith("_")]
except ImportError as _error:
    # Without the extension (or numpy) the pure-Python modules (frappe.stream)
    # still import; the detector's names say why they are missing.
    _why = f"{_error}"

    def __getattr__(name):  # an AttributeError, so that `from frappe import stream` goes on to the module
        if name.startswith("__"):
            raise AttributeError(name)
        raise AttributeError(f"frappe.{name} needs the compiled detector frappe._frappe, which did not "
                          f"import: {_why}")
