#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Runs examples/frappe-json on the shipped sample video: every frame must
give one meta line and one message line, with the same four markers."""
import json
import subprocess
import sys


def main():
    exe, video = sys.argv[1], sys.argv[2]
    p = subprocess.run([exe, video], capture_output=True, text=True, timeout=120)
    if p.returncode != 0:
        if "no element" in p.stderr or "missing" in p.stderr.lower():
            print(p.stderr)
            return 77  # decoder plugins not installed
        print(p.stderr)
        return 1
    meta, msg = [], []
    for line in p.stdout.splitlines():
        d = json.loads(line)
        (meta if d["source"] == "meta" else msg).append(d)
    if len(meta) != 120 or len(msg) != 120:
        print(f"expected 120 + 120 lines, got {len(meta)} + {len(msg)}")
        return 1
    for a, b in zip(meta, msg):
        if a["pts"] != b["timestamp"]:
            print(f"out of order: {a['pts']} vs {b['timestamp']}")
            return 1
        # One record, one writer: the meta's and the message's markers have
        # the same fields in the same order, as frappe-detect's and frappejson's.
        for ma, mb in zip(a["markers"], b["markers"]):
            if list(ma) != list(mb) or list(ma)[:5] != ["id", "dictionary", "corners", "hamming", "margin"]:
                print(f"frame {a['pts']}: fields {list(ma)} (meta) vs {list(mb)} (message)")
                return 1
        ids = sorted(m["id"] for m in a["markers"])
        if ids != [0, 7, 23, 42] or ids != sorted(m["id"] for m in b["markers"]):
            print(f"frame {a['pts']}: ids {ids}")
            return 1
    print("frappe-json: 120 frames, 4 markers each, meta and messages agree")

    # The sample is rendered through a 700 px pinhole with 5 cm markers;
    # markers 0 and 42 stay at 0.27 m and 0.26 m from the camera.
    pipeline = (f'filesrc location="{video}" ! decodebin ! videoconvert ! frappedetect '
                'marker-size=0.05 camera-matrix="<700.0,0.0,319.5,0.0,700.0,239.5,0.0,0.0,1.0>" ! '
                'appsink name=sink sync=false')
    p = subprocess.run([exe, "-p", pipeline], capture_output=True, text=True, timeout=120)
    if p.returncode != 0:
        print(p.stderr)
        return 1
    depth = {0: 0.27, 42: 0.26}
    worst = 0.0
    for line in p.stdout.splitlines():
        d = json.loads(line)
        for m in d["markers"]:
            if m["id"] in depth:
                worst = max(worst, abs(m["tvec"][2] - depth[m["id"]]) / depth[m["id"]])
    print(f"pose: worst depth error of markers 0 and 42 {100 * worst:.2f} %")
    return 0 if worst < 0.01 else 1


if __name__ == "__main__":
    sys.exit(main())
