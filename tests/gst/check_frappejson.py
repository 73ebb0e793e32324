#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The sample video through frappedetect with the sample's calibration file
and frappejson into a file: 120 frames numbered 0 to 119, each in parts of
at most 1400 bytes (the default max-bytes), each line one JSON object with
the keys of the marker line ending in a newline, in PTS order, with markers
0, 7, 23 and 42, and marker 0 at
z = 0.27 m and marker 42 at 0.26 m within 1 % (the sample is rendered
through a 700 px pinhole with 5 cm markers). Exit 77 when the sample's
decoder plugins are missing."""
import json
import os
import subprocess
import sys
import tempfile

DEPTH = {0: 0.27, 42: 0.26}
# The marker line's keys, in order (gst/gstfrappejson.cpp, docs/streaming.md).
KEYS = ["frame", "part", "parts", "pts", "running_time", "width", "height", "frame_id", "capture_time",
        "capture_clock", "markers"]


def main():
    launch, video, calibration = sys.argv[1:4]
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "markers.jsonl")
        p = subprocess.run([launch, "-q", "filesrc", f"location={video}", "!", "decodebin", "!", "videoconvert",
                            "!", "frappedetect", "marker-size=0.05", f"calibration-file={calibration}", "!",
                            "frappejson", "!", "filesink", f"location={out}"],
                           capture_output=True, text=True, timeout=120)
        if p.returncode != 0:
            print(p.stdout + p.stderr)
            if "no element" in p.stderr or "missing" in p.stderr.lower():
                return 77
            return 1
        with open(out, "rb") as f:
            data = f.read().decode("utf-8")
    lines = data.split("\n")
    if lines[-1] != "":
        print("the output does not end in a newline")
        return 1
    lines = lines[:-1]
    # Each frame in parts of at most 1400 bytes (4 posed markers do not fit
    # in one), numbered from 0, in order; every part repeats the header.
    frames = []
    for i, line in enumerate(lines):
        if len(line.encode("utf-8")) + 1 > 1400:
            print(f"line {i}: {len(line) + 1} bytes, more than max-bytes")
            return 1
        d = json.loads(line)  # raises on anything but one JSON value
        if not isinstance(d, dict) or list(d) != KEYS:
            print(f"line {i}: keys {list(d)}")
            return 1
        if d["part"] == 1:
            frames.append(dict(d, markers=[]))
        f = frames[-1]
        header = {k: v for k, v in d.items() if k not in ("part", "markers")}
        if header != {k: v for k, v in f.items() if k not in ("part", "markers")} or d["part"] != f["part"]:
            print(f"line {i}: part {d['part']} of {d['parts']} out of place after part {f['part']} of frame {f}")
            return 1
        f["part"] = d["part"] + 1
        f["markers"] += d["markers"]
    if len(frames) != 120 or any(f["part"] != f["parts"] + 1 for f in frames):
        print(f"expected 120 whole frames, got {len(frames)}")
        return 1
    worst, last = 0.0, -1
    for i, d in enumerate(frames):
        if d["frame"] != i or (d["width"], d["height"], d["frame_id"]) != (640, 480, "camera"):
            print(f"frame {i}: {d}")
            return 1
        if not isinstance(d["pts"], int) or d["pts"] <= last or d["running_time"] != d["pts"]:
            print(f"frame {i}: pts {d['pts']} after {last}")
            return 1
        last = d["pts"]
        ids = sorted(m["id"] for m in d["markers"])
        if ids != [0, 7, 23, 42]:
            print(f"frame {i}: ids {ids}")
            return 1
        for m in d["markers"]:
            if m["dictionary"] != "aruco_mip_36h12" or len(m["corners"]) != 4 or "tvec" not in m:
                print(f"frame {i}: marker {m}")
                return 1
            if m["id"] in DEPTH:
                worst = max(worst, abs(m["tvec"][2] - DEPTH[m["id"]]) / DEPTH[m["id"]])
    print(f"frappejson: 120 frames in {len(lines)} lines; worst depth error of markers 0 and 42 {100 * worst:.3f} %")
    return 0 if worst < 0.01 else 1


if __name__ == "__main__":
    sys.exit(main())
