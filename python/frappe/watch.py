# SPDX-License-Identifier: MIT
"""frappe-watch: a page to watch a camera's markers in any browser, no plugin:
the annotated video as MJPEG over HTTP (a real multipart/x-mixed-replace
response) with the markers listed beside it.

  frappe-watch                                     # /dev/video0, http://THIS_HOST:8080/
  frappe-watch --file examples/data/markers.webm --loop \\
      --detect 'marker-size=0.05 calibration-file=examples/data/camera-700.yaml'
  frappe-watch --source 'libcamerasrc ! video/x-raw,width=640,height=480' --format NV12 \\
      --encoder 'v4l2jpegenc'                      # a Raspberry Pi and its camera

One detection: `SOURCE ! frappedetect annotate=true ! tee`, one branch to a JPEG
encoder, the other through frappejson; the server keeps the newest of each.
  /                  the page: <img src=/video.mjpeg> and the markers' list (polls /markers.json)
  /video.mjpeg       multipart/x-mixed-replace; boundary=frame, one JPEG a frame
  /frame.jpg         the newest JPEG
  /markers.json      the newest frame's markers (frappe.stream.Frame's fields)
Needs Python's gi (python3-gi, gir1.2-gstreamer-1.0) and the frappedetect element.
"""

import argparse
import dataclasses
import json
import signal
import sys
import threading
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer

from . import stream

BOUNDARY = "frame"

PAGE = """<!doctype html>
<html><head><meta charset="utf-8"><title>frappe-watch</title>
<style>
body { margin: 0; font: 16px sans-serif; background: #222; color: #eee; }
#video { position: absolute; left: 0; top: 0; display: block; }
#side { position: absolute; left: %(side)dpx; top: 8px; }
#markers { list-style: none; padding: 0; font-family: monospace; }
</style></head>
<body>
<img id="video" src="/video.mjpeg" alt="the camera, annotated">
<div id="side"><div id="status">waiting for the first frame</div><ul id="markers"></ul></div>
<script>
function describe(m) {
  if (m.pose) {
    const t = m.pose.tvec, d = Math.hypot(t[0], t[1], t[2]);
    return `id ${m.id}: ${d.toFixed(3)} m (${t.map(v => v.toFixed(3)).join(", ")})`;
  }
  const c = m.corners, x = (c[0][0] + c[1][0] + c[2][0] + c[3][0]) / 4, y = (c[0][1] + c[1][1] + c[2][1] + c[3][1]) / 4;
  return `id ${m.id}: pixel (${x.toFixed(0)}, ${y.toFixed(0)})`;
}
async function update() {
  try {
    const f = await (await fetch("/markers.json", {cache: "no-store"})).json();
    if (f.number !== null) {
      document.getElementById("status").textContent = `frame ${f.number}: ${f.markers.length} markers`;
      const list = document.getElementById("markers");
      list.replaceChildren(...f.markers.map(m => {
        const li = document.createElement("li"); li.textContent = describe(m); return li; }));
    }
  } catch (e) {
    document.getElementById("status").textContent = "no answer from the robot";
  }
  setTimeout(update, 200);
}
update();
</script></body></html>
"""


class Latest:
    """The newest JPEG and markers; HTTP threads wait here for the next JPEG."""

    def __init__(self):
        self.cond = threading.Condition()
        self.jpeg, self.seq = None, 0
        self.markers = {"number": None, "markers": []}
        self.stopped = False

    def put_jpeg(self, data):
        with self.cond:
            self.jpeg, self.seq = data, self.seq + 1
            self.cond.notify_all()

    def next_jpeg(self, after, timeout=5.0):
        """(seq, jpeg) newer than `after`, or (after, None) when none came in time or the stream stopped."""
        with self.cond:
            self.cond.wait_for(lambda: self.seq > after or self.stopped, timeout)
            return (self.seq, self.jpeg) if self.seq > after else (after, None)

    def stop(self):
        with self.cond:
            self.stopped = True
            self.cond.notify_all()


