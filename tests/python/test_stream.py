# SPDX-License-Identifier: MIT
# frappe.stream against a fake robot (stream_sender.py): parts out of order,
# a lost part, a restart, late parts, the old line form, 300 posed markers
# over UDP, TCP with a robot that starts late and restarts, frappe-receive.
import json
import os
import socket
import subprocess
import sys
import threading
import time

import pytest

from frappe import stream
from stream_sender import Robot, frame_lines, free_port, marker, send_udp


def feed(reassembler, lines):
    out = []
    for line in lines:
        out += reassembler.add(line)
    return out


def test_parts_in_any_order_make_one_frame_with_markers_in_order():
    r = stream.Reassembler()
    lines = frame_lines(5, [marker(i) for i in range(7)], parts=3)
    frames = feed(r, [lines[2], lines[0], lines[1]])
    assert len(frames) == 1
    f = frames[0]
    assert (f.number, f.complete, f.parts, f.width, f.height, f.frame_id) == (5, True, 3, 640, 480, "camera")
    assert (f.pts, f.running_time, f.capture_clock) == (5 * 33_333_333, 5 * 33_333_333, "pipeline")
    assert f.capture_time == 1_700_000_000_000_000_000 + 5 * 33_333_333
    assert [m.id for m in f.markers] == list(range(7))
    m = f.markers[3]
    assert m.corners == [(30.0, 20.0), (35.0, 20.0), (35.0, 25.0), (30.0, 25.0)]
    assert (m.dictionary, m.hamming, m.margin, m.center) == ("aruco_mip_36h12", 0, 0.5, (32.5, 22.5))
    assert m.pose.tvec == (0.03, -0.02, 1.003) and m.pose.rvec == (0.1, 0.2, 0.3)
    assert (m.pose.reprojection_error, m.pose.alternative_reprojection_error) == (0.01, None)
    assert r.stats == stream.Stats(frames=1)


BUNDLE = {"name": "board", "rvec": [-2.7, 0.0, 0.6], "tvec": [-0.05, 0.04, 0.55], "reprojection_error": 0.05,
          "used": [0, 1, 2, 3, 5], "rejected": [4]}


def test_the_bundle_pose_of_any_part_is_typed_and_a_frame_without_has_none():
    r = stream.Reassembler()
    lines = frame_lines(7, [marker(i) for i in range(6)], parts=2, bundle=BUNDLE) + frame_lines(8, [marker(0)])
    frames = feed(r, [lines[1], lines[0], lines[2]])
    assert [f.number for f in frames] == [7, 8]
    b = frames[0].bundle
    assert b == stream.BundlePose("board", (-2.7, 0.0, 0.6), (-0.05, 0.04, 0.55), 0.05, [0, 1, 2, 3, 5], [4])
    assert b.distance == pytest.approx((0.05 ** 2 + 0.04 ** 2 + 0.55 ** 2) ** 0.5)
    assert [m.id for m in frames[0].markers] == list(range(6))
    assert frames[1].bundle is None
    assert stream.parse_line(json.dumps(dict(json.loads(lines[2]), bundle=None)))["bundle"] is None


def test_a_frame_missing_a_part_is_lost_or_delivered_flagged():
    lines = frame_lines(0, [marker(0)]) + frame_lines(1, [marker(i) for i in range(6)], parts=3)[:2] + \
        frame_lines(2, [marker(9)])
    r = stream.Reassembler()
    assert [f.number for f in feed(r, lines)] == [0, 2]
    assert (r.stats.frames, r.stats.lost, r.stats.incomplete) == (2, 1, 0)

    r = stream.Reassembler(incomplete=True)
    frames = feed(r, lines)
    assert [(f.number, f.complete) for f in frames] == [(0, True), (1, False), (2, True)]
    assert [m.id for m in frames[1].markers] == [0, 1, 2, 3]  # parts 1 and 2 of 3
    assert (r.stats.frames, r.stats.lost, r.stats.incomplete) == (3, 0, 1)


def test_the_last_frame_missing_a_part_is_lost_at_the_end():
    r = stream.Reassembler()
    feed(r, frame_lines(0, [marker(0)]) + frame_lines(1, [marker(0), marker(1)], parts=2)[1:])
    assert r.flush() == [] and (r.stats.frames, r.stats.lost) == (1, 1)


