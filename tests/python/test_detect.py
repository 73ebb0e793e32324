# SPDX-License-Identifier: MIT
# tests/python/test_detect.py: Detector.detect() on rendered scenes whose
# corners are known, on every kind of strided array, and from two threads.
import threading

import numpy as np
import pytest

import frappe
from conftest import SCENE, render_scene


def by_id(markers):
    return {m.id: m for m in markers}


def test_rendered_scene_ids_and_corners(scene):
    image, truth = scene
    found = frappe.Detector("aruco_mip_36h12").detect(image)
    assert sorted(m.id for m in found) == sorted(truth)
    for m in found:
        assert m.corners.shape == (4, 2) and m.corners.dtype == np.float32
        err = np.abs(m.corners - truth[m.id]).max()
        assert err < 0.1, f"id {m.id}: corner error {err:.3f} px"
        assert m.hamming == 0
        assert 0.5 < m.margin <= 1.0
        np.testing.assert_allclose(m.center, truth[m.id].mean(axis=0), atol=0.5)


@pytest.mark.parametrize("name,ids", [("apriltag_36h11", [0, 5, 586]), ("4x4_50", [1, 20, 49]),
                                      ("DICT_6X6_250", [7, 100, 249])])
def test_other_dictionaries(name, ids):
    scene = [(i, (15 * k, -10 * k, 40 * k), (-0.12 + 0.12 * k, 0.0, 0.5)) for k, i in enumerate(ids)]
    image, truth = render_scene(frappe.get_dictionary(name), scene)
    found = frappe.Detector(name).detect(image)
    assert sorted(m.id for m in found) == sorted(ids)
    for m in found:
        assert np.abs(m.corners - truth[m.id]).max() < 0.5
    # The other family's detector sees none of them.
    assert frappe.Detector("aruco_mip_36h12").detect(image) == []


def test_detector_accepts_dictionary_object_and_aliases(scene):
    image, truth = scene
    d = frappe.get_dictionary("ARUCO_MIP_36h12")
    det = frappe.Detector(d)
    assert det.dictionary == d and det.dictionary.name == "aruco_mip_36h12"
    assert sorted(m.id for m in det.detect(image)) == sorted(truth)


def test_strided_inputs_match_contiguous(scene):
    image, _ = scene
    det = frappe.Detector()
    reference = [(m.id, m.corners.tolist()) for m in det.detect(image)]
    assert det.stats["input_copied"] is False

    def same(view, copied):
        got = [(m.id, m.corners.tolist()) for m in det.detect(view)]
        assert det.stats["input_copied"] is copied
        return got

    # Rows padded: a slice of columns of a wider array is read in place.
    wide = np.zeros((480, 700), np.uint8)
    wide[:, 30:670] = image
    assert same(wide[:, 30:670], False) == reference
    # Every other column of a twice-as-wide array: copied.
    doubled = np.repeat(image, 2, axis=1)
    assert same(doubled[:, ::2], True) == reference
    # Fortran order, and a transpose of a transpose.
    assert same(np.asfortranarray(image), True) == reference
    assert same(np.ascontiguousarray(image.T).T, True) == reference
    # Upside down twice: negative row strides.
    flipped = np.ascontiguousarray(image[::-1])
    assert same(flipped[::-1], True) == reference
    # A (h, w, 1) array and a read-only one.
    assert same(image[:, :, None], False) == reference
    ro = image.copy()
    ro.setflags(write=False)
    assert same(ro, False) == reference


def test_sliced_view_corners_are_relative_to_the_view(scene):
    image, truth = scene
    det = frappe.Detector()
    crop = image[100:, 200:]
    found = by_id(det.detect(crop))
    assert det.stats["input_copied"] is False
    for i, m in found.items():
        assert np.abs(m.corners + [200, 100] - truth[i]).max() < 0.5
    # What the crop holds whole is found (the rest is cut).
    inside = [i for i, c in truth.items() if (c[:, 0] > 205).all() and (c[:, 1] > 105).all()]
    assert inside and set(inside) <= set(found)


def test_no_copy_for_c_contiguous(scene):
    """The detector reads the caller's memory: a marker written into the
    array after a first detect() is seen by the next, without a new array."""
    image, _ = scene
    det = frappe.Detector()
    buf = np.full((200, 200), 255, np.uint8)
    assert det.detect(buf) == []
    buf[40:40 + 64, 50:50 + 64] = frappe.render_marker("aruco_mip_36h12", 9, cell_px=8, quiet_cells=0)
    assert [m.id for m in det.detect(buf)] == [9]
    assert det.stats["input_copied"] is False


def test_threads_two_detectors(scene):
    image, truth = scene
    flipped = np.ascontiguousarray(image[:, ::-1])  # mirrored: no marker
    results, errors = {}, []

    def work(name, img):
        try:
            det = frappe.Detector()
            results[name] = [sorted(m.id for m in det.detect(img)) for _ in range(20)]
        except Exception as e:  # pragma: no cover - reported below
            errors.append(e)

    threads = [threading.Thread(target=work, args=("a", image)), threading.Thread(target=work, args=("b", flipped))]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors
    assert results["a"] == [sorted(truth)] * 20
    assert results["b"] == [[]] * 20


