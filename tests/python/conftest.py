# SPDX-License-Identifier: MIT
# tests/python/conftest.py: what the Python tests share: scenes rendered
# with known corners, a reader for the grey PNGs of examples/images and the
# shared data, and where frappe-detect and the data are.
import os
import struct
import zlib
from pathlib import Path

import numpy as np
import pytest

import frappe

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples" / "images"
SHARED = ROOT.parent / "shared"


def frappe_detect():
    """The frappe-detect the build made, or skip."""
    path = os.environ.get("FRAPPE_DETECT")
    if not path or not os.access(path, os.X_OK):
        pytest.skip("frappe-detect not built (FRAPPE_DETECT unset)")
    return path


def read_grey_png(path):
    """An 8-bit grey, non-interlaced PNG as a (h, w) uint8 array (what
    frappe-detect reads the same file as)."""
    data = Path(path).read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", f"{path}: not a PNG"
    pos, idat, header = 8, b"", None
    while pos < len(data):
        (length,) = struct.unpack(">I", data[pos:pos + 4])
        kind, body = data[pos + 4:pos + 8], data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    w, h, depth, colour, _, _, interlace = header
    if (depth, colour, interlace) != (8, 0, 0):
        pytest.skip(f"{path}: not an 8-bit grey non-interlaced PNG")
    raw = zlib.decompress(idat)
    out = np.empty((h, w), np.uint8)
    prev = bytes(w)
    for y in range(h):
        kind, line = raw[y * (w + 1)], raw[y * (w + 1) + 1:(y + 1) * (w + 1)]
        if kind == 0:
            row = line
        elif kind == 2:  # Up
            row = ((np.frombuffer(line, np.uint8) + np.frombuffer(prev, np.uint8)) & 255).tobytes()
        elif kind == 1:  # Sub: a running sum
            row = (np.cumsum(np.frombuffer(line, np.uint8), dtype=np.uint64) & 255).astype(np.uint8).tobytes()
        else:  # Average, Paeth: pixel by pixel
            r = bytearray(w)
            a = c = 0
            for x in range(w):
                b = prev[x]
                if kind == 3:
                    p = (a + b) >> 1
                else:
                    pa, pb, pc = abs(b - c), abs(a - c), abs(a + b - 2 * c)
                    p = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
                a = r[x] = (line[x] + p) & 255
                c = b
            row = bytes(r)
        out[y] = np.frombuffer(row, np.uint8)
        prev = row
    return out


def marker_corners(K, R, t, side):
    """The image corners (top-left, top-right, bottom-right, bottom-left) of a
    square of `side` centred at t, rotated by R, seen by the pinhole K: OpenCV
    aruco's marker frame (x right, y up)."""
    s = side / 2
    obj = np.array([[-s, s, 0], [s, s, 0], [s, -s, 0], [-s, -s, 0]], float)
    cam = obj @ np.asarray(R, float).T + np.asarray(t, float)
    uv = cam @ np.asarray(K, float).T
    return uv[:, :2] / uv[:, 2:]


def rotation(rx=0.0, ry=0.0, rz=0.0):
    """Rotation about x, then y, then z (degrees), in the camera frame, of a
    marker that faces the camera (its z towards the viewer)."""
    a, b, c = np.radians([rx, ry, rz])
    Rx = np.array([[1, 0, 0], [0, np.cos(a), -np.sin(a)], [0, np.sin(a), np.cos(a)]])
    Ry = np.array([[np.cos(b), 0, np.sin(b)], [0, 1, 0], [-np.sin(b), 0, np.cos(b)]])
    Rz = np.array([[np.cos(c), -np.sin(c), 0], [np.sin(c), np.cos(c), 0], [0, 0, 1]])
    # Facing the camera: the marker's y up is the camera's -y, its z is -z.
    face = np.diag([1.0, -1.0, -1.0])
    return Rz @ Ry @ Rx @ face


K640 = np.array([[600.0, 0, 319.5], [0, 600.0, 239.5], [0, 0, 1]])

# (id, rotation degrees (x, y, z), position metres) of 0.06 m markers in a
# 640 x 480 view: tilted, rolled, near and far.
SCENE = [
    (3, (0, 0, 0), (-0.12, -0.08, 0.5)),
    (17, (30, 0, 15), (0.05, -0.09, 0.55)),
    (200, (0, -40, -30), (0.14, -0.05, 0.6)),
    (101, (-25, 20, 100), (-0.1, 0.08, 0.45)),
    (42, (10, 35, 200), (0.12, 0.1, 0.7)),
]


def render_scene(dictionary="aruco_mip_36h12", scene=SCENE, shape=(480, 640), background=150):
    """A grey image with the scene's markers drawn, and their true corners by id."""
    image = np.full(shape, background, np.uint8)
    # A gradient so that no row of the image is like another.
    image += (np.arange(shape[1]) // 16).astype(np.uint8)[None, :]
    truth = {}
    for marker_id, angles, t in scene:
        corners = marker_corners(K640, rotation(*angles), t, 0.06)
        frappe.draw_marker(image, dictionary, marker_id, corners)
        truth[marker_id] = corners
    return image, truth


def check_file_errors(load, tmp_path, bad_text):
    """`load` raises OSError naming a missing file, ValueError naming a file
    of `bad_text`."""
    with pytest.raises(OSError, match="missing.txt"):
        load(tmp_path / "missing.txt")
    bad = tmp_path / "bad.txt"
    bad.write_text(bad_text)
    with pytest.raises(ValueError, match="bad.txt"):
        load(bad)


@pytest.fixture(scope="session")
def scene():
    return render_scene()