def test_gaps_count_lost_frames_and_a_restart_does_not():
    r = stream.Reassembler()
    numbers = [0, 1, 2, 5, 6] + list(range(0, 4))  # 3 and 4 lost, then the robot restarts
    frames = feed(r, [line for n in numbers for line in frame_lines(n, [marker(n)])])
    assert [f.number for f in frames] == numbers
    assert (r.stats.lost, r.stats.restarts) == (2, 1)


def test_a_restart_long_after_frame_0_is_seen_whatever_frame_comes_first():
    r = stream.Reassembler()
    numbers = list(range(100, 110)) + [1, 2, 3]  # the new run's frame 0 lost
    feed(r, [line for n in numbers for line in frame_lines(n, [marker(0)])])
    assert (r.stats.frames, r.stats.restarts, r.stats.lost) == (13, 1, 0)


def test_a_new_connection_counts_afresh():
    r = stream.Reassembler()
    feed(r, frame_lines(40, [marker(0)]) + frame_lines(41, [marker(0)]))
    r.new_stream()  # the host was away: frames 42..59 never reached it
    feed(r, frame_lines(60, [marker(0)]) + frame_lines(62, [marker(0)]))
    r.new_stream()  # the robot restarted: its frame 3 is the first the host sees
    feed(r, frame_lines(3, [marker(0)]))
    assert (r.stats.frames, r.stats.lost, r.stats.restarts) == (5, 1, 1)


def test_a_late_part_of_a_given_up_frame_is_dropped():
    r = stream.Reassembler()
    late = frame_lines(1, [marker(0), marker(1)], parts=2)
    lines = frame_lines(0, [marker(0)]) + late[:1] + frame_lines(2, [marker(2)]) + late[1:] + \
        frame_lines(3, [marker(3)])
    assert [f.number for f in feed(r, lines)] == [0, 2, 3]
    assert (r.stats.lost, r.stats.late, r.stats.restarts) == (1, 1, 0)


def test_the_old_line_form_is_one_frame_a_line_numbered_by_arrival():
    r = stream.Reassembler()
    lines = [json.dumps({"pts": 10 * i, "markers": [marker(i, pose=False)]}) for i in range(3)]
    frames = feed(r, lines)
    assert [(f.number, f.pts, f.complete, f.markers[0].id, f.markers[0].pose) for f in frames] == \
        [(0, 0, True, 0, None), (1, 10, True, 1, None), (2, 20, True, 2, None)]
    assert frames[0].width is None and r.stats.lost == 0


def test_tracked_is_read_when_the_robot_tracks_and_none_otherwise():
    r = stream.Reassembler()
    found, tracked, plain = marker(1, pose=False), marker(2, pose=False), marker(3, pose=False)
    found["tracked"], tracked["tracked"] = False, True
    frames = feed(r, [json.dumps({"pts": 0, "markers": [found, tracked, plain]})])
    assert [m.tracked for m in frames[0].markers] == [False, True, None]


def test_a_bad_line_is_an_error_that_says_so():
    r = stream.Reassembler()
    for bad in ["not json", "[1, 2]", '{"frame": 1}', '{"frame": 1, "part": 3, "parts": 2, "markers": []}']:
        with pytest.raises(ValueError, match="bad marker line"):
            r.add(bad)
    assert r.stats.bad_lines == 4


def test_300_posed_markers_in_parts_over_udp_arrive_whole():
    port = free_port(socket.SOCK_DGRAM)
    with stream.udp(port, "127.0.0.1") as rx:
        markers = [marker(i) for i in range(300)]
        lines = frame_lines(0, [marker(0)]) + frame_lines(1, markers, parts=75) + frame_lines(2, [marker(1)])
        assert max(len(line) for line in lines) < 1400  # each part fits an Ethernet frame
        lines[1:76] = lines[75:0:-1]  # the parts in reverse
        send_udp(port, lines)
        frames = list(rx.frames(timeout=1.0))
    assert [f.number for f in frames] == [0, 1, 2]
    assert [m.id for m in frames[1].markers] == list(range(300))
    assert frames[1].markers[299].pose.tvec == (2.99, -0.02, 1.299)
    assert (rx.stats.frames, rx.stats.lost) == (3, 0)


