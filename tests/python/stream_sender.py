# SPDX-License-Identifier: MIT
# tests/python/stream_sender.py: a fake robot for frappe.stream's tests: the
# marker lines frappejson writes (streaming.md in the docs, "The marker line"), split
# into parts, sent over UDP or served by a TCP server that can start late and
# restart. Pure Python.
import json
import socket
import threading


def marker(i, pose=True):
    """Marker i: id i, corners around (10 i, 20), a pose at z = 1 + i / 1000."""
    m = {"id": i, "dictionary": "aruco_mip_36h12",
         "corners": [[10.0 * i, 20.0], [10.0 * i + 5, 20.0], [10.0 * i + 5, 25.0], [10.0 * i, 25.0]],
         "hamming": i % 3, "margin": 0.5}
    if pose:
        m.update(rvec=[0.1, 0.2, 0.3], tvec=[0.01 * i, -0.02, 1 + i / 1000], reprojection_error=0.01,
                 alternative_reprojection_error=None)
    return m


def frame_lines(number, markers, parts=1, pts=None, bundle=None):
    """The lines of one frame: its markers split in order over `parts` lines,
    each with the whole header (and `bundle`, a frame field, when given)."""
    pts = number * 33_333_333 if pts is None else pts
    chunks = [markers[k * len(markers) // parts:(k + 1) * len(markers) // parts] for k in range(parts)]
    out = []
    for k, chunk in enumerate(chunks, 1):
        line = {"frame": number, "part": k, "parts": parts, "pts": pts, "running_time": pts, "width": 640,
                "height": 480, "frame_id": "camera", "capture_time": 1_700_000_000_000_000_000 + pts,
                "capture_clock": "pipeline"}
        if bundle is not None:
            line["bundle"] = bundle
        line["markers"] = chunk
        out.append(json.dumps(line) + "\n")
    return out


def send_udp(port, lines):
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    for line in lines:
        s.sendto(line.encode(), ("127.0.0.1", port))
    s.close()


class Robot:
    """A TCP server on `port` serving the lines of frames start..stop-1
    (two markers each) to each client that connects, then closing; `start()`
    may come after a client already tries to connect."""

    def __init__(self, port, frames, cut_last_line=False):
        self.port, self.frames, self.cut = port, frames, cut_last_line
        self.listener = None
        self.thread = None

    def start(self):
        self.listener = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        self.listener.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        self.listener.bind(("127.0.0.1", self.port))
        self.listener.listen(1)
        self.thread = threading.Thread(target=self._serve, daemon=True)
        self.thread.start()
        return self

    def _serve(self):
        conn, _ = self.listener.accept()
        data = "".join(line for n in self.frames for line in frame_lines(n, [marker(n), marker(n + 1)]))
        if self.cut:  # the robot dies in the middle of a line
            data += frame_lines(self.frames[-1] + 1, [marker(0)])[0][:30]
        conn.sendall(data.encode())
        conn.close()
        self.listener.close()

    def join(self):
        self.thread.join(10)


def free_port(kind=socket.SOCK_STREAM):
    s = socket.socket(socket.AF_INET, kind)
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port
