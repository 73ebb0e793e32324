# SPDX-License-Identifier: MIT
# tests/python/test_pose.py: estimate_pose() on rendered markers against the
# pose they were drawn at, on corners projected through a distorting camera,
# and the calibration files.
import numpy as np
import pytest

import frappe
from conftest import K640, ROOT, SCENE, check_file_errors, marker_corners, render_scene, rotation

def rotation_angle(Ra, Rb):
    """The angle, degrees, of the rotation between two rotation matrices."""
    c = (np.trace(Ra.T @ Rb) - 1) / 2
    return np.degrees(np.arccos(np.clip(c, -1, 1)))


def rodrigues(rvec):
    """The rotation matrix of a rotation vector (independent of the module's own)."""
    angle = np.linalg.norm(rvec)
    x, y, z = rvec / angle
    k = np.array([[0, -z, y], [z, 0, -x], [-y, x, 0]])
    return np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * (k @ k)


# Markers 50 px wide (0.06 m at 0.72 m): face on off the pixel grid, rolled,
# tilted; the hardest cases for rotation the bar covers.
SMALL = [
    (5, (0, 0, 0), (0.013, 0.021, 0.72)),
    (6, (0, 0, 30), (-0.15, 0.05, 0.72)),
    (7, (10, 0, 0), (0.15, 0.1, 0.7)),
]


def blur_and_noise(image):
    """A camera's softness and sensor noise: a 5-tap blur, noise of sigma 3."""
    f = image.astype(float)
    f = (f + np.roll(f, 1, 0) + np.roll(f, -1, 0) + np.roll(f, 1, 1) + np.roll(f, -1, 1)) / 5
    noise = np.random.default_rng(1).normal(0, 3, f.shape)
    return np.clip(f + noise, 0, 255).astype(np.uint8)


@pytest.mark.parametrize("blurred", [False, True], ids=["sharp", "blurred"])
@pytest.mark.parametrize("scene_", [SCENE, SMALL], ids=["scene", "50px"])
def test_pose_of_rendered_markers(scene_, blurred):
    image, _ = render_scene(scene=scene_)
    if blurred:
        image = blur_and_noise(image)
    found = {m.id: m for m in frappe.Detector().detect(image)}
    assert sorted(found) == sorted(i for i, _, _ in scene_)
    for marker_id, angles, t in scene_:
        R = rotation(*angles)
        pose = frappe.estimate_pose(found[marker_id], 0.06, K640)
        assert pose is not None
        # The bar for markers of 50 px or more: 1 % of the
        # distance, half a degree (measured: 0.1 %, 0.4 degree at worst).
        assert np.linalg.norm(pose.tvec - t) < 0.01 * np.linalg.norm(t), (marker_id, pose.tvec, t)
        assert rotation_angle(pose.rotation_matrix, R) < 0.5, marker_id
        assert pose.error < 0.1 and pose.ambiguity > 10
        assert pose.tvec.dtype == np.float64 and pose.rvec.shape == (3,)
        # rotation_matrix is rvec's, transform both.
        np.testing.assert_allclose(rodrigues(pose.rvec), pose.rotation_matrix, atol=1e-9)
        np.testing.assert_allclose(pose.transform[:3, :3], pose.rotation_matrix)
        np.testing.assert_allclose(pose.transform[:3, 3], pose.tvec)
        assert pose.transform[3].tolist() == [0, 0, 0, 1]


def test_exact_corners_give_exact_pose_and_alternative():
    R, t = rotation(20, -30, 10), np.array([0.02, -0.01, 0.8])
    corners = marker_corners(K640, R, t, 0.1)
    pose = frappe.estimate_pose(corners, 0.1, K640)
    np.testing.assert_allclose(pose.tvec, t, atol=1e-5)
    assert rotation_angle(pose.rotation_matrix, R) < 0.01
    assert pose.error < 1e-3
    # cv2.aruco's (1, 4, 2) and a Camera work alike.
    same = frappe.estimate_pose(corners[None].astype(np.float32), 0.1, frappe.Camera(K640))
    np.testing.assert_allclose(same.tvec, pose.tvec, atol=1e-6)
    alt = pose.alternative
    assert alt is not None and alt.alternative is None
    assert alt.error > pose.error and pose.ambiguity == pytest.approx(alt.error / pose.error)
    # Scale: the same corners of a marker twice as large are twice as far.
    np.testing.assert_allclose(frappe.estimate_pose(corners, 0.2, K640).tvec, 2 * t, atol=2e-5)


