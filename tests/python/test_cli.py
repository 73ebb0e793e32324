# SPDX-License-Identifier: MIT
# tests/python/test_cli.py: the module finds what frappe-detect finds in
# the same pixels: the same ids, corners within the 0.001 px of its output.
import json
import subprocess

import numpy as np
import pytest

import frappe
from conftest import EXAMPLES, SHARED, frappe_detect, read_grey_png, render_scene


def cli_markers(path, dictionary):
    out = subprocess.run([frappe_detect(), "--json", "-d", dictionary, str(path)],
                         check=True, capture_output=True, text=True).stdout
    return {m["id"]: np.array(m["corners"]) for m in json.loads(out)["markers"]}


def compare(image, path, dictionary):
    cli = cli_markers(path, dictionary)
    found = frappe.Detector(dictionary).detect(image)
    assert sorted(m.id for m in found) == sorted(cli), path
    for m in found:
        # frappe-detect prints 3 decimals.
        assert np.abs(m.corners - cli[m.id]).max() <= 0.0006, (path, m.id)
    return len(found)


@pytest.mark.parametrize("name,dictionary", [("markers-36h12.png", "aruco_mip_36h12"),
                                             ("markers-apriltag36h11.png", "apriltag_36h11")])
def test_example_images(name, dictionary):
    assert compare(read_grey_png(EXAMPLES / name), EXAMPLES / name, dictionary) >= 5


def test_rendered_scene_as_pgm(tmp_path):
    image, truth = render_scene()
    path = tmp_path / "scene.pgm"
    path.write_bytes(b"P5\n%d %d\n255\n" % (image.shape[1], image.shape[0]) + image.tobytes())
    assert compare(image, path, "aruco_mip_36h12") == len(truth)


@pytest.mark.parametrize("subset,dictionary", [("images", "aruco_mip_36h12"), ("apriltag36h11", "apriltag_36h11"),
                                               ("blur", "aruco_mip_36h12"), ("4x4_50", "4x4_50")])
def test_shared_synthetic_images(subset, dictionary):
    folder = SHARED / "data" / "synth" / subset
    if not folder.is_dir():
        pytest.skip(f"{folder} absent")
    total = 0
    for path in sorted(folder.glob("*.png"))[:2]:
        total += compare(read_grey_png(path), path, dictionary)
    assert total > 0
