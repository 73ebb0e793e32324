# SPDX-License-Identifier: MIT
# tests/python/test_errors.py: bad arguments raise TypeError or ValueError
# saying what is wrong, never crash.
import numpy as np
import pytest

import frappe


@pytest.fixture(scope="module")
def det():
    return frappe.Detector()


def test_image_dtype(det):
    with pytest.raises(TypeError, match="uint8.*float64"):
        det.detect(np.zeros((100, 100)))
    with pytest.raises(TypeError, match="uint8.*uint16"):
        det.detect(np.zeros((100, 100), np.uint16))


def test_image_shape(det):
    with pytest.raises(ValueError, match="3 channels.*grey.*cvtColor"):
        det.detect(np.zeros((100, 100, 3), np.uint8))
    with pytest.raises(ValueError, match="2-D.*1-D"):
        det.detect(np.zeros(100, np.uint8))
    with pytest.raises(ValueError, match="2-D.*4-D"):
        det.detect(np.zeros((2, 2, 2, 2), np.uint8))


def test_image_type(det):
    with pytest.raises(TypeError, match="numpy array.*NoneType"):
        det.detect(None)
    with pytest.raises(TypeError, match="uint8"):
        det.detect([[1, 2], [3, 4]])


def test_image_too_large():
    det = frappe.Detector(max_pixels=10000)
    with pytest.raises(ValueError, match="max_pixels"):
        det.detect(np.zeros((101, 100), np.uint8))
    # A huge broadcast view is refused before any copy.
    huge = np.broadcast_to(np.uint8(0), (30000, 30000))
    with pytest.raises(ValueError, match="max_pixels"):
        frappe.Detector().detect(huge)


def test_config_values():
    with pytest.raises(ValueError, match="unknown dictionary 'nope'.*aruco_mip_36h12"):
        frappe.Detector("nope")
    with pytest.raises(ValueError, match="mode must be 'normal' or 'ascale'"):
        frappe.Detector(mode="fast")
    with pytest.raises(ValueError, match="edge_threshold"):
        frappe.Detector(edge_threshold=-1)
    with pytest.raises(ValueError, match="max_candidates"):
        frappe.Detector(max_candidates=0)
    with pytest.raises(ValueError, match="threads"):
        frappe.Detector(threads=-3)
    with pytest.raises(TypeError):
        frappe.Detector(edge_threshold="high")
    with pytest.raises(TypeError):
        frappe.Detector(no_such_parameter=1)
    with pytest.raises(TypeError, match="dictionary must be a name"):
        frappe.Detector(36)


def test_render_arguments():
    with pytest.raises(ValueError, match="id"):
        frappe.render_marker("4x4_50", 50)
    with pytest.raises(ValueError, match="cell_px"):
        frappe.render_marker("4x4_50", 0, cell_px=0)
    with pytest.raises(ValueError, match="unknown dictionary"):
        frappe.render_marker("4x4_5", 0)
    image = np.zeros((100, 100), np.uint8)
    square = [[10, 10], [50, 10], [50, 50], [10, 50]]
    with pytest.raises(ValueError, match="corners must be 4"):
        frappe.draw_marker(image, "4x4_50", 0, [[1, 2], [3, 4]])
    with pytest.raises(ValueError):  # collinear
        frappe.draw_marker(image, "4x4_50", 0, [[0, 0], [10, 0], [20, 0], [30, 0]])
    with pytest.raises(ValueError, match="read-only"):
        ro = image.copy()
        ro.setflags(write=False)
        frappe.draw_marker(ro, "4x4_50", 0, square)
    with pytest.raises(ValueError, match="contiguous"):
        frappe.draw_marker(np.zeros((100, 200), np.uint8)[:, ::2], "4x4_50", 0, square)
    with pytest.raises(TypeError, match="uint8"):
        frappe.draw_marker(np.zeros((100, 100)), "4x4_50", 0, square)
