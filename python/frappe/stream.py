# SPDX-License-Identifier: MIT
"""The host's side of a robot's marker stream: `frappejson`'s lines read from
UDP or TCP, put back together into whole frames of typed markers.

    from frappe import stream
    with stream.tcp("robot.local", 5001) as markers:      # or stream.udp(5001)
        for frame in markers:
            for m in frame.markers:
                print(frame.number, m.id, m.pose.tvec if m.pose else m.center)
    print(markers.stats)          # frames, lost, restarts, reconnects, ...

Python's standard library only: this module imports without the compiled
detector (frappe._frappe) and without GStreamer.

The line format (streaming.md in the docs, "The marker line"): one JSON object a line,
`frame` counting every buffer since the robot's pipeline started, `part` k of
`parts` n when one frame's markers take several lines (each repeats the frame's
header; a marker is whole in one part). Rules of reassembly, which the tests
(tests/python/test_stream.py) hold:

* the parts of a frame may arrive in any order; the frame is delivered when its
  last part arrives;
* frames are delivered in increasing `frame` order: when frame N is delivered,
  an earlier frame still missing parts is given up, and a part arriving for a
  frame at or before N later is dropped (`Stats.late`);
* a frame given up is lost: not delivered at all, unless the receiver was made
  with `incomplete=True`, which delivers it with the markers that arrived and
  `Frame.complete` False (`Stats.incomplete`);
* `Stats.lost` counts the frame numbers never delivered between two delivered
  frames, so frames dropped by the robot (a leaky queue), the network or a
  given-up frame all count. Frames before the first one received do not;
* a robot that restarts counts from 0 again: a frame number below the last
  delivered one is a restart (`Stats.restarts`, nothing counted lost) when it
  is 0 or more than `reorder` frames back; otherwise it is a late part;
* a new TCP connection counts afresh: what the robot sent while the host was
  not connected is not counted lost (`Stats.reconnects` says it happened),
  and a first frame numbered below the last one is a restart;
* old lines without `frame` (frappejson before the time base) are whole frames
  numbered by arrival; no loss can be counted for them.
"""

from __future__ import annotations

import json
import math
import select
import socket
import time
from dataclasses import dataclass, field
from typing import Iterator, List, Optional, Tuple

__all__ = ["Pose", "Marker", "BundlePose", "Frame", "Stats", "Reassembler", "Receiver", "udp", "tcp", "open_url",
           "parse_line"]

#: How far back (frames) a frame number may be and still be a late part rather
#: than a restart of the robot's pipeline.
REORDER = 8


@dataclass
class Pose:
    """A marker's pose in the camera frame (OpenCV's: x right, y down, z
    forward; metres, as the robot's `marker-size`): `rvec` a Rodrigues
    rotation, `tvec` the marker centre; the RMS reprojection error of this
    solution and of the other one a square allows (None when unknown)."""
    rvec: Tuple[float, float, float]
    tvec: Tuple[float, float, float]
    reprojection_error: Optional[float] = None
    alternative_reprojection_error: Optional[float] = None

    @property
    def distance(self) -> float:
        """Metres from the camera to the marker centre."""
        return math.sqrt(sum(v * v for v in self.tvec))


@dataclass
class Marker:
    """One marker of a frame: corners in pixels (top-left, top-right,
    bottom-right, bottom-left of the black border, the marker upright),
    `pose` None when the robot knows no camera or marker size; `tracked`
    None unless the robot runs mode=track, then whether the marker continued
    a track of the last frames (False: found afresh)."""
    id: int
    dictionary: str
    corners: List[Tuple[float, float]]
    hamming: Optional[int] = None
    margin: Optional[float] = None
    pose: Optional[Pose] = None
    tracked: Optional[bool] = None

    @property
    def center(self) -> Tuple[float, float]:
        """The mean of the four corners, pixels."""
        return (sum(c[0] for c in self.corners) / len(self.corners),
                sum(c[1] for c in self.corners) / len(self.corners))


