#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""A Python GStreamer application reads frappedetect's markers through the
GstFrappe-1.0 typelib: exact ids, dictionary and Hamming distance of the
sample image, corners equal to the element's own bus message and within
0.1 px of the rendered truth, the pose consistent with its reprojection
error, and no markers on a frame without any; a board's bundle pose
(GstFrappeBundlePose) against the pose the board was rendered at and the
element's message.

Usage: test_meta_gi.py SAMPLES_DIR HAVE_TYPELIB(0|1) [FRAPPE_RENDER]. Exit 77
when gi or Gst cannot be imported, or the typelib was not built."""
import json
import math
import os
import subprocess
import sys
import tempfile

SKIP = 77
failures = []


def check(cond, what):
    print(('ok   ' if cond else 'FAIL ') + what)
    if not cond:
        failures.append(what)


def run(Gst, samples, props, frames=2):
    """Runs the sample image through frappedetect; returns the buffers and
    the `frappedetect` messages' marker lists, per frame."""
    png = os.path.join(samples, 'markers-36h12.png')
    pipeline = Gst.parse_launch(
        f'filesrc location="{png}" ! pngdec ! videoconvert ! video/x-raw,format=GRAY8 ! '
        f'imagefreeze num-buffers={frames} ! frappedetect {props} ! appsink name=sink sync=false')
    return pull(Gst, pipeline, frames)


def pull(Gst, pipeline, frames):
    sink = pipeline.get_by_name('sink')
    bus = pipeline.get_bus()
    pipeline.set_state(Gst.State.PLAYING)
    buffers = []
    for _ in range(frames):
        sample = sink.emit('try-pull-sample', 10 * Gst.SECOND)
        if sample is None:
            break
        buffers.append(sample.get_buffer())
    messages = []
    while True:
        msg = bus.pop_filtered(Gst.MessageType.ELEMENT | Gst.MessageType.ERROR)
        if msg is None:
            break
        if msg.type == Gst.MessageType.ERROR:
            err, dbg = msg.parse_error()
            print(f'pipeline error: {err.message} ({dbg})')
            continue
        s = msg.get_structure()
        if s.get_name() == 'frappedetect':
            messages.append(s.get_value('markers'))
    pipeline.set_state(Gst.State.NULL)
    return buffers, messages


def rodrigues(r):
    """The rotation matrix of a Rodrigues vector (numpy-free)."""
    theta = math.sqrt(sum(v * v for v in r))
    if theta < 1e-12:
        return [[1, 0, 0], [0, 1, 0], [0, 0, 1]]
    kx, ky, kz = (v / theta for v in r)
    c, s, t = math.cos(theta), math.sin(theta), 1 - math.cos(theta)
    return [[c + kx * kx * t, kx * ky * t - kz * s, kx * kz * t + ky * s],
            [ky * kx * t + kz * s, c + ky * ky * t, ky * kz * t - kx * s],
            [kz * kx * t - ky * s, kz * ky * t + kx * s, c + kz * kz * t]]


def reprojection_rms(marker, side, fx, fy, cx, cy):
    """RMS pixel distance between the marker's corners and its model corners
    posed by rvec/tvec (marker frame: x right, y up, corner 0 top-left)."""
    R = rodrigues(marker.get_rvec())
    t = marker.get_tvec()
    h = side / 2
    model = [(-h, h), (h, h), (h, -h), (-h, -h)]
    total = 0.0
    for i, (X, Y) in enumerate(model):
        p = [R[k][0] * X + R[k][1] * Y + t[k] for k in range(3)]
        u, v = fx * p[0] / p[2] + cx, fy * p[1] / p[2] + cy
        x, y = marker.get_corner(i)
        total += (u - x) ** 2 + (v - y) ** 2
    return math.sqrt(total / 4)