def handler(latest, width):
    page = (PAGE % {"side": max(width, 320) + 16}).encode()

    class Handler(BaseHTTPRequestHandler):
        protocol_version = "HTTP/1.0"  # one answer a connection: the MJPEG answer ends when it closes

        def log_message(self, fmt, *args):  # quiet: a browser polls markers.json five times a second
            pass

        def send(self, kind, body):
            self.send_response(200)
            self.send_header("Content-Type", kind)
            self.send_header("Content-Length", str(len(body)))
            self.send_header("Cache-Control", "no-store")
            self.end_headers()
            self.wfile.write(body)

        def do_GET(self):
            path = self.path.split("?")[0]
            if path in ("/", "/index.html"):
                self.send("text/html; charset=utf-8", page)
            elif path == "/markers.json":
                with latest.cond:
                    body = json.dumps(latest.markers)
                self.send("application/json", body.encode())
            elif path == "/frame.jpg":
                seq, jpeg = latest.next_jpeg(0)
                if jpeg is None:
                    self.send_error(503, "no frame yet")
                else:
                    self.send("image/jpeg", jpeg)
            elif path == "/video.mjpeg":
                self.mjpeg()
            else:
                self.send_error(404)

        def mjpeg(self):
            self.send_response(200)
            self.send_header("Content-Type", f"multipart/x-mixed-replace; boundary={BOUNDARY}")
            self.send_header("Cache-Control", "no-store")
            self.end_headers()
            seq = 0
            try:
                while not latest.stopped:
                    seq, jpeg = latest.next_jpeg(seq)
                    if jpeg is None:
                        continue
                    self.wfile.write(f"--{BOUNDARY}\r\nContent-Type: image/jpeg\r\n"
                                     f"Content-Length: {len(jpeg)}\r\n\r\n".encode() + jpeg + b"\r\n")
                    self.wfile.flush()
            except (BrokenPipeError, ConnectionResetError):
                pass  # the viewer went away

    return Handler


def pipeline_description(args):
    source = args.source
    if args.file:
        source = f'filesrc location="{args.file}" ! decodebin'
    # identity sync=true: a file or imagefreeze plays at its frame rate, not as
    # fast as the CPU goes (a camera is paced already).
    return (f"{source} ! identity sync=true ! videoconvert ! video/x-raw,format={args.format} ! "
            f"frappedetect annotate=true {args.detect} ! tee name=t "
            f"t. ! queue leaky=downstream max-size-buffers=2 ! videoconvert ! {args.encoder} ! "
            "appsink name=jpeg emit-signals=true max-buffers=2 drop=true sync=false "
            "t. ! queue ! frappejson ! appsink name=json emit-signals=true sync=false")


def parser():
    p = argparse.ArgumentParser(prog="frappe-watch", description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter,
                                epilog="\n\n".join(__doc__.split("\n\n")[1:]))
    src = p.add_mutually_exclusive_group()
    src.add_argument("--source", default="v4l2src", metavar="PIPELINE",
                     help="GStreamer elements giving raw video (default: v4l2src)")
    src.add_argument("--file", metavar="PATH", help="a video or image file instead of a camera, at its own rate")
    p.add_argument("--loop", action="store_true", help="with --file: start again at the end")
    p.add_argument("--format", default="I420", help="the raw format frappedetect reads (default I420; NV12 on a Pi)")
    p.add_argument("--detect", default="", metavar="PROPERTIES",
                   help="frappedetect's properties, e.g. 'dictionary=apriltag_36h11 marker-size=0.05'")
    p.add_argument("--encoder", default="jpegenc quality=80", metavar="PIPELINE",
                   help="the JPEG encoder (default: jpegenc quality=80; v4l2jpegenc on a Pi)")
    p.add_argument("--width", type=int, default=640, help="the video's width on the page, for the layout (default 640)")
    p.add_argument("--port", type=int, default=8080, help="the HTTP port (default 8080)")
    p.add_argument("--bind", default="0.0.0.0", metavar="ADDRESS", help="the address to serve on (default: all)")
    return p


