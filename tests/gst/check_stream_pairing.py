#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Issue 31: examples/stream-markers.sh sends the annotated video and the
markers of one detection, and the host pairs every decoded frame with its
markers (python/frappe/video.py), end to end on loopback.

The robot: stream-markers.sh with 45 frames standing in for the camera,
each showing another subset of the six markers of
examples/images/markers-36h12.png (frame n shows marker j when bit j of
n + 1 is set), paced at 15 frames a second; H.264 from x264enc.
The host: receive_ts() decodes the MPEG-TS and runs frappedetect again on
each decoded (annotated) frame. For every one of the 45 frames:
  * its line's `frame` number n is new, and all 45 come;
  * the ids in its paired line are frame n's subset;
  * the ids frappedetect reads on the decoded frame are the same:
    the frame and the line are each other's, not a neighbour's;
  * the markers-only datagrams (MARKER_PORT, parts of at most 1400
    bytes) paired by `frame` give the same markers, poses included.
Then the robot restarts (a second run of the script, frame numbers from
0 again) while the same host program reads on: every frame of the second
run is paired as well.
Exit 77 without gi, the typelib, or the GStreamer elements it takes."""
import importlib
import json
import os
import socket
import subprocess
import sys
import tempfile
import threading

FRAMES = 45
RUNS = 2  # the robot's first run, then a restart


def load_video_module(path):
    """python/frappe/video.py as frappe.video, imported from its source
    folder: the package imports without the compiled extension."""
    sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(path))))
    return importlib.import_module("frappe.video")


def shown(n, ids):
    """The ids frame n shows."""
    return sorted(ids[j] for j in range(len(ids)) if (n + 1) >> j & 1)


def main():
    script, video_py, image_dir = sys.argv[1:4]
    try:
        import gi
        gi.require_version("Gst", "1.0")
        gi.require_version("GstFrappe", "1.0")
        from gi.repository import Gst, GstFrappe
        import numpy as np
    except (ImportError, ValueError) as e:
        print(f"skipped: {e}")
        return 77
    Gst.init(None)
    need = ["x264enc", "h264parse", "mpegtsmux", "tsdemux", "avdec_h264", "pnmdec", "pngdec", "multifilesrc"]
    missing = [e for e in need if Gst.ElementFactory.find(e) is None]
    if missing:
        print(f"skipped: no {' '.join(missing)} (gstreamer1.0-plugins-bad, -ugly, -libav)")
        return 77
    video = load_video_module(video_py)

    # The six markers' picture as grey pixels, and where each marker is.
    with open(os.path.join(image_dir, "markers-36h12.json")) as f:
        truth = json.load(f)
    ids = [m["id"] for m in truth["markers"]]
    p = Gst.parse_launch(f"filesrc location={os.path.join(image_dir, truth['image'])} ! pngdec ! videoconvert ! "
                         "video/x-raw,format=GRAY8 ! appsink name=sink")
    p.set_state(Gst.State.PLAYING)
    sample = p.get_by_name("sink").emit("pull-sample")
    caps = sample.get_caps().get_structure(0)
    width, height = caps.get_value("width"), caps.get_value("height")
    buf = sample.get_buffer()
    grey = np.frombuffer(buf.extract_dup(0, buf.get_size()), np.uint8)
    grey = grey.reshape(height, -1)[:, :width].copy()
    p.set_state(Gst.State.NULL)

    with tempfile.TemporaryDirectory() as tmp:
        for n in range(FRAMES):
            frame = grey.copy()
            for j, m in enumerate(truth["markers"]):
                if not (n + 1) >> j & 1:
                    xs, ys = [c[0] for c in m["corners"]], [c[1] for c in m["corners"]]
                    top, left = max(0, int(min(ys)) - 12), max(0, int(min(xs)) - 12)
                    frame[top:int(max(ys)) + 12, left:int(max(xs)) + 12] = 255
            with open(os.path.join(tmp, f"frame{n:03d}.pgm"), "wb") as f:
                f.write(b"P5\n%d %d\n255\n" % (width, height) + frame.tobytes())

        probe = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        probe.bind(("127.0.0.1", 0))
        video_port = probe.getsockname()[1]
        probe.close()
        markers_sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        markers_sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 1 << 22)
        markers_sock.bind(("127.0.0.1", 0))

        # The host, listening before the robot starts.
        paired, errors = [], []
        started = threading.Event()

        def host():
            try:
                frames = video.receive_ts(port=video_port, address="127.0.0.1",
                                          video_caps="video/x-raw,format=GRAY8", then="frappedetect ! ",
                                          timeout=6)  # longer than a restart takes
                started.set()
                for f in frames:
                    read = sorted(m.id for m in GstFrappe.buffer_get_markers(f.sample.get_buffer()))
                    paired.append((f, read))
            except Exception as e:  # reported below
                errors.append(repr(e))
            started.set()

        t = threading.Thread(target=host)
        t.start()
        started.wait(10)
        env = dict(os.environ, HOST="127.0.0.1", VIDEO_PORT=str(video_port),
                   MARKER_PORT=str(markers_sock.getsockname()[1]), QUEUE="queue",
                   SOURCE=f"multifilesrc location={tmp}/frame%03d.pgm index=0 stop-index={FRAMES - 1} "
                          "caps=image/x-portable-graymap,framerate=15/1 ! pnmdec ! videoconvert ! "
                          "video/x-raw,format=I420 ! identity sync=true",
                   ENCODER="x264enc tune=zerolatency speed-preset=ultrafast key-int-max=15 bitrate=4000 ! "
                           "h264parse")
        # The markers-only datagrams of the first run are read before the
        # restart: frame numbers start again at 0 in the second.
        datagrams_first = []
        robots = []
        for run in range(RUNS):
            robots.append(subprocess.run(["sh", script], env=env, capture_output=True, text=True, timeout=120))
            if run == 0:
                markers_sock.settimeout(1.0)
                try:
                    while True:
                        datagrams_first.append(markers_sock.recv(65536))
                except socket.timeout:
                    pass
        t.join(60)
    for robot in robots:
        if robot.returncode != 0:
            print(robot.stdout + robot.stderr)
            return 1
    if errors:
        print(f"host: {errors}")
        return 1

    failures = []
    runs = [[]]  # the frame numbers of each run, in the order they came
    first_run = []
    for f, read in paired:
        if f.line is None:
            failures.append(f"PTS {f.key}: no markers paired")
            continue
        n = f.line["frame"]
        if runs[-1] and n <= runs[-1][-1]:
            runs.append([])  # the restart
        runs[-1].append(n)
        if len(runs) == 1:
            first_run.append(f)
        in_line = sorted(m["id"] for m in f.markers)
        if in_line != shown(n, ids) or read != in_line:
            failures.append(f"run {len(runs)} frame {n}: line {in_line}, decoded frame {read}, shown {shown(n, ids)}")
    if runs != [list(range(FRAMES))] * RUNS:
        failures.append(f"frame numbers by run: {runs}")
    seen = set(runs[0])

    # The markers alone (the first run's), by frame number, against the
    # lines in the video.
    by_frame = video.Pairer(max_waiting=FRAMES)
    datagrams, longest = len(datagrams_first), max((len(d) for d in datagrams_first), default=0)
    for data in datagrams_first:
        by_frame.add_line(json.loads(data))
    alone = []
    for f in first_run:
        if f.line is not None:
            alone += by_frame.add_frame(f.line, f.line["frame"])
    alone += by_frame.flush()
    for p in alone[:1]:
        if p.line is None or p.line["markers"] != p.image["markers"]:
            print(f"frame {p.key}: alone {p.line}\nin the video {p.image}")
    same = sum(1 for p in alone if p.line is not None and p.line["markers"] == p.image["markers"])
    if same != FRAMES or longest > 1400:
        failures.append(f"markers alone: {same} of {FRAMES} frames the same, longest datagram {longest}")

    for line in failures:
        print(line)
    print(f"{len(paired)} decoded frames paired in {len(runs)} runs, {len(seen)} frame numbers in the first, {datagrams} marker datagrams "
          f"(at most {longest} bytes), {same} frames the same alone")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