def check_bundle_pose(Gst, GstFrappe, render):
    """A 2x3 board rendered face on (64 px markers, 16 px apart, 16 px of
    margin) by frappe-render, which also writes its bundle file; through a
    pinhole camera the board is at z = f 0.04 m / 64 px, the bundle frame's
    origin (the board's bottom-left corner, y up) where that corner's pixel
    edge projects."""
    with tempfile.TemporaryDirectory() as tmp:
        png = os.path.join(tmp, 'board.png')
        subprocess.run([render, '--board', '2x3', '--dictionary', 'aruco_mip_36h12', '--cell', '8', png],
                       check=True, stdout=subprocess.DEVNULL)
        f, cx, cy = 600.0, 128.0, 88.0
        pipeline = Gst.parse_launch(
            f'filesrc location="{png}" ! pngdec ! videoconvert ! video/x-raw,format=GRAY8 ! '
            f'imagefreeze num-buffers=1 ! frappedetect bundle-file="{png[:-4]}.yaml" '
            f'camera-matrix="<{f}, 0.0, {cx}, 0.0, {f}, {cy}, 0.0, 0.0, 1.0>" ! appsink name=sink sync=false')
        sink, bus = pipeline.get_by_name('sink'), pipeline.get_bus()
        pipeline.set_state(Gst.State.PLAYING)
        sample = sink.emit('try-pull-sample', 10 * Gst.SECOND)
        msg = bus.timed_pop_filtered(10 * Gst.SECOND, Gst.MessageType.ELEMENT)
        pipeline.set_state(Gst.State.NULL)
    check(sample is not None and msg is not None, 'bundle: one frame, one message')
    if sample is None or msg is None:
        return
    pose = GstFrappe.buffer_get_bundle_pose(sample.get_buffer())
    sample = None  # the pose is a copy: it outlives the buffer
    check(pose is not None, 'bundle: buffer_get_bundle_pose gives the board\'s pose')
    if pose is None:
        return
    z = f * 0.04 / 64
    want_t = [(15.5 - cx) * z / f, (159.5 - cy) * z / f, z]
    t, R = list(pose.get_tvec()), rodrigues(pose.get_rvec())
    check(max(abs(a - b) for a, b in zip(t, want_t)) < 1e-4, f'bundle: tvec {t} is the rendered {want_t}')
    flip = [[1, 0, 0], [0, -1, 0], [0, 0, -1]]  # board y up, z out; camera y down, z forward
    check(max(abs(R[i][j] - flip[i][j]) for i in range(3) for j in range(3)) < 1e-4,
          'bundle: face on (rotation of pi about x)')
    check(pose.name == 'grid' and list(pose.get_used()) == [0, 1, 2, 3, 4, 5] and pose.n_used == 6 and
          list(pose.get_rejected()) == [] and pose.n_rejected == 0,
          f'bundle: name {pose.name!r}, used {list(pose.get_used())}, none rejected')
    check(pose.reprojection_error < 0.05, f'bundle: reprojection error {pose.reprojection_error:.4f} px')
    st = msg.get_structure()  # held: the bundle structure is borrowed from it
    s = st.get_value('bundle')
    check(list(s.get_value('rvec')) == list(pose.get_rvec()) and list(s.get_value('tvec')) == t and
          s.get_value('reprojection-error') == pose.reprojection_error and
          list(s.get_value('used')) == list(pose.get_used()), 'bundle: the message\'s values exactly')
    copy = pose.copy()
    pose = None
    check(list(copy.get_used()) == [0, 1, 2, 3, 4, 5] and list(copy.get_tvec()) == t, 'bundle: a copy holds its ids')

    # A meta added from Python reads back; a buffer without one has none.
    buf = Gst.Buffer.new()
    check(GstFrappe.buffer_get_bundle_pose(buf) is None, 'bundle: none on a buffer without the meta')
    GstFrappe.buffer_add_frappe_bundle_meta(buf, 'b', [0.5, -0.25, 1.0], [0.1, 0.2, 1.5], 0.75, [3, 1], [9])
    p = GstFrappe.buffer_get_bundle_pose(buf)
    check(p is not None and p.name == 'b' and list(p.get_rvec()) == [0.5, -0.25, 1.0] and
          list(p.get_tvec()) == [0.1, 0.2, 1.5] and p.reprojection_error == 0.75 and
          list(p.get_used()) == [3, 1] and list(p.get_rejected()) == [9],
          'bundle: buffer_add_frappe_bundle_meta reads back')


