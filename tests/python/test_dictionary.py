# SPDX-License-Identifier: MIT
# tests/python/test_dictionary.py: the dictionaries, render_marker's pixels
# against the codes, and dictionaries loaded from files.
import numpy as np
import pytest

import frappe
from conftest import ROOT, check_file_errors, render_scene


def test_names_and_lookup():
    names = frappe.dictionaries()
    assert len(names) == 27
    assert {"aruco_mip_36h12", "apriltag_36h11", "6x6_250", "4x4_50", "apriltag_16h5"} <= set(names)
    # AprilTag 3's layout families (issue 32), by their own names too
    assert frappe.get_dictionary("tagStandard41h12").name == "apriltag_standard41h12"
    assert frappe.get_dictionary("apriltag_circle49h12").size == 65535
    d = frappe.get_dictionary("DICT_APRILTAG_36h11")
    assert (d.name, d.bits, d.size, len(d), d.min_hamming, d.builtin) == ("apriltag_36h11", 6, 587, 587, 11, True)
    assert frappe.get_dictionary("tag36h11") == d
    assert d.codes.dtype == np.uint64 and d.codes.shape == (587,)
    assert repr(d) == "frappe.Dictionary('apriltag_36h11', bits=6, size=587, min_hamming=11)"
    with pytest.raises(ValueError, match="unknown dictionary 'tag99h1'"):
        frappe.get_dictionary("tag99h1")


@pytest.mark.parametrize("name,marker_id", [("aruco_mip_36h12", 17), ("4x4_50", 3), ("apriltag_36h11", 500)])
def test_render_marker_pixels_are_the_code(name, marker_id):
    d = frappe.get_dictionary(name)
    cell, quiet = 7, 2
    img = frappe.render_marker(d, marker_id, cell_px=cell, quiet_cells=quiet)
    n = d.bits
    assert img.shape == ((n + 2 + 2 * quiet) * cell,) * 2 and img.dtype == np.uint8
    cells = img[::cell, ::cell]
    assert (img == np.repeat(np.repeat(cells, cell, 0), cell, 1)).all()
    assert (cells[:quiet] == 255).all() and (cells[-quiet:] == 255).all()
    inner = cells[quiet:-quiet, quiet:-quiet]
    assert (inner[0] == 0).all() and (inner[-1] == 0).all() and (inner[:, 0] == 0).all() and (inner[:, -1] == 0).all()
    code = int(d.codes[marker_id])
    bits = [(code >> (n * n - 1 - i)) & 1 for i in range(n * n)]
    assert ((inner[1:-1, 1:-1] == 255).astype(int).ravel().tolist()) == bits


def test_render_and_detect_every_family():
    for name in frappe.dictionaries():
        d = frappe.get_dictionary(name)
        marker_id = d.size - 1
        img = frappe.render_marker(d, marker_id, cell_px=10, quiet_cells=1)
        canvas = np.full((img.shape[0] + 40, img.shape[1] + 40), 255, np.uint8)
        canvas[20:-20, 20:-20] = img
        found = frappe.Detector(d).detect(canvas)
        assert [m.id for m in found] == [marker_id], name


def test_load_dictionary_round_trip(tmp_path):
    base = frappe.get_dictionary("4x4_50")
    # Five of 4x4_50's codes in frappe's text format, and in OpenCV's YAML.
    codes = [int(c) for c in base.codes[[4, 9, 16, 25, 36]]]
    text = tmp_path / "mine.txt"
    text.write_text("# marker_side_bits: 4\n" + "".join(f"0x{c:04x}\n" for c in codes))
    yml = tmp_path / "cv.yml"
    yml.write_text("%YAML:1.0\n---\nnmarkers: 5\nmarkersize: 4\nmaxCorrectionBits: 1\n" +
                   "".join(f'marker_{i}: "{c:016b}"\n' for i, c in enumerate(codes)))
    for path in (text, str(yml)):
        d = frappe.load_dictionary(path)
        assert (d.bits, d.size, d.builtin) == (4, 5, False)
        assert d.codes.tolist() == codes
        assert d.min_hamming >= base.min_hamming
        img = frappe.render_marker(d, 3, cell_px=10)
        canvas = np.full((img.shape[0] + 40,) * 2, 255, np.uint8)
        canvas[20:-20, 20:-20] = img
        det = frappe.Detector(d)
        assert det.dictionary == d and det.config["dictionary"] == d
        assert [m.id for m in det.detect(canvas)] == [3]
        # The built-in family finds it under its own id.
        assert [m.id for m in frappe.Detector("4x4_50").detect(canvas)] == [25]
    assert frappe.load_dictionary(text).name == "mine"
    check_file_errors(frappe.load_dictionary, tmp_path, "0x1\n0xzz\n")


def test_load_built_in_file():
    """A built-in family's source file loads as the same codes, and a
    detector with it finds what the built-in one does."""
    path = ROOT / "frappe-core" / "dictionaries" / "4x4_50.txt"
    loaded, base = frappe.load_dictionary(path), frappe.get_dictionary("4x4_50")
    assert (loaded.name, loaded.bits, loaded.size, loaded.builtin) == ("4x4_50", 4, 50, False)
    assert loaded.codes.tolist() == base.codes.tolist()
    assert loaded.min_hamming == base.min_hamming == 4
    assert loaded != base
    image, truth = render_scene(loaded, [(i, (10 * k, -15 * k, 30 * k), (-0.15 + 0.1 * k, 0.0, 0.5))
                                         for k, i in enumerate((0, 17, 33, 49))])
    found = frappe.Detector(loaded).detect(image)
    assert sorted(m.id for m in found) == [0, 17, 33, 49]
    for m in found:
        np.testing.assert_allclose(m.corners, truth[m.id], atol=0.1)
    assert [m.id for m in found] == [m.id for m in frappe.Detector(base).detect(image)]
