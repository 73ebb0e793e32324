#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Each gst-launch example of examples/ run briefly on the sample video, its
claim checked (examples/README.md):

  annotate-file.sh   an annotated WebM of all 120 frames (green outline on
                     marker 0's four sides in frame 0) and a message a frame
  libcamera-pi.sh    a message with poses a frame: the Pi's libcamerasrc
                     replaced by the sample (a gst-launch-1.0 shim on PATH),
                     everything else as written, so its properties are checked
  stream-h264-rtp.sh RTP packets of payload type 96 that decode (avdec_h264)
                     to frames with the overlay
  stream-mjpeg.sh    a page at http://HOST:PORT/, multipart/x-mixed-replace
                     JPEGs, /markers.json listing markers 0, 7, 23, 42
  env.sh             sourced, gst-inspect-1.0 finds frappedetect
  render-sample      a WebM of the frames asked for, frame 0 with the sample's
                     markers 0, 7, 23, 42 (frappedetect reads them back)

(stream-markers.sh and receive-markers.py: the receive-markers test; the page
in a browser: watch-page.) A check whose plugins are missing is skipped; exit
77 when all are. Run with /usr/bin/python3 (gi):
  check_examples.py SOURCE_ROOT BUILD_ROOT RENDER_SAMPLE"""
import json
import os
import shutil
import socket
import stat
import subprocess
import sys
import tempfile
import time
import urllib.request

import gi

gi.require_version("Gst", "1.0")
from gi.repository import Gst  # noqa: E402

Gst.init(None)

SKIP = 77
ROOT, BUILD, RENDER_SAMPLE = sys.argv[1:4]
EXAMPLES = os.path.join(ROOT, "examples")
SAMPLE = os.path.join(EXAMPLES, "data", "markers.webm")
# Marker 0 in the sample's frame 0: the middle of each side of its outline.
MARKER0_SIDES = [(150.0, 85.2), (214.8, 150.0), (150.0, 214.8), (85.2, 150.0)]


class Skip(Exception):
    pass


def need(*elements):
    missing = [e for e in elements if not Gst.ElementFactory.find(e)]
    if missing:
        raise Skip("no element " + ", ".join(missing))


def first_frame_rgb(pipeline_head):
    """Frame 0 of `pipeline_head` (ending in raw video) as (w, h, stride, RGB bytes)."""
    p = Gst.parse_launch(pipeline_head + " ! videoconvert ! video/x-raw,format=RGB ! appsink name=s")
    p.set_state(Gst.State.PLAYING)
    sample = p.get_by_name("s").emit("try-pull-sample", 20 * Gst.SECOND)
    p.set_state(Gst.State.NULL)
    if sample is None:
        raise AssertionError(f"no frame from {pipeline_head}")
    s = sample.get_caps().get_structure(0)
    buf = sample.get_buffer()
    data = buf.extract_dup(0, buf.get_size())
    return s.get_value("width"), s.get_value("height"), len(data) // s.get_value("height"), data


def count_frames(pipeline_head):
    p = Gst.parse_launch(pipeline_head + " ! appsink name=s sync=false")
    p.set_state(Gst.State.PLAYING)
    n = 0
    while p.get_by_name("s").emit("try-pull-sample", 20 * Gst.SECOND) is not None:
        n += 1
    p.set_state(Gst.State.NULL)
    return n


def green_at(frame, points, r=3):
    """The points with no green (the overlay's outline) within r pixels."""
    w, h, stride, rgb = frame
    missing = []
    for x, y in points:
        found = False
        for yy in range(int(y) - r, int(y) + r + 1):
            for xx in range(int(x) - r, int(x) + r + 1):
                if 0 <= xx < w and 0 <= yy < h:
                    R, G, B = rgb[yy * stride + 3 * xx:yy * stride + 3 * xx + 3]
                    found = found or (G > 120 and G - max(R, B) > 60)
        if not found:
            missing.append((x, y))
    return missing


def messages_with(out, word):
    return sum(1 for line in out.splitlines() if "frappedetect" in line and word in line)


def check_annotate_file(tmp):
    need("vp8enc", "webmmux", "vp8dec", "matroskademux")
    out = os.path.join(tmp, "annotated.webm")
    p = subprocess.run(["sh", os.path.join(EXAMPLES, "annotate-file.sh"), SAMPLE, out], capture_output=True,
                       text=True, timeout=120)
    assert p.returncode == 0, p.stderr[-2000:]
    n = messages_with(p.stdout, "aruco_mip_36h12")
    assert n == 120, f"{n} messages with markers, not 120"
    decoded = count_frames(f'filesrc location="{out}" ! decodebin')
    assert decoded == 120, f"{out}: {decoded} frames, not 120"
    missing = green_at(first_frame_rgb(f'filesrc location="{out}" ! decodebin'), MARKER0_SIDES)
    assert not missing, f"frame 0: no green outline at {missing}"
    return "120 frames annotated (outline on marker 0), 120 messages"


def check_libcamera_pi(tmp):
    need("matroskademux", "vp8dec")
    shim = os.path.join(tmp, "gst-launch-1.0")
    with open(shim, "w") as f:  # libcamerasrc -> the sample, the rest untouched
        f.write(f"""#!{sys.executable}
import os, sys
args = []
for a in sys.argv[1:]:
    args += ["filesrc", "location={SAMPLE}", "!", "decodebin", "!", "videoconvert"] if a == "libcamerasrc" else [a]
os.execvp("{shutil.which('gst-launch-1.0')}", ["gst-launch-1.0"] + args)
""")
    os.chmod(shim, stat.S_IRWXU)
    env = dict(os.environ, PATH=tmp + os.pathsep + os.environ["PATH"])
    p = subprocess.run(["sh", os.path.join(EXAMPLES, "libcamera-pi.sh")], capture_output=True, text=True,
                       env=env, timeout=120)
    assert p.returncode == 0, p.stderr[-2000:]
    assert "WARN" not in p.stderr and "rror" not in p.stderr, p.stderr[-2000:]
    n = messages_with(p.stdout, "rvec")
    assert n == 120, f"{n} messages with poses, not 120"
    return "120 messages with poses (libcamerasrc replaced by the sample)"


def check_stream_h264_rtp(tmp):
    need("x264enc", "rtph264pay", "rtph264depay", "avdec_h264")
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 8 << 20)
    sock.bind(("127.0.0.1", 0))
    env = dict(os.environ, HOST="127.0.0.1", PORT=str(sock.getsockname()[1]))
    p = subprocess.run(["sh", os.path.join(EXAMPLES, "stream-h264-rtp.sh")], capture_output=True, text=True,
                       env=env, timeout=120)
    assert p.returncode == 0, p.stderr[-2000:]
    sock.setblocking(False)
    packets = []
    try:
        while True:
            packets.append(sock.recv(65536))
    except BlockingIOError:
        pass
    assert packets and all(pkt[1] & 0x7F == 96 for pkt in packets), f"{len(packets)} packets, not all PT 96"
    # The packets back through an appsrc into the decoder: the overlay is in the video.
    rtp = Gst.parse_launch('appsrc name=src format=time caps="application/x-rtp,media=video,encoding-name=H264,'
                           'payload=96,clock-rate=90000" ! rtph264depay ! h264parse ! avdec_h264 ! videoconvert ! '
                           "video/x-raw,format=RGB ! appsink name=s sync=false")
    src = rtp.get_by_name("src")
    rtp.set_state(Gst.State.PLAYING)
    for pkt in packets:
        src.emit("push-buffer", Gst.Buffer.new_wrapped(pkt))
    src.emit("end-of-stream")
    decoded, first = 0, None
    while True:
        sample = rtp.get_by_name("s").emit("try-pull-sample", 10 * Gst.SECOND)
        if sample is None:
            break
        if first is None:
            s = sample.get_caps().get_structure(0)
            buf = sample.get_buffer()
            data = buf.extract_dup(0, buf.get_size())
            first = (s.get_value("width"), s.get_value("height"), len(data) // s.get_value("height"), data)
        decoded += 1
    rtp.set_state(Gst.State.NULL)
    assert decoded >= 100, f"{decoded} frames decoded from {len(packets)} packets"
    missing = green_at(first, MARKER0_SIDES, r=4)
    assert not missing, f"frame 0 decoded: no green outline at {missing}"
    return f"{len(packets)} RTP packets (PT 96), {decoded} frames decoded with the overlay"


def check_stream_mjpeg(tmp):
    need("jpegenc", "vp8dec")
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    p = subprocess.Popen(["sh", os.path.join(EXAMPLES, "stream-mjpeg.sh")], env=dict(os.environ, PORT=str(port)),
                         stderr=subprocess.PIPE, text=True)
    try:
        url = f"http://127.0.0.1:{port}/"
        deadline, frame = time.monotonic() + 20, None
        while time.monotonic() < deadline:
            try:
                frame = json.load(urllib.request.urlopen(url + "markers.json", timeout=2))
                if frame["number"] is not None:
                    break
            except OSError:
                assert p.poll() is None, p.stderr.read()[-2000:]
            time.sleep(0.2)
        assert frame and frame["number"] is not None, "no frame in 20 s"
        ids = sorted(m["id"] for m in frame["markers"])
        assert ids == [0, 7, 23, 42], f"/markers.json: ids {ids}"
        page = urllib.request.urlopen(url, timeout=5).read().decode()
        assert '<img id="video" src="/video.mjpeg"' in page, "the page shows no /video.mjpeg"
        with urllib.request.urlopen(url + "video.mjpeg", timeout=5) as r:
            kind = r.headers["Content-Type"]
            data = r.read(100_000)
        assert kind == "multipart/x-mixed-replace; boundary=frame", f"/video.mjpeg: {kind}"
        assert data.startswith(b"--frame\r\nContent-Type: image/jpeg\r\n"), data[:80]
        assert data.count(b"\r\n\r\n\xff\xd8") >= 2, "fewer than two JPEGs"
    finally:
        p.terminate()
        p.wait(10)
    return f"page, MJPEG answer and /markers.json (ids {ids}) on port {port}"


def check_env_sh(tmp):
    p = subprocess.run(["bash", "-c", f'. "{EXAMPLES}/env.sh" "{BUILD}" && gst-inspect-1.0 frappedetect'],
                       capture_output=True, text=True, timeout=60,
                       env={k: v for k, v in os.environ.items() if not k.startswith("GST_PLUGIN_PATH")})
    assert p.returncode == 0 and "frappedetect" in p.stdout, p.stderr[-2000:]
    return "gst-inspect-1.0 frappedetect after sourcing it"


def check_render_sample(tmp):
    need("vp8enc", "webmmux", "vp8dec", "matroskademux")
    out = os.path.join(tmp, "sample.webm")
    p = subprocess.run([RENDER_SAMPLE, out, "10"], capture_output=True, text=True, timeout=120)
    assert p.returncode == 0, p.stderr[-2000:]
    head = f'filesrc location="{out}" ! decodebin'
    assert count_frames(head) == 10, f"{out}: not 10 frames"
    d = Gst.parse_launch(head + " ! videoconvert ! frappedetect ! frappejson ! appsink name=s sync=false")
    d.set_state(Gst.State.PLAYING)
    sample = d.get_by_name("s").emit("try-pull-sample", 20 * Gst.SECOND)
    d.set_state(Gst.State.NULL)
    assert sample is not None, "no marker line"
    buf = sample.get_buffer()
    line = json.loads(buf.extract_dup(0, buf.get_size()).split(b"\n")[0])
    ids = sorted(m["id"] for m in line["markers"])
    assert ids == [0, 7, 23, 42], f"frame 0: ids {ids}"
    return "10 frames, frame 0 with markers 0, 7, 23, 42"


def main():
    results = {"ok": 0, "skip": 0, "fail": 0}
    for check in (check_annotate_file, check_libcamera_pi, check_stream_h264_rtp, check_stream_mjpeg, check_env_sh,
                  check_render_sample):
        name = check.__name__[len("check_"):].replace("_", "-")
        start = time.monotonic()
        with tempfile.TemporaryDirectory(prefix="frappe-example-") as tmp:
            try:
                what, kind = check(tmp), "ok"
            except Skip as e:
                what, kind = f"skipped: {e}", "skip"
            except (AssertionError, subprocess.TimeoutExpired) as e:
                what, kind = f"FAIL: {e}", "fail"
        results[kind] += 1
        print(f"{name}: {what} ({time.monotonic() - start:.1f} s)", flush=True)
    if results["fail"]:
        return 1
    return SKIP if not results["ok"] else 0


if __name__ == "__main__":
    sys.exit(main())