def main():
    samples, have_typelib = sys.argv[1], sys.argv[2] == '1'
    try:
        import gi
        gi.require_version('Gst', '1.0')
        from gi.repository import Gst
    except (ImportError, ValueError) as e:
        print(f'skip: no PyGObject or Gst-1.0 typelib ({e})')
        return SKIP
    try:
        gi.require_version('GstFrappe', '1.0')
        from gi.repository import GstFrappe
    except (ImportError, ValueError) as e:
        if have_typelib:
            print(f'FAIL: the GstFrappe-1.0 typelib was built but does not load: {e}')
            return 1
        print(f'skip: the GstFrappe-1.0 typelib was not built ({e})')
        return SKIP
    Gst.init(None)
    truth = json.load(open(os.path.join(samples, 'markers-36h12.json')))
    truth = {m['id']: [c for xy in m['corners'] for c in xy] for m in truth['markers']}

    # Without pose.
    buffers, messages = run(Gst, samples, '')
    check(len(buffers) == 2 and len(messages) == 2, 'two frames, two frappedetect messages')
    for frame, (buf, msg) in enumerate(zip(buffers, messages)):
        markers = GstFrappe.buffer_get_markers(buf)
        check(sorted(m.id for m in markers) == sorted(truth),
              f'frame {frame}: ids {sorted(m.id for m in markers)} are the sample\'s {sorted(truth)}')
        check([m.id for m in markers] == [s.get_value('id') for s in msg],
              f'frame {frame}: markers in the order of the message')
        check(GstFrappe.buffer_get_n_frappe_marker_metas(buf) == len(markers),
              f'frame {frame}: buffer_get_n_frappe_marker_metas agrees')
        for m, s in zip(markers, msg):
            corners = list(m.get_corners())
            check(len(corners) == 8 and corners == list(s.get_value('corners')),
                  f'id {m.id}: the 8 corner coordinates equal the message\'s')
            check([m.get_corner(i) for i in range(4)] ==
                  [(corners[2 * i], corners[2 * i + 1]) for i in range(4)], f'id {m.id}: get_corner(i)')
            if m.id in truth:
                err = max(abs(a - b) for a, b in zip(corners, truth[m.id]))
                check(err < 0.1, f'id {m.id}: corners within 0.1 px of the rendered truth ({err:.4f})')
            check(m.dictionary == 'aruco_mip_36h12', f'id {m.id}: dictionary {m.dictionary!r}')
            check(m.hamming == 0 and s.get_value('hamming') == 0, f'id {m.id}: hamming {m.hamming}')
            check(abs(m.margin - s.get_value('margin')) < 1e-6 and 0.5 < m.margin <= 1,
                  f'id {m.id}: margin {m.margin:.3f} is the message\'s')
            check(not m.has_pose and list(m.get_tvec()) == [0, 0, 0], f'id {m.id}: no pose without marker-size')

    # With marker-size and camera-matrix: the pose.
    side, fx, fy, cx, cy = 0.1, 600.0, 600.0, 320.0, 240.0
    buffers, messages = run(Gst, samples, f'marker-size={side} camera-matrix="<{fx}, 0.0, {cx}, 0.0, {fy}, '
                            f'{cy}, 0.0, 0.0, 1.0>"', frames=1)
    check(len(buffers) == 1 and len(messages) == 1, 'posed: one frame, one message')
    markers = GstFrappe.buffer_get_markers(buffers[0]) if buffers else []
    buffers = None  # the markers are copies: they outlive the buffer
    check(sorted(m.id for m in markers) == sorted(truth), 'posed: the sample\'s ids')
    for m, s in zip(markers, messages[0] if messages else []):
        check(m.has_pose, f'id {m.id}: has_pose')
        check(list(m.get_tvec()) == list(s.get_value('tvec')) and
              list(m.get_rvec()) == list(s.get_value('rvec')), f'id {m.id}: rvec and tvec equal the message\'s')
        check(m.reprojection_error == s.get_value('reprojection-error') and
              m.alternative_reprojection_error == s.get_value('alternative-reprojection-error'),
              f'id {m.id}: reprojection errors equal the message\'s')
        z = m.get_tvec()[2]
        check(0.3 < z < 1.5, f'id {m.id}: in front of the camera at {z:.3f} m')
        rms = reprojection_rms(m, side, fx, fy, cx, cy)
        check(abs(rms - m.reprojection_error) < 1e-3 and m.reprojection_error < 3,
              f'id {m.id}: rvec/tvec reproject the corners with the stated error '
              f'({rms:.4f} vs {m.reprojection_error:.4f} px)')

    # A frame without markers, and a buffer frappedetect never saw.
    pipeline = Gst.parse_launch('videotestsrc pattern=white num-buffers=1 ! '
                                'video/x-raw,format=GRAY8,width=160,height=120 ! frappedetect ! '
                                'appsink name=sink sync=false')
    buffers, _ = pull(Gst, pipeline, 1)
    check(len(buffers) == 1 and GstFrappe.buffer_get_markers(buffers[0]) == [],
          'a white frame: an empty list')
    check(GstFrappe.buffer_get_markers(Gst.Buffer.new()) == [], 'a buffer without metas: an empty list')

    # A meta added from Python reads back exactly (floats exact in binary).
    buf = Gst.Buffer.new()
    meta = GstFrappe.buffer_add_frappe_marker_meta(buf, 7, 'apriltag_36h11',
                                                   [1.5, 2.25, 10.5, 2.0, 10.0, 11.75, 1.0, 11.5], 1)
    markers = GstFrappe.buffer_get_markers(buf)
    check(meta is not None and len(markers) == 1 and markers[0].id == 7 and
          markers[0].dictionary == 'apriltag_36h11' and markers[0].hamming == 1 and
          list(markers[0].get_corners()) == [1.5, 2.25, 10.5, 2.0, 10.0, 11.75, 1.0, 11.5] and
          not markers[0].has_pose and markers[0].margin == 0, 'buffer_add_frappe_marker_meta reads back')

    if len(sys.argv) > 3:
        check_bundle_pose(Gst, GstFrappe, sys.argv[3])
    else:  # a build without the CLI (-Dcli=disabled): no board to render
        print('bundle pose: not checked, no frappe-render in this build')

    print(f'{len(failures)} failure(s)')
    return 1 if failures else 0


if __name__ == '__main__':
    sys.exit(main())
