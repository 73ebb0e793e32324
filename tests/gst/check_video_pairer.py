#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""python/frappe/video.py's pairing alone, in pure Python (no GStreamer,
no compiled module): a frame's parts in any order, before or after the
frame; a frame whose line lost a part comes out with line None after
max_waiting later frames, in order; a line without its frame is dropped;
frappejson's KLV packets read back (short and long BER lengths, other keys
skipped)."""
import importlib
import json
import os
import sys


def load(path):
    """python/frappe/video.py as frappe.video, imported from its source
    folder: the package imports without the compiled extension."""
    sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(path))))
    return importlib.import_module("frappe.video")


def line(frame, part, parts, ids):
    return {"frame": frame, "part": part, "parts": parts, "pts": 1000 * frame, "running_time": None,
            "width": 640, "height": 480, "frame_id": "camera", "capture_time": None, "capture_clock": None,
            "markers": [{"id": i} for i in ids]}


def check(condition, what):
    if not condition:
        raise AssertionError(what)


def main():
    video = load(sys.argv[1])
    p = video.Pairer(max_waiting=2)
    # Frame 0: parts 2 then 1, after its frame; frame 1: its line first.
    check(p.add_frame("image0", 0) == [], "frame 0 waits for its line")
    check(p.add_line(line(0, 2, 2, [5, 6])) == [], "part 2 of 2 is not whole")
    out = p.add_line(json.dumps(line(0, 1, 2, [3, 4])))
    check([(o.image, [m["id"] for m in o.markers]) for o in out] == [("image0", [3, 4, 5, 6])],
          f"frame 0 whole, its markers in part order: {out}")
    check("part" not in out[0].line and out[0].line["parts"] == 2 and out[0].line["pts"] == 0, out[0].line)
    check(p.add_line(line(1, 1, 1, [])) == [], "a line waits for its frame")
    out = p.add_frame("image1", 1)
    check([(o.key, o.markers) for o in out] == [(1, [])], f"frame 1 with no markers: {out}")

    # Frame 2 loses part 2: it waits while 2 frames come after it, then
    # comes out unpaired, before frame 3, which was whole first.
    p.add_line(line(2, 1, 2, [1]))
    p.add_frame("image2", 2)
    p.add_line(line(3, 1, 1, [9]))
    check(p.add_frame("image3", 3) == [], "frame 3 waits behind frame 2")
    p.add_line(line(4, 1, 1, [8]))
    out = p.add_frame("image4", 4)
    check([(o.key, o.line is None) for o in out] == [(2, True), (3, False), (4, False)], f"in order: {out}")
    check(p.unpaired == 1, p.unpaired)
    # Lines whose frames never come are dropped beyond 4 * max_waiting.
    for f in range(10, 30):
        p.add_line(line(f, 1, 1, []))
    check(p.orphans == 20 - 8, f"orphans {p.orphans}")
    check(p.flush() == [], "nothing waits")

    # The bundle, a frame field in every part, stays in the merged line.
    bundle = {"name": "board", "rvec": [0.1, 0.2, 0.3], "tvec": [0.0, 0.0, 1.0], "reprojection_error": 0.1,
              "used": [1, 2], "rejected": []}
    p.add_frame("image40", 40)
    p.add_line(dict(line(40, 2, 2, [2]), bundle=bundle))
    out = p.add_line(dict(line(40, 1, 2, [1]), bundle=bundle))
    check([(o.key, o.bundle, [m["id"] for m in o.markers]) for o in out] == [(40, bundle, [1, 2])],
          f"frame 40 with its bundle: {out}")
    p.add_frame("image41", 41)
    out = p.add_line(line(41, 1, 1, []))
    check([(o.key, o.bundle) for o in out] == [(41, None)], f"frame 41 without: {out}")

    # By any key: the demuxed PTS.
    p = video.Pairer()
    p.add_line(line(7, 1, 1, [42]), key=123456)
    out = p.add_frame("image", 123456)
    check(len(out) == 1 and out[0].line["frame"] == 7, f"by PTS: {out}")

    # KLV: frappejson's key, BER short and long forms, another key skipped.
    short = b'{"frame": 0, "part": 1, "parts": 1, "markers": []}\n'
    long_ = json.dumps(line(1, 1, 1, list(range(40)))).encode() + b"\n"
    check(len(short) < 128 < 256 < len(long_) < 65536, (len(short), len(long_)))
    data = (video.KLV_KEY + bytes([len(short)]) + short + b"\x06\x0e\x2b\x34" + b"\x00" * 12 + b"\x02ab" +
            video.KLV_KEY + b"\x82" + len(long_).to_bytes(2, "big") + long_)
    lines = video.klv_lines(data)
    check([l["frame"] for l in lines] == [0, 1] and len(lines[1]["markers"]) == 40, lines)
    print("1 passed, 0 failed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
