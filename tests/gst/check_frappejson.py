#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The sample video through frappedetect with the sample's calibration file
and frappejson into a file: 120 lines, each one JSON object ending in a
newline, in PTS order, with markers 0, 7, 23 and 42, and marker 0 at
z = 0.27 m and marker 42 at 0.26 m within 1 % (the sample is rendered
through a 700 px pinhole with 5 cm markers). Exit 77 when the sample's
decoder plugins are missing."""
import json
import os
import subprocess
import sys
import tempfile

DEPTH = {0: 0.27, 42: 0.26}


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
    if len(lines) != 120:
        print(f"expected 120 lines, got {len(lines)}")
        return 1
    worst, last = 0.0, -1
    for i, line in enumerate(lines):
        d = json.loads(line)  # raises on anything but one JSON value
        if not isinstance(d, dict) or sorted(d) != ["markers", "pts"]:
            print(f"line {i}: keys {sorted(d)}")
            return 1
        if not isinstance(d["pts"], int) or d["pts"] <= last:
            print(f"line {i}: pts {d['pts']} after {last}")
            return 1
        last = d["pts"]
        ids = sorted(m["id"] for m in d["markers"])
        if ids != [0, 7, 23, 42]:
            print(f"line {i}: ids {ids}")
            return 1
        for m in d["markers"]:
            if m["dictionary"] != "aruco_mip_36h12" or len(m["corners"]) != 4 or "tvec" not in m:
                print(f"line {i}: marker {m}")
                return 1
            if m["id"] in DEPTH:
                worst = max(worst, abs(m["tvec"][2] - DEPTH[m["id"]]) / DEPTH[m["id"]])
    print(f"frappejson: 120 lines; worst depth error of markers 0 and 42 {100 * worst:.3f} %")
    return 0 if worst < 0.01 else 1


if __name__ == "__main__":
    sys.exit(main())
