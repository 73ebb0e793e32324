# SPDX-License-Identifier: MIT
"""Each decoded video frame with its markers (docs/streaming.md).

The robot sends the annotated video and frappejson's marker lines in one
MPEG transport stream (examples/stream-markers.sh): the lines ride as KLV
packets beside the video, and on the host tsdemux gives a decoded frame and
the lines of that frame the same PTS, whatever the encoder, the payloader or
the network did to the timestamps. This module pairs them:

    from frappe.video import receive_ts
    for frame in receive_ts(port=5000):       # the robot's MPEG-TS over UDP
        print(frame.line["frame"], frame.image.shape, [m["id"] for m in frame.markers])

`Pairer` is the pairing alone, in pure Python (no GStreamer, no compiled
extension): give it frames and lines with a key both share (the demuxed PTS,
or the `frame` number) and it gives each frame back with its whole line,
its parts reassembled. `receive_ts()` runs the host's GStreamer pipeline
through Debian's python3-gi (tsdemux, h264parse and avdec_h264 from
gstreamer1.0-plugins-bad and gstreamer1.0-libav).
"""

import collections
import json

from .stream import _Pending

# The KLV key of frappejson's packets (src caps meta/x-klv).
KLV_KEY = b"frappe/markers/1"


def klv_lines(data):
    """The marker lines of frappejson's KLV packets in `data` (bytes): each
    one as a dict. Packets under other keys are skipped."""
    lines, at = [], 0
    while at + 17 <= len(data):
        key = data[at:at + 16]
        length, at = data[at + 16], at + 17
        if length & 0x80:  # BER long form: that many bytes of length
            n = length & 0x7F
            length, at = int.from_bytes(data[at:at + n], "big"), at + n
        value, at = data[at:at + length], at + length
        if key == KLV_KEY:
            lines.append(json.loads(value))
    return lines


class Paired:
    """A video frame and its line: `line` is the frame's whole line (the
    header of the marker line, docs/streaming.md, with the markers of all its
    parts), or None when its markers did not arrive whole."""

    __slots__ = ("key", "image", "line", "sample")

    def __init__(self, key, image, line, sample=None):
        self.key, self.image, self.line, self.sample = key, image, line, sample

    @property
    def markers(self):
        return self.line["markers"] if self.line else []

    @property
    def bundle(self):
        """The line's bundle pose (a dict: name, rvec, tvec,
        reprojection_error, used, rejected), None without one."""
        return self.line.get("bundle") if self.line else None

    def __repr__(self):
        n = len(self.line["markers"]) if self.line else None
        return f"Paired(key={self.key}, frame={self.line and self.line['frame']}, markers={n})"


class Pairer:
    """Pairs video frames with marker lines by a key both carry.

    add_frame(image, key) and add_line(line, key) return the frames now
    paired, in the order the frames came. A frame waits for its line's parts
    until `max_waiting` later frames came (then it comes out with line None,
    counted in `unpaired`); a line whose frame never comes is dropped after
    as many (counted in `orphans`). key defaults to the line's `frame`."""

    def __init__(self, max_waiting=30):
        self.max_waiting = max_waiting
        self._frames = collections.deque()  # (key, image, sample)
        self._lines = collections.OrderedDict()  # key -> _Pending
        self.unpaired = 0
        self.orphans = 0

    def add_line(self, line, key=None):
        if isinstance(line, (bytes, str)):
            line = json.loads(line)
        key = line["frame"] if key is None else key
        if key not in self._lines:
            self._lines[key] = _Pending(line)
            while len(self._lines) > self.max_waiting * 4:
                self._lines.popitem(last=False)
                self.orphans += 1
        self._lines[key].add(line)
        return self._drain()

    def add_frame(self, image, key, sample=None):
        self._frames.append((key, image, sample))
        return self._drain()

    def flush(self):
        """Every frame still waiting, with its line when whole."""
        return self._drain(everything=True)

    def _drain(self, everything=False):
        out = []
        while self._frames:
            key, image, sample = self._frames[0]
            line = self._lines.get(key)
            whole = line is not None and line.whole()
            if not whole and not everything and len(self._frames) <= self.max_waiting:
                break
            self._frames.popleft()
            self._lines.pop(key, None)
            self.unpaired += not whole
            out.append(Paired(key, image, line.merged() if whole else None, sample))
        return out