@dataclass
class BundlePose:
    """One pose from every marker of a bundle seen in the frame (the robot's
    `bundle-file`: a board, apriltag_ros's bundle): the bundle frame in the
    camera frame (`rvec` a Rodrigues rotation, `tvec` its origin, metres),
    the RMS reprojection error over the corners `used` (pixels), the ids
    whose corners made it and the ids `rejected` as outliers (a marker
    moved, a wrong read)."""
    name: str
    rvec: Tuple[float, float, float]
    tvec: Tuple[float, float, float]
    reprojection_error: Optional[float]
    used: List[int]
    rejected: List[int]

    @property
    def distance(self) -> float:
        """Metres from the camera to the bundle frame's origin."""
        return math.sqrt(sum(v * v for v in self.tvec))


@dataclass
class Frame:
    """One camera frame's markers. Times in nanoseconds: `pts` and
    `running_time` of the robot's pipeline, `capture_time` since the Unix
    epoch with `capture_clock` "reference" (the source's own clock) or
    "pipeline" (the pipeline clock's estimate); None when the line has none.
    `bundle` the bundle's pose, None when the robot has no bundle-file or
    did not see it. `received` is the host's time.time() when the frame was
    delivered."""
    number: int
    markers: List[Marker]
    pts: Optional[int] = None
    running_time: Optional[int] = None
    capture_time: Optional[int] = None
    capture_clock: Optional[str] = None
    width: Optional[int] = None
    height: Optional[int] = None
    frame_id: Optional[str] = None
    complete: bool = True
    parts: int = 1
    received: float = 0.0
    bundle: Optional[BundlePose] = None


@dataclass
class Stats:
    """What a receiver saw: `frames` delivered (of which `incomplete` with
    parts missing), `lost` frame numbers never delivered, `late` parts
    dropped, `restarts` of the robot's numbering, `reconnects` of TCP,
    `bad_lines` that were not a marker line."""
    frames: int = 0
    lost: int = 0
    incomplete: int = 0
    late: int = 0
    restarts: int = 0
    reconnects: int = 0
    bad_lines: int = 0


def _floats(values) -> Tuple[float, ...]:
    return tuple(float(v) for v in values)


def _marker(m: dict) -> Marker:
    pose = None
    if m.get("rvec") is not None and m.get("tvec") is not None:
        pose = Pose(_floats(m["rvec"]), _floats(m["tvec"]), m.get("reprojection_error"),
                    m.get("alternative_reprojection_error"))
    return Marker(id=int(m["id"]), dictionary=m.get("dictionary", ""),
                  corners=[(float(x), float(y)) for x, y in m["corners"]], hamming=m.get("hamming"),
                  margin=m.get("margin"), pose=pose, tracked=m.get("tracked"))


def _bundle(b: Optional[dict]) -> Optional[BundlePose]:
    if b is None:
        return None
    return BundlePose(name=b.get("name", ""), rvec=_floats(b["rvec"]), tvec=_floats(b["tvec"]),
                      reprojection_error=b.get("reprojection_error"), used=[int(i) for i in b.get("used", [])],
                      rejected=[int(i) for i in b.get("rejected", [])])


def parse_line(line) -> dict:
    """One line (bytes or str) as a dict with the markers and the bundle
    (None when the line has none) typed; ValueError when it is not a marker
    line. The old form without `frame` gets frame None, part 1 of 1."""
    obj = json.loads(line)
    if not isinstance(obj, dict) or not isinstance(obj.get("markers"), list):
        raise ValueError("not a marker line (no \"markers\" list)")
    obj["markers"] = [_marker(m) for m in obj["markers"]]
    obj["bundle"] = _bundle(obj.get("bundle"))
    obj.setdefault("frame", None)
    part, parts = int(obj.get("part", 1)), int(obj.get("parts", 1))
    if not 1 <= part <= parts:
        raise ValueError(f"part {part} of {parts}")
    obj["part"], obj["parts"] = part, parts
    return obj


