# SPDX-License-Identifier: MIT
# frappe.stream against the real element: the sample video through
# frappedetect ! frappejson in gst-launch-1.0 (GST_PLUGIN_PATH from meson),
# over UDP, and over TCP from a tcpserversink that starts after the host and
# is killed and started again mid-stream (the robot restarting).
# Either line form is accepted: the time base's (frame numbers, parts) is
# checked further when the element writes it.
import os
import shutil
import signal
import socket
import subprocess
import sys
import threading
import time

import pytest

from frappe import stream

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SAMPLE = os.path.join(ROOT, "examples", "data", "markers.webm")
CALIBRATION = os.path.join(ROOT, "examples", "data", "camera-700.yaml")


def gst_launch():
    """gst-launch-1.0, or skip without it or the element's build."""
    launch = shutil.which("gst-launch-1.0")
    if not launch or not os.environ.get("GST_PLUGIN_PATH"):
        pytest.skip("gst-launch-1.0 or the element's build (GST_PLUGIN_PATH) missing")
    return launch


def robot(sink):
    """gst-launch-1.0: the sample, detected with poses, frappejson into `sink`."""
    return subprocess.Popen([gst_launch(), "-q", "filesrc", f"location={SAMPLE}", "!", "decodebin", "!", "videoconvert",
                             "!", "frappedetect", "marker-size=0.05", f"calibration-file={CALIBRATION}", "!",
                             "frappejson", "!", *sink.split()], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True)


def check_sample_frame(frame):
    assert sorted(m.id for m in frame.markers) == [0, 7, 23, 42]
    zero = next(m for m in frame.markers if m.id == 0)
    assert abs(zero.pose.tvec[2] - 0.27) < 0.0027  # the sample's marker 0 is 0.27 m away
    assert zero.dictionary == "aruco_mip_36h12" and len(zero.corners) == 4
    # The time base of every line (issue 31's frappejson).
    assert (frame.width, frame.height) == (640, 480)
    assert frame.frame_id == "camera" and frame.pts is not None and frame.running_time is not None


def free_port(kind):
    s = socket.socket(socket.AF_INET, kind)
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port


def test_udp_from_the_element_every_frame():
    port = free_port(socket.SOCK_DGRAM)
    with stream.udp(port, "127.0.0.1") as rx:
        p = robot(f"udpsink host=127.0.0.1 port={port} sync=false")
        frames = []
        while len(frames) < 120 and (frame := rx.read(timeout=10)) is not None:
            frames.append(frame)
        assert p.wait(60) == 0, p.stderr.read()
    assert len(frames) == 120
    for f in frames:
        check_sample_frame(f)
    assert [f.number for f in frames] == list(range(120))
    assert rx.stats.lost == 0 and rx.stats.frames == 120


def test_tcp_robot_starts_late_and_restarts_mid_stream():
    port = free_port(socket.SOCK_STREAM)
    rx = stream.tcp("127.0.0.1", port, backoff=(0.05, 0.5))
    got = []
    reader = threading.Thread(target=lambda: got.extend(rx.frames(timeout=3)))
    reader.start()
    sink = f"tcpserversink host=127.0.0.1 port={port}"  # sync: the sample at 30 frames a second
    time.sleep(1.0)  # the host is refused until the robot is up
    first = robot(sink)
    deadline = time.monotonic() + 30
    while len(got) < 15 and time.monotonic() < deadline:
        time.sleep(0.05)
    first.send_signal(signal.SIGKILL)  # the robot dies mid-stream
    first.wait(10)
    before = len(got)
    assert before >= 15, f"{before} frames from the first run"
    time.sleep(0.5)
    second = robot(sink)
    assert second.wait(60) == 0, second.stderr.read()
    reader.join(30)
    rx.close()
    after = got[before:]
    # Connected within the back-off (0.5 s at most) of the second run's start: most of its 4 s.
    assert len(after) >= 60, f"{len(after)} frames from the second run"
    for f in got:
        check_sample_frame(f)
    s = rx.stats
    assert s.reconnects == 1
    # Frame numbers: the restart is seen, nothing lost.
    assert s.restarts == 1 and s.lost == 0
    assert after[0].number < got[before - 1].number
    numbers = [f.number for f in after]
    assert numbers == list(range(numbers[0], numbers[0] + len(numbers)))


def test_frappe_watch_says_why_it_cannot_start():
    pytest.importorskip("gi")
    gst_launch()
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(p for p in sys.path if p))
    p = subprocess.run([sys.executable, "-m", "frappe.watch", "--port", "0", "--file", "/nonexistent.webm"],
                       capture_output=True, text=True, env=env, timeout=60)
    assert p.returncode == 1
    assert 'frappe-watch: filesrc0: Resource not found.' in p.stderr and 'No such file "/nonexistent.webm"' in p.stderr
    assert "Traceback" not in p.stderr