def test_read_times_out_with_none():
    with stream.udp(free_port(socket.SOCK_DGRAM), "127.0.0.1") as rx:
        start = time.monotonic()
        assert rx.read(timeout=0.3) is None
        assert 0.25 < time.monotonic() - start < 2


def test_tcp_waits_for_a_robot_that_starts_late_and_follows_its_restart():
    port = free_port()
    log = []
    rx = stream.tcp("127.0.0.1", port, backoff=(0.05, 0.2), log=log.append)
    got = []
    reader = threading.Thread(target=lambda: got.extend(rx.frames(timeout=3.0)))
    reader.start()
    time.sleep(0.5)  # refused a few times
    first = Robot(port, range(0, 10), cut_last_line=True).start()
    first.join()
    time.sleep(0.5)  # down: refused again
    second = Robot(port, range(0, 5)).start()
    second.join()
    reader.join(10)
    rx.close()
    assert [f.number for f in got] == list(range(10)) + list(range(5))
    assert [m.id for m in got[12].markers] == [2, 3]
    s = rx.stats
    assert (s.frames, s.lost, s.restarts, s.reconnects, s.bad_lines) == (15, 0, 1, 1, 0)
    where = f"tcp 127.0.0.1:{port}"
    # Down (one line, however many tries), up, gone: twice, and down at the end.
    assert log == [f"{where}: Connection refused; trying again", f"connected to {where}",
                   f"{where}: connection closed"] * 2 + [f"{where}: Connection refused; trying again"]


def test_tcp_without_reconnect_ends_with_the_connection():
    port = free_port()
    robot = Robot(port, range(3)).start()
    rx = stream.tcp("127.0.0.1", port, reconnect=False)
    assert [f.number for f in rx.frames(timeout=5)] == [0, 1, 2]
    robot.join()
    with pytest.raises(EOFError):
        rx.read(timeout=1)


def frappe_receive(*args, **kw):
    """frappe-receive as `python -m frappe.receive` from the package under test."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(p for p in sys.path if p))
    return subprocess.Popen([sys.executable, "-m", "frappe.receive", *args], env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, **kw)


def test_frappe_receive_prints_frames_and_counts_lost_ones():
    port = free_port(socket.SOCK_DGRAM)
    p = frappe_receive("--udp", str(port), "--bind", "127.0.0.1", "--timeout", "1")
    assert "listening on udp 127.0.0.1:" in p.stderr.readline()
    send_udp(port, [line for n in (0, 1, 4) for line in frame_lines(n, [marker(n)])])
    out, err = p.communicate(timeout=20)
    assert p.returncode == 0, err
    assert out.splitlines() == [
        "frame 0 t=0.000s: id 0 at (+0.0000, -0.0200, 1.0000) m, 1.000 m away",
        "frame 1 t=0.033s: id 1 at (+0.0100, -0.0200, 1.0010) m, 1.001 m away",
        "frame 4 t=0.133s: id 4 at (+0.0400, -0.0200, 1.0040) m, 1.005 m away"]
    assert "3 frames, 2 lost, 0 incomplete" in err


def test_frappe_receive_writes_jsonl(tmp_path):
    port = free_port(socket.SOCK_DGRAM)
    out = tmp_path / "frames.jsonl"
    p = frappe_receive("--udp", str(port), "--bind", "127.0.0.1", "--count", "2", "--jsonl", str(out))
    p.stderr.readline()
    send_udp(port, frame_lines(7, [marker(1), marker(2)], parts=2) + frame_lines(8, [marker(3, pose=False)]))
    p.communicate(timeout=20)
    assert p.returncode == 0
    frames = [json.loads(line) for line in out.read_text().splitlines()]
    assert [(f["number"], f["complete"], f["width"], [m["id"] for m in f["markers"]]) for f in frames] == \
        [(7, True, 640, [1, 2]), (8, True, 640, [3])]
    assert frames[0]["markers"][1]["pose"]["tvec"] == [0.02, -0.02, 1.002]
    assert frames[1]["markers"][0]["pose"] is None


def test_frappe_receive_says_when_no_robot_answers():
    p = frappe_receive("--tcp", f"127.0.0.1:{free_port()}", "--timeout", "0.5")
    out, err = p.communicate(timeout=20)
    assert p.returncode == 1 and out == ""
    assert "Connection refused; trying again" in err and "no frame in 0.5 s" in err and "Traceback" not in err