class _Pending:
    """The parts of one frame's line received so far, in any order (also
    frappe.video's pairing of lines with video frames)."""

    def __init__(self, header: dict):
        self.header = header
        self.parts = {}

    def add(self, part: dict):
        self.parts[part["part"]] = part["markers"]

    def whole(self) -> bool:
        return len(self.parts) == self.header["parts"]

    def markers(self) -> list:
        return [m for k in sorted(self.parts) for m in self.parts[k]]

    def merged(self) -> dict:
        """The whole line: the header with every part's markers."""
        header = {k: v for k, v in self.header.items() if k != "part"}
        return dict(header, markers=self.markers())

    def frame(self, number: int) -> Frame:
        h = self.header
        return Frame(number=number, markers=self.markers(), pts=h.get("pts"), running_time=h.get("running_time"),
                     capture_time=h.get("capture_time"), capture_clock=h.get("capture_clock"),
                     width=h.get("width"), height=h.get("height"), frame_id=h.get("frame_id"),
                     complete=self.whole(), parts=h["parts"], received=time.time(),
                     bundle=h.get("bundle"))


class Reassembler:
    """Parts in, whole frames out, by the rules of the module's docstring.
    `add(line)` returns the frames it completes (often none, sometimes an
    earlier incomplete one too, in order); `flush()` gives up what is
    pending (at the end of a stream)."""

    def __init__(self, incomplete: bool = False, reorder: int = REORDER):
        self.incomplete = incomplete
        self.reorder = reorder
        self.stats = Stats()
        self._pending = {}  # frame number -> _Pending
        self._last = None  # the last frame number delivered (or given up)
        self._arrivals = 0  # numbers for lines of the old form
        self._new_stream = False

    def new_stream(self):
        """A new connection: the next frame may be numbered from 0 again
        without that being a late part. Returns the frames given up."""
        self._new_stream = True
        return self._give_up(None)

    def add(self, line) -> List[Frame]:
        try:
            part = parse_line(line)
        except (ValueError, KeyError, TypeError, IndexError) as e:
            self.stats.bad_lines += 1
            raise ValueError(f"bad marker line ({e}): {line[:80]!r}") from None
        number = part["frame"]
        if number is None:  # the old form: whole, numbered by arrival
            self._arrivals += 1
            pending = _Pending(dict(part, parts=1))
            pending.add(part)
            return [self._deliver(pending.frame(self._arrivals - 1), count_gap=False)]
        number = int(number)
        out = []
        if self._new_stream:  # a new connection counts afresh
            if self._last is not None and number <= self._last:
                self.stats.restarts += 1
            self._last, self._new_stream = None, False
        elif self._last is not None and number <= self._last and number not in self._pending:
            if number == 0 or self._last - number > self.reorder:
                self.stats.restarts += 1
                out += self._give_up(None)
                self._last = None
            else:
                self.stats.late += 1
                return out
        pending = self._pending.get(number)
        if pending is None:
            pending = self._pending[number] = _Pending(part)
        pending.add(part)
        if pending.whole():
            out += self._give_up(number)
            del self._pending[number]
            out.append(self._deliver(pending.frame(number)))
        return out

    def flush(self) -> List[Frame]:
        """Gives up every pending frame (end of stream)."""
        return self._give_up(None)

    def _give_up(self, before: Optional[int]) -> List[Frame]:
        """Ends the pending frames numbered below `before` (all when None):
        delivered flagged incomplete, or lost."""
        out = []
        for number in sorted(n for n in self._pending if before is None or n < before):
            pending = self._pending.pop(number)
            if self.incomplete:
                self.stats.incomplete += 1
                out.append(self._deliver(pending.frame(number)))
            else:  # lost, with any gap before it
                self.stats.lost += number - self._last if self._last is not None else 1
                self._last = number
        return out

    def _deliver(self, frame: Frame, count_gap: bool = True) -> Frame:
        if count_gap and self._last is not None and frame.number > self._last + 1:
            self.stats.lost += frame.number - self._last - 1
        if count_gap:
            self._last = frame.number
        self.stats.frames += 1
        return frame