def opencv_distort(K, dist, xy):
    """OpenCV's distortion model in numpy: normalised points to pixels."""
    k = np.zeros(8)
    k[:len(dist)] = dist
    x, y = xy[:, 0], xy[:, 1]
    r2 = x * x + y * y
    radial = (1 + k[0] * r2 + k[1] * r2**2 + k[4] * r2**3) / (1 + k[5] * r2 + k[6] * r2**2 + k[7] * r2**3)
    xd = x * radial + 2 * k[2] * x * y + k[3] * (r2 + 2 * x * x)
    yd = y * radial + k[2] * (r2 + 2 * y * y) + 2 * k[3] * x * y
    return np.stack([K[0, 0] * xd + K[0, 2], K[1, 1] * yd + K[1, 2]], axis=1)


@pytest.mark.parametrize("dist", [[-0.3, 0.12, 0.001, -0.002, -0.02],
                                  [0.1, -0.05, 0.0005, 0.001, 0.01, 0.05, -0.02, 0.005], [-0.2, 0.05, 0, 0]])
def test_distortion(dist):
    R, t, size = rotation(-15, 25, 60), np.array([0.15, 0.1, 0.6]), 0.08
    s = size / 2
    obj = np.array([[-s, s, 0], [s, s, 0], [s, -s, 0], [-s, -s, 0]])
    cam = obj @ R.T + t
    corners = opencv_distort(K640, dist, cam[:, :2] / cam[:, 2:])
    pose = frappe.estimate_pose(corners, size, K640, np.array(dist).reshape(1, -1))
    np.testing.assert_allclose(pose.tvec, t, atol=1e-4)
    assert rotation_angle(pose.rotation_matrix, R) < 0.02
    # Projecting back lands on the corners; undistorting gives the pinhole's.
    np.testing.assert_allclose(frappe.project_points(obj, pose, K640, dist), corners, atol=2e-3)
    pinhole = cam[:, :2] / cam[:, 2:] * [600, 600] + [319.5, 239.5]
    np.testing.assert_allclose(frappe.undistort_points(corners, K640, dist), pinhole, atol=2e-3)
    # Ignoring the distortion gives another pose.
    assert np.abs(frappe.estimate_pose(corners, size, K640).tvec - t).max() > 1e-3


def test_degenerate_and_bad_arguments():
    assert frappe.estimate_pose([[10, 10], [20, 20], [30, 30], [40, 40]], 0.1, K640) is None
    assert frappe.estimate_pose([[np.nan, 0], [1, 0], [1, 1], [0, 1]], 0.1, K640) is None
    square = [[300, 200], [340, 200], [340, 240], [300, 240]]
    with pytest.raises(ValueError, match="size|marker"):
        frappe.estimate_pose(square, 0.0, K640)
    with pytest.raises(ValueError, match="3 x 3"):
        frappe.estimate_pose(square, 0.1, np.eye(4))
    with pytest.raises(ValueError, match="distortion|coefficient"):
        frappe.estimate_pose(square, 0.1, K640, [0.1, 0.2, 0.3])
    with pytest.raises(ValueError, match="focal|fx"):
        frappe.estimate_pose(square, 0.1, [[0, 0, 320], [0, 600, 240], [0, 0, 1]])
    with pytest.raises(ValueError, match="corners must be 4"):
        frappe.estimate_pose([[1, 2, 3]], 0.1, K640)
    with pytest.raises(ValueError, match="dist_coeffs"):
        frappe.estimate_pose(square, 0.1, frappe.Camera(K640), [0, 0, 0, 0])


