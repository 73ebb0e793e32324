#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""frappe-watch in a real browser: the page served for the sample still
image (examples/images/markers-36h12.png through imagefreeze), opened by
Debian's headless Chromium. The screenshot must show the overlay, green
outline pixels on each of the image's six markers' four sides (where the
fixture's corners say) and none at their centres, at the place the page puts
the video; the page's text, after its script polled /markers.json, must list
exactly the six ids. The MJPEG answer must be multipart/x-mixed-replace with
whole JPEGs between the boundaries.

Exit 77 without chromium, Python's gi or the element. Run with /usr/bin/python3:
  check_watch.py SOURCE_ROOT PYTHONPATH"""
import json
import os
import re
import shutil
import socket
import subprocess
import sys
import tempfile
import time
import urllib.request

SKIP = 77


def free_port():
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port


def read_png_rgb(path):
    """The screenshot as (width, height, RGB bytes), decoded by GStreamer."""
    import gi
    gi.require_version("Gst", "1.0")
    from gi.repository import Gst
    Gst.init(None)
    p = Gst.parse_launch(f'filesrc location="{path}" ! pngdec ! videoconvert ! video/x-raw,format=RGB ! '
                         "appsink name=s")
    p.set_state(Gst.State.PLAYING)
    sample = p.get_by_name("s").emit("pull-sample")
    s = sample.get_caps().get_structure(0)
    w, h = s.get_value("width"), s.get_value("height")
    buf = sample.get_buffer()
    data = buf.extract_dup(0, buf.get_size())
    p.set_state(Gst.State.NULL)
    return w, h, data, (len(data) // h)


def chromium(browser, tmp, *args):
    return subprocess.run([browser, "--headless", "--no-sandbox", "--disable-gpu", "--no-first-run",
                           f"--user-data-dir={tmp}/profile", "--force-device-scale-factor=1",
                           "--virtual-time-budget=3000", *args],
                          capture_output=True, timeout=60, cwd=tmp)


def main():
    root, pythonpath = sys.argv[1:3]
    browser = shutil.which("chromium") or shutil.which("chromium-browser")
    if not browser:
        print("chromium not installed (scripts/install-deps.sh installs it)")
        return SKIP
    try:
        import gi
        gi.require_version("Gst", "1.0")
        from gi.repository import Gst
        Gst.init(None)
    except (ImportError, ValueError) as e:
        print(f"no GStreamer for Python: {e}")
        return SKIP
    if not Gst.ElementFactory.find("frappedetect") or not Gst.ElementFactory.find("jpegenc"):
        print("frappedetect or jpegenc not found")
        return SKIP

    image = os.path.join(root, "examples", "images", "markers-36h12.png")
    truth = json.load(open(os.path.join(root, "examples", "images", "markers-36h12.json")))["markers"]
    port = free_port()
    env = dict(os.environ, PYTHONPATH=pythonpath)
    watch = subprocess.Popen([sys.executable, "-m", "frappe.watch", "--bind", "127.0.0.1", "--port", str(port),
                              "--source", f'filesrc location="{image}" ! pngdec ! imagefreeze'],
                             env=env, stderr=subprocess.PIPE, text=True)
    try:
        line = watch.stderr.readline()
        if f":{port}/" not in line:
            print(f"frappe-watch did not start: {line}{watch.stderr.read() if watch.poll() is not None else ''}")
            return 1
        url = f"http://127.0.0.1:{port}/"
        # The first frame through the detector before the browser looks.
        deadline = time.monotonic() + 10
        while json.load(urllib.request.urlopen(url + "markers.json"))["number"] is None:
            if time.monotonic() > deadline:
                print("no frame in 10 s")
                return 1
            time.sleep(0.1)

        # The MJPEG answer, read raw: a header browsers accept, whole JPEGs.
        with urllib.request.urlopen(url + "video.mjpeg", timeout=10) as r:
            kind = r.headers["Content-Type"]
            data = r.read(300_000)
        if kind != "multipart/x-mixed-replace; boundary=frame":
            print(f"/video.mjpeg: Content-Type {kind}")
            return 1
        parts = re.findall(rb"--frame\r\nContent-Type: image/jpeg\r\nContent-Length: (\d+)\r\n\r\n\xff\xd8", data)
        if len(parts) < 2:
            print(f"/video.mjpeg: {len(parts)} JPEG parts in {len(data)} bytes")
            return 1

        with tempfile.TemporaryDirectory(prefix="frappe-watch-") as tmp:
            shot = os.path.join(tmp, "shot.png")
            p = chromium(browser, tmp, "--window-size=1000,520", f"--screenshot={shot}", url)
            if not os.path.exists(shot):
                print(f"chromium made no screenshot:\n{p.stderr.decode(errors='replace')[-2000:]}")
                return 1
            w, h, rgb, stride = read_png_rgb(shot)
            dom = chromium(browser, tmp, "--dump-dom", url).stdout.decode()
    finally:
        watch.terminate()
        watch.wait(10)

    def green_near(x, y, r=3):
        for yy in range(int(y) - r, int(y) + r + 1):
            for xx in range(int(x) - r, int(x) + r + 1):
                if 0 <= xx < w and 0 <= yy < h:
                    R, G, B = rgb[yy * stride + 3 * xx:yy * stride + 3 * xx + 3]
                    if G > 120 and G - max(R, B) > 60:  # green, paled by JPEG's chroma
                        return True
        return False

    failures = []
    for m in truth:
        c = m["corners"]
        for k in range(4):  # the middle of each side: the outline, not an id label or corner dot
            x = (c[k][0] + c[(k + 1) % 4][0]) / 2
            y = (c[k][1] + c[(k + 1) % 4][1]) / 2
            if not green_near(x, y):
                failures.append(f"marker {m['id']}: no green outline at ({x:.0f}, {y:.0f})")
        cx, cy = sum(p[0] for p in c) / 4, sum(p[1] for p in c) / 4
        if green_near(cx, cy, 1):
            failures.append(f"marker {m['id']}: green at its centre ({cx:.0f}, {cy:.0f})")
    listed = sorted(int(i) for i in re.findall(r"<li>id (\d+):", dom))
    want = sorted(m["id"] for m in truth)
    if listed != want:
        failures.append(f"the page lists ids {listed}, not {want}")
    if failures:
        print("\n".join(failures))
        return 1
    print(f"screenshot {w}x{h}: the outline on all four sides of {len(truth)} markers; the page lists {listed}; "
          f"/video.mjpeg: {len(parts)} JPEGs in the first {len(data)} bytes")
    return 0


if __name__ == "__main__":
    sys.exit(main())