class Receiver:
    """Frames from a socket: iterate it (forever, or until `close()`), or
    `read(timeout)` one frame (None when none came in time); `frames(timeout)`
    iterates until no frame came for `timeout` seconds. Made by `udp()`,
    `tcp()` or `open_url()`."""

    def __init__(self, transport, incomplete: bool = False, reorder: int = REORDER):
        self._transport = transport
        self._reassembler = Reassembler(incomplete=incomplete, reorder=reorder)
        self._ready = []  # frames completed, not yet read
        self.errors = []  # the last few bad lines, for a log

    @property
    def stats(self) -> Stats:
        s = self._reassembler.stats
        s.reconnects = getattr(self._transport, "reconnects", 0)
        return s

    @property
    def address(self) -> str:
        return self._transport.describe()

    def read(self, timeout: Optional[float] = None) -> Optional[Frame]:
        """The next frame, or None when none is complete after `timeout`
        seconds (None: wait for ever)."""
        deadline = None if timeout is None else time.monotonic() + timeout
        while not self._ready:
            left = None if deadline is None else deadline - time.monotonic()
            if left is not None and left <= 0:
                return None
            for line in self._transport.lines(left) or ():
                if line is _NEW_STREAM:
                    self._ready += self._reassembler.new_stream()
                    continue
                if not line.strip():
                    continue
                try:
                    self._ready += self._reassembler.add(line)
                except ValueError as e:
                    self.errors = (self.errors + [str(e)])[-10:]
        return self._ready.pop(0)

    def frames(self, timeout: Optional[float] = None) -> Iterator[Frame]:
        """Frames until none came for `timeout` seconds (None: for ever) or
        the stream ended (a TCP receiver that does not reconnect); then the
        frames still missing parts are given up (`flush()`)."""
        while True:
            try:
                frame = self.read(timeout)
            except EOFError:
                frame = None
            if frame is None:
                yield from self.flush()
                return
            yield frame

    def flush(self) -> List[Frame]:
        """Gives up the frames still missing parts: lost, or returned flagged
        incomplete (`incomplete=True`)."""
        out, self._ready = self._ready + self._reassembler.flush(), []
        return out

    def __iter__(self) -> Iterator[Frame]:
        return self.frames(None)

    def close(self):
        self._transport.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


# A marker the transports put among the lines: a new TCP connection began.
_NEW_STREAM = object()


class _Udp:
    """A bound UDP socket: each datagram holds one or more whole lines."""

    def __init__(self, port: int, host: str):
        self.sock = socket.socket(socket.AF_INET6 if ":" in host else socket.AF_INET, socket.SOCK_DGRAM)
        # A frame split in many parts comes as a burst: room for it.
        self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4 << 20)
        self.sock.bind((host, port))
        self.sock.setblocking(False)

    def describe(self):
        host, port = self.sock.getsockname()[:2]
        return f"udp {host}:{port}"

    def lines(self, timeout):
        if not select.select([self.sock], [], [], timeout)[0]:
            return None
        out = []
        while True:  # everything queued, so a frame's parts are reassembled at once
            try:
                data = self.sock.recv(65536)
            except (BlockingIOError, InterruptedError):
                return out
            out += data.split(b"\n")

    def close(self):
        self.sock.close()


