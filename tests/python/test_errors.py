# SPDX-License-Identifier: MIT
# tests/python/test_errors.py: bad arguments raise TypeError or ValueError
# saying what is wrong, never crash.
import os
import subprocess
import sys

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
    with pytest.raises(ValueError, match="mode must be normal, ascale or track, got 'fast'"):
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


def test_render_arguments_out_of_range():
    # Issue 34: quiet_cells=2**31-1 overflowed an int in draw_marker and a
    # negative one was clamped silently where render_marker refused it:
    # both refuse, with the library's words, whatever the int's size.
    image = np.zeros((64, 64), np.uint8)
    square = [[10, 10], [50, 10], [50, 50], [10, 50]]
    for q in (-1, 32769, 2**31 - 1, 2**31, 2**70, -2**70):
        with pytest.raises(ValueError, match=r"renderMarker: quiet_cells must be 0\.\.32768, got"):
            frappe.draw_marker(image, "4x4_50", 0, square, quiet_cells=q)
        with pytest.raises(ValueError, match=r"markerImage: quiet_cells must be 0\.\.32768, got"):
            frappe.render_marker("4x4_50", 0, quiet_cells=q)
    for s in (0, -3, 257, 2**40):
        with pytest.raises(ValueError, match=r"supersample must be 1\.\.256, got"):
            frappe.draw_marker(image, "4x4_50", 0, square, supersample=s)
    for level in (-1, 256, 2**64):
        with pytest.raises(ValueError, match="black must be 0..255, got %d$" % level):
            frappe.draw_marker(image, "4x4_50", 0, square, black=level)
        with pytest.raises(ValueError, match="white must be 0..255, got %d$" % level):
            frappe.draw_marker(image, "4x4_50", 0, square, white=level)
    for marker_id in (2**31, -2**40):
        with pytest.raises(ValueError, match="not in 4x4_50"):
            frappe.draw_marker(image, "4x4_50", marker_id, square)
        with pytest.raises(ValueError, match="not in 4x4_50"):
            frappe.render_marker("4x4_50", marker_id)
    assert not image.any(), "nothing drawn by a refused call"


def test_dictionary_name_that_is_not_text():
    # Issue 34: a str with a lone surrogate raised RuntimeError.
    with pytest.raises(ValueError, match=r"unknown dictionary '\\udcff': not valid text"):
        frappe.Detector("\udcff")
    with pytest.raises(ValueError, match="not valid text"):
        frappe.render_marker("4x4\udce9", 0)


def test_files_named_in_any_bytes_and_fifos(tmp_path):
    # Issue 34: a path that is not UTF-8 (bytes, or its os.fsdecode str)
    # raised RuntimeError; a FIFO is refused without waiting.
    name = os.path.join(os.fsencode(tmp_path), b"caf\xe9.txt")
    with open(name, "wb") as f:
        f.write(b"0x1234\n0xff00\n")
    for path in (name, os.fsdecode(name)):
        d = frappe.load_dictionary(path)
        assert d.name == "caf\u00e9"
    fifo = tmp_path / "fifo.yaml"
    os.mkfifo(fifo)
    with pytest.raises(OSError, match=r"fifo\.yaml: not a regular file \(a FIFO\)"):
        frappe.read_calibration(fifo)
    with pytest.raises(OSError, match=r"not a regular file \(a FIFO\)"):
        frappe.load_dictionary(fifo)


def test_exit_with_a_daemon_thread_detecting():
    # Issue 34: a daemon thread inside detect() when Python exited aborted
    # the interpreter (exit 134): it came back to a finalizing interpreter.
    code = (
        "import threading, time, numpy as np, frappe\n"
        "det = frappe.Detector()\n"
        "img = (np.random.default_rng(1).random((1080, 1920)) * 255).astype(np.uint8)\n"
        "started = threading.Event()\n"
        "def loop():\n"
        "    while True:\n"
        "        started.set()\n"
        "        det.detect(img)\n"
        "for _ in range(3):\n"
        "    threading.Thread(target=loop, daemon=True).start()\n"
        "started.wait()\n"
        "time.sleep(0.05)\n"
    )
    for attempt in range(4):
        r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
        assert r.returncode == 0 and r.stderr == "", "attempt %d: exit %d, %s" % (attempt, r.returncode, r.stderr)