def test_read_calibration(tmp_path):
    ros = tmp_path / "ros.yaml"
    ros.write_text("""image_width: 640
image_height: 480
camera_name: test
camera_matrix:
  rows: 3
  cols: 3
  data: [600.0, 0.0, 319.5, 0.0, 601.0, 239.5, 0.0, 0.0, 1.0]
distortion_model: plumb_bob
distortion_coefficients:
  rows: 1
  cols: 5
  data: [-0.3, 0.12, 0.001, -0.002, -0.02]
""")
    cam = frappe.read_calibration(ros)
    assert (cam.width, cam.height, cam.fx, cam.fy, cam.cx, cam.cy) == (640, 480, 600.0, 601.0, 319.5, 239.5)
    assert cam.distortion.tolist() == [-0.3, 0.12, 0.001, -0.002, -0.02]
    np.testing.assert_array_equal(cam.matrix, [[600, 0, 319.5], [0, 601, 239.5], [0, 0, 1]])
    half = cam.scaled_to(320, 240)
    assert (half.width, half.fx, half.cx) == (320, 300.0, 159.5)
    corners = [[300, 200], [340, 202], [338, 240], [299, 238]]
    a = frappe.estimate_pose(corners, 0.05, cam)
    b = frappe.estimate_pose(corners, 0.05, cam.matrix, cam.distortion)
    np.testing.assert_array_equal(a.tvec, b.tvec)
    check_file_errors(frappe.read_calibration, tmp_path, "hello: world\n")


def test_sample_calibrations(tmp_path):
    """The sample video's camera (examples/data) in ROS and OpenCV YAML, and
    the same written as OpenCV XML, read alike."""
    data = ROOT / "examples" / "data"
    xml = tmp_path / "camera.xml"
    xml.write_text("""<?xml version="1.0"?>
<opencv_storage>
<image_width>640</image_width>
<image_height>480</image_height>
<camera_matrix type_id="opencv-matrix"><rows>3</rows><cols>3</cols><dt>d</dt>
  <data>700. 0. 319.5 0. 700. 239.5 0. 0. 1.</data></camera_matrix>
<distortion_coefficients type_id="opencv-matrix"><rows>5</rows><cols>1</cols><dt>d</dt>
  <data>0. 0. 0. 0. 0.</data></distortion_coefficients>
</opencv_storage>
""")
    K700 = [[700, 0, 319.5], [0, 700, 239.5], [0, 0, 1]]
    R, t = rotation(25, -15, 40), np.array([0.05, -0.03, 0.5])
    corners = marker_corners(K700, R, t, 0.05)
    for path in (data / "camera-700.yaml", str(data / "camera-700-opencv.yml"), xml):
        cam = frappe.read_calibration(path)
        assert (cam.width, cam.height) == (640, 480), path
        np.testing.assert_array_equal(cam.matrix, K700)
        assert cam.distortion.tolist() == [0.0] * 5
        pose = frappe.estimate_pose(corners, 0.05, cam)
        np.testing.assert_allclose(pose.tvec, t, atol=1e-5)
        assert rotation_angle(pose.rotation_matrix, R) < 0.01


def test_bundle_pose_of_a_rendered_board(tmp_path):
    """Issue 32: a 2 x 3 grid board drawn through a known pose; its pose
    from all six markers, from a bundle file or Bundle.grid()."""
    board = frappe.Bundle.grid(2, 3, 0.05, 0.01, first_id=10)
    assert len(board) == 6 and board.ids == list(range(10, 16))
    path = tmp_path / "board.yaml"
    path.write_text("board: grid\nrows: 2\ncols: 3\nsize: 0.05\ngap: 0.01\nfirst_id: 10\n")
    loaded = frappe.load_bundle(path)
    np.testing.assert_allclose(loaded.corners(12), board.corners(12))
    R, t = rotation(20, -15, 10), np.array([-0.08, 0.03, 0.6])
    image = np.full((480, 640), 140, np.uint8)
    for i in board.ids:
        corners = (K640 @ (R @ board.corners(i).T + t[:, None])).T
        frappe.draw_marker(image, "aruco_mip_36h12", i, corners[:, :2] / corners[:, 2:])
    markers = frappe.Detector().detect(image)
    bp = frappe.estimate_bundle_pose(loaded, markers, K640)
    assert bp is not None and bp.used == list(range(10, 16)) and bp.rejected == []
    assert np.linalg.norm(bp.pose.tvec - t) < 0.005 * np.linalg.norm(t)
    assert rotation_angle(bp.pose.rotation_matrix, R) < 0.5
    assert frappe.estimate_bundle_pose(loaded, [], K640) is None
    with pytest.raises(ValueError, match="board: 'hexagon'"):
        bad = tmp_path / "bad.yaml"
        bad.write_text("board: hexagon\n")
        frappe.load_bundle(bad)
    with pytest.raises(OSError):
        frappe.load_bundle(tmp_path / "missing.yaml")