def test_one_detector_shared_by_threads_takes_turns(scene):
    image, truth = scene
    det = frappe.Detector()
    out = []

    def work():
        out.extend(sorted(m.id for m in det.detect(image)) for _ in range(10))

    threads = [threading.Thread(target=work) for _ in range(3)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert out == [sorted(truth)] * 30


def test_config_round_trip_and_stats(scene):
    image, truth = scene
    det = frappe.Detector("apriltag_36h11", mode="ascale", edge_threshold=0.3, max_hamming=1, threads=2)
    cfg = det.config
    assert cfg["dictionary"] == "apriltag_36h11" and cfg["mode"] == "ascale"
    assert cfg["edge_threshold"] == pytest.approx(0.3) and cfg["threads"] == 2
    assert frappe.Detector(**cfg).config == cfg
    assert det.max_hamming == 1
    assert frappe.Detector("6x6_250").max_hamming == frappe.get_dictionary("6x6_250").default_max_hamming

    det = frappe.Detector()
    det.detect(image)
    s = det.stats
    assert set(s["times_ms"]) == {"adaptive_scale", "front_end", "trace", "refine", "warp", "decode", "total"}
    assert s["scale"] == 1.0 and s["candidates"] >= len(truth) and s["candidates_dropped"] == 0


def test_max_candidates_counts_dropped(scene):
    image, truth = scene
    det = frappe.Detector(max_candidates=1)
    det.detect(image)
    assert det.stats["candidates_dropped"] >= len(truth) - 1


def test_empty_and_tiny_images():
    det = frappe.Detector()
    with pytest.raises(ValueError, match="image size must be positive, got 0x0"):
        det.detect(np.zeros((0, 0), np.uint8))
    with pytest.raises(ValueError, match="image size must be positive, got 0x480"):
        det.detect(np.zeros((480, 0), np.uint8))
    assert det.detect(np.zeros((3, 5), np.uint8)) == []
    assert det.detect(np.zeros((1, 640), np.uint8)[:, ::2]) == []


def test_marker_object():
    m = frappe.Marker(7, [[0, 0], [10, 0], [10, 10], [0, 10]], hamming=1, margin=0.5)
    assert m.id == 7 and m.hamming == 1 and m.margin == 0.5
    assert m.center.tolist() == [5.0, 5.0]
    assert repr(m) == "frappe.Marker(id=7, corners=[[0.00, 0.00], [10.00, 0.00], [10.00, 10.00], [0.00, 10.00]], hamming=1, margin=0.500)"
    import pickle
    m2 = pickle.loads(pickle.dumps(m))
    assert (m2.id, m2.corners.tolist(), m2.hamming, m2.margin) == (m.id, m.corners.tolist(), m.hamming, m.margin)


def test_marker_has_the_librarys_fields(scene):
    # One list of a marker's fields (frappe/marker_record.h): Python's
    # Marker has each that is not the pose's (frappe.estimate_pose's).
    image, _ = scene
    m = frappe.Detector("aruco-mip-36h12").detect(image)[0]
    pose_fields = ("rvec", "tvec", "reprojection_error", "alternative_reprojection_error")
    assert frappe.MARKER_FIELDS[:5] == ("id", "dictionary", "corners", "hamming", "margin")
    for name in frappe.MARKER_FIELDS:
        assert name in pose_fields or hasattr(m, name), name
    assert m.dictionary == "aruco_mip_36h12"


def test_settings_are_the_keywords():
    # Every setting frappe.settings() lists is a keyword with its default,
    # and config gives each back.
    names = [s["name"] for s in frappe.settings()]
    assert names[:2] == ["dictionary", "mode"] and "weak_margin" in names
    cfg = frappe.Detector().config
    for s in frappe.settings():
        assert cfg[s["name"]] == s["default"], s["name"]
    kwargs = {s["name"]: s["default"] for s in frappe.settings() if s["name"] != "dictionary"}
    assert frappe.Detector(**kwargs).config == cfg
    with pytest.raises(TypeError, match="unexpected keyword argument 'edge-threshold'"):
        frappe.Detector(**{"edge-threshold": 0.3})


def test_track_mode_reports_tracked_markers_and_reads_less(scene):
    image, truth = scene
    det = frappe.Detector(mode="track", track_cover_frames=3)
    assert det.config["mode"] == "track" and det.config["track_cover_frames"] == 3
    first = det.detect(image)
    assert sorted(m.id for m in first) == sorted(truth)
    assert not any(m.tracked for m in first)
    assert det.stats["whole_frame"] and det.stats["bytes_read"] == image.size
    second = det.detect(image)
    assert sorted(m.id for m in second) == sorted(truth)
    assert all(m.tracked for m in second)
    for m in second:
        assert np.abs(m.corners - np.asarray(truth[m.id], np.float32)).mean() < 0.5
    s = det.stats
    # the frame once for the region map, the regions' edges less than it again
    assert not s["whole_frame"] and image.size < s["bytes_read"] < 2 * image.size
    det.reset()
    det.detect(image)
    assert det.stats["whole_frame"]
    with pytest.raises(ValueError, match="track_cover_frames"):
        frappe.Detector(mode="track", track_cover_frames=0)