def main(argv=None):
    args = parser().parse_args(argv)
    try:
        import gi
        gi.require_version("Gst", "1.0")
        from gi.repository import GLib, Gst
    except (ImportError, ValueError) as e:
        print(f"frappe-watch: needs Python's GStreamer bindings (python3-gi, gir1.2-gstreamer-1.0): {e}",
              file=sys.stderr)
        return 1
    Gst.init(None)
    description = pipeline_description(args)
    try:
        pipeline = Gst.parse_launch(description)
    except GLib.Error as e:
        print(f"frappe-watch: {e.message}\n  pipeline: {description}", file=sys.stderr)
        return 1

    latest = Latest()
    markers = stream.Reassembler()

    def on_jpeg(sink):
        buf = sink.emit("pull-sample").get_buffer()
        latest.put_jpeg(buf.extract_dup(0, buf.get_size()))
        return Gst.FlowReturn.OK

    def on_json(sink):
        buf = sink.emit("pull-sample").get_buffer()
        for line in buf.extract_dup(0, buf.get_size()).split(b"\n"):
            try:
                frames = markers.add(line) if line.strip() else []
            except ValueError as e:
                print(f"frappe-watch: {e}", file=sys.stderr)
                frames = []
            for frame in frames:
                with latest.cond:
                    latest.markers = dataclasses.asdict(frame)
        return Gst.FlowReturn.OK

    pipeline.get_by_name("jpeg").connect("new-sample", on_jpeg)
    pipeline.get_by_name("json").connect("new-sample", on_json)

    loop = GLib.MainLoop()
    status = {"code": 0}

    def on_message(bus, message):
        if message.type == Gst.MessageType.ERROR:
            err, debug = message.parse_error()
            print(f"frappe-watch: {message.src.get_name()}: {err.message}\n{debug or ''}", file=sys.stderr)
            status["code"] = 1
            loop.quit()
        elif message.type == Gst.MessageType.WARNING:
            err, _ = message.parse_warning()
            print(f"frappe-watch: warning: {message.src.get_name()}: {err.message}", file=sys.stderr)
        elif message.type == Gst.MessageType.EOS:
            if args.loop and args.file:
                pipeline.seek_simple(Gst.Format.TIME, Gst.SeekFlags.FLUSH | Gst.SeekFlags.KEY_UNIT, 0)
            else:
                loop.quit()

    bus = pipeline.get_bus()
    bus.add_signal_watch()
    bus.connect("message", on_message)

    try:
        server = ThreadingHTTPServer((args.bind, args.port), handler(latest, args.width))
    except OSError as e:
        print(f"frappe-watch: cannot serve on {args.bind}:{args.port}: {e}", file=sys.stderr)
        return 1
    server.daemon_threads = True
    threading.Thread(target=server.serve_forever, daemon=True).start()
    if pipeline.set_state(Gst.State.PLAYING) == Gst.StateChangeReturn.FAILURE:
        # the bus holds the element's error: print it
        message = bus.timed_pop_filtered(0, Gst.MessageType.ERROR)
        if message:
            on_message(bus, message)
        else:
            print("frappe-watch: the pipeline cannot start", file=sys.stderr)
        return 1
    host = "localhost" if args.bind in ("0.0.0.0", "::") else args.bind
    print(f"frappe-watch: http://{host}:{server.server_address[1]}/", file=sys.stderr, flush=True)
    GLib.unix_signal_add(GLib.PRIORITY_DEFAULT, signal.SIGINT, loop.quit)
    GLib.unix_signal_add(GLib.PRIORITY_DEFAULT, signal.SIGTERM, loop.quit)
    loop.run()
    pipeline.set_state(Gst.State.NULL)
    latest.stop()
    server.shutdown()
    return status["code"]


if __name__ == "__main__":
    sys.exit(main())