# The host's pipeline: the robot's MPEG-TS from UDP, the video decoded to
# `video_caps`, the KLV packets as they are; {source} and {decode} filled in.
HOST_PIPELINE = ("{source} ! tsdemux name=demux "
                 "demux. ! video/x-h264 ! queue ! {decode} ! videoconvert ! {video_caps} ! {then}"
                 "appsink name=video sync=false max-buffers={max_frames} drop={drop} "
                 "demux. ! meta/x-klv ! queue ! appsink name=klv sync=false")


# The packed formats receive_ts() gives, by their channels.
CHANNELS = {"GRAY8": 1, "BGR": 3, "RGB": 3, "BGRx": 4, "BGRA": 4, "RGBx": 4, "RGBA": 4}


def receive_ts(port=5000, address="0.0.0.0", source=None, decode="h264parse ! avdec_h264",
               video_caps="video/x-raw,format=BGR", then="", max_waiting=30, max_frames=0, timeout=None):
    """Yields a Paired for every decoded frame of the robot's MPEG-TS: its
    `image` a numpy array (height, width, channels) of `video_caps`, its
    `line` the frame's markers and times, `sample` the Gst.Sample. `source`
    replaces the UDP source (e.g. "filesrc location=robot.ts"); `decode`
    the decoder; `then` elements between the video caps and the appsink
    (e.g. "frappedetect ! ": the decoded frame's own markers in the
    sample's metas). `max_frames` > 0 keeps only that many decoded frames
    waiting for the caller, dropping the oldest (a program slower than the
    camera then sees the newest frames; a dropped frame's line is counted
    as an orphan); 0 keeps every frame. Stops at the end of the stream, or
    after `timeout` seconds without a frame (an EOS then pushes out the
    frame the demuxer still holds)."""
    import gi
    gi.require_version("Gst", "1.0")
    from gi.repository import Gst
    import numpy as np

    Gst.init(None)
    if Gst.Caps.from_string(video_caps).get_structure(0).get_value("format") not in CHANNELS:
        raise ValueError(f"video_caps {video_caps}: a format of {', '.join(CHANNELS)}")
    if source is None:
        source = (f"udpsrc address={address} port={port} buffer-size=4194304 "
                  "caps=video/mpegts,systemstream=true,packetsize=188")
    pipeline = Gst.parse_launch(HOST_PIPELINE.format(source=source, decode=decode, video_caps=video_caps, then=then,
                                                     max_frames=max_frames, drop=str(max_frames > 0).lower()))
    video, klv = pipeline.get_by_name("video"), pipeline.get_by_name("klv")
    # Playing (the socket bound) before the first frame is asked for.
    pipeline.set_state(Gst.State.PLAYING)
    return _paired_frames(Gst, np, pipeline, video, klv, Pairer(max_waiting), timeout)


def _paired_frames(Gst, np, pipeline, video, klv, pairer, timeout):
    waited, step, flushed = 0.0, 0.05, 0.0
    try:
        while True:
            sample = video.emit("try-pull-sample", int(step * Gst.SECOND))
            out = []
            while True:
                k = klv.emit("try-pull-sample", 0)
                if k is None:
                    break
                buf = k.get_buffer()
                for line in klv_lines(buf.extract_dup(0, buf.get_size())):
                    out += pairer.add_line(line, key=buf.pts)
            if sample is not None:
                waited = 0.0
                out += pairer.add_frame(_image(np, sample), sample.get_buffer().pts, sample)
            yield from out
            if sample is None:
                waited += step
                if video.get_property("eos") or (flushed and waited >= flushed + 5):
                    break
                if timeout is not None and waited >= timeout and not flushed:
                    # The sender is silent: an EOS pushes out what the
                    # demuxer holds (its last frame ends at the next packet).
                    pipeline.send_event(Gst.Event.new_eos())
                    flushed = waited
        yield from pairer.flush()
    finally:
        pipeline.set_state(Gst.State.NULL)


def _image(np, sample):
    """A sample's packed frame as a (height, width, channels) array."""
    buf, caps = sample.get_buffer(), sample.get_caps().get_structure(0)
    w, h = caps.get_value("width"), caps.get_value("height")
    c = CHANNELS[caps.get_value("format")]
    image = np.frombuffer(buf.extract_dup(0, buf.get_size()), np.uint8)
    stride = image.size // h  # rows may be padded
    return image[:stride * h].reshape(h, stride)[:, :w * c].reshape(h, w, c)