class _Tcp:
    """A TCP client of tcpserversink that connects again, with back-off from
    `backoff[0]` doubling to `backoff[1]` seconds, when the robot is not up
    yet or goes away; a line cut by a lost connection is dropped."""

    def __init__(self, host: str, port: int, backoff=(0.1, 2.0), reconnect: bool = True, log=None):
        self.host, self.port = host, port
        self.log = log or (lambda text: None)
        self.backoff, self.reconnect = backoff, reconnect
        self.sock = None
        self.pending = b""
        self.delay = backoff[0]
        self.next_try = 0.0
        self.connections = 0
        self.reconnects = 0
        self.closed = False
        self.last_error = None

    def describe(self):
        return f"tcp {self.host}:{self.port}"

    def _connect(self, deadline):
        """Connects once the back-off allows it; False when not before `deadline`."""
        while True:
            now = time.monotonic()
            wait = self.next_try - now
            if wait > 0:
                if deadline is not None and now + wait > deadline:
                    time.sleep(max(0.0, deadline - now))
                    return False
                time.sleep(wait)
            try:
                left = None if deadline is None else max(0.05, deadline - time.monotonic())
                self.sock = socket.create_connection((self.host, self.port),
                                                     timeout=min(left or 5.0, 5.0))
                self.sock.setblocking(False)
                self.delay = self.backoff[0]
                self.log(f"connected to {self.describe()}")
                if self.connections:
                    self.reconnects += 1
                self.connections += 1
                return True
            except OSError as e:
                if self.last_error is None or type(e) is not type(self.last_error):
                    self.log(f"{self.describe()}: {e.strerror or e}; trying again")
                self.last_error = e
                self.next_try = time.monotonic() + self.delay
                self.delay = min(self.delay * 2, self.backoff[1])
                if deadline is not None and time.monotonic() >= deadline:
                    return False

    def lines(self, timeout):
        deadline = None if timeout is None else time.monotonic() + timeout
        out = []
        if self.sock is None:
            if self.closed or (self.connections and not self.reconnect):
                raise EOFError(f"{self.describe()}: connection closed")
            if not self._connect(deadline):
                return None
            out.append(_NEW_STREAM)
        left = None if deadline is None else max(0.0, deadline - time.monotonic())
        if not select.select([self.sock], [], [], left)[0]:
            return out or None
        try:
            data = self.sock.recv(1 << 16)
        except (BlockingIOError, InterruptedError):
            return out
        except OSError as e:
            data, self.last_error = b"", e
        if not data:  # the robot went away: connect again, from a clean line
            self.log(f"{self.describe()}: connection closed")
            self.last_error = None
            self.sock.close()
            self.sock, self.pending = None, b""
            self.next_try = time.monotonic() + self.delay
            return out
        *complete, self.pending = (self.pending + data).split(b"\n")
        return out + complete

    def close(self):
        self.closed = True
        if self.sock is not None:
            self.sock.close()
            self.sock = None


def udp(port: int, host: str = "0.0.0.0", **options) -> Receiver:
    """Receives `udpsink host=THIS_HOST port=PORT` on `host`:`port`."""
    return Receiver(_Udp(port, host), **options)


def tcp(host: str, port: int, backoff=(0.1, 2.0), reconnect: bool = True, log=None, **options) -> Receiver:
    """Connects to the robot's `tcpserversink port=PORT`, again whenever it
    is not there; with `reconnect=False`, iterating ends (EOFError from
    read) when the first connection closes. `log(text)`, when given, hears
    of each connection, its end, and a new reason for a refusal."""
    return Receiver(_Tcp(host, port, backoff, reconnect, log), **options)


def open_url(url: str, **options) -> Receiver:
    """`udp://[HOST]:PORT` (HOST the address to listen on) or
    `tcp://HOST:PORT` (the robot)."""
    scheme, sep, rest = url.partition("://")
    host, _, port = rest.rpartition(":")
    if not sep or scheme not in ("udp", "tcp") or not port.isdigit():
        raise ValueError(f"{url!r}: expected udp://[HOST]:PORT or tcp://HOST:PORT")
    host = host.strip("[]")
    if scheme == "udp":
        return udp(int(port), host or "0.0.0.0", **options)
    return tcp(host or "127.0.0.1", int(port), **options)
