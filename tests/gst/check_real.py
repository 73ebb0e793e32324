#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""frappedetect on real photos nobody here rendered (../shared/data/real):
decodebin ! videoconvert ! GRAY8 ! frappedetect ! appsink through the
frappe-json example. Every image must go through without an error; the
markers found must sit where the labels say (corners within 3 px), and the
recall over all images must stay above a floor. Exit 77 when the data set
is not present."""
import json
import os
import subprocess
import sys

CORNER_TOL = 3.0
RECALL_FLOOR = 0.9


def nick(family):
    family = family.removeprefix("opencv_")
    return family.replace("_", "-")


def main():
    exe, root = sys.argv[1], sys.argv[2]
    if not os.path.isdir(root):
        print(f"no data set at {root}")
        return 77
    found = expected = wrong = 0
    for ds in sorted(os.listdir(root)):
        truth = os.path.join(root, ds, "truth.jsonl")
        if not os.path.exists(truth):
            continue
        ds_found = ds_expected = 0
        for line in open(truth):
            t = json.loads(line)
            img = os.path.join(root, ds, t["image"])
            pipeline = (f'filesrc location="{img}" ! decodebin ! videoconvert ! '
                        f'video/x-raw,format=GRAY8 ! frappedetect dictionary={nick(t["family"])} ! '
                        f'appsink name=sink sync=false')
            p = subprocess.run([exe, "-p", pipeline], capture_output=True, text=True, timeout=60)
            if p.returncode != 0:
                print(f"{img}: frappe-json failed\n{p.stderr}")
                return 1
            metas = [json.loads(l) for l in p.stdout.splitlines()]
            metas = [m for m in metas if m["source"] == "meta"]
            if len(metas) != 1:
                print(f"{img}: {len(metas)} frames out, expected 1")
                return 1
            got = metas[0]["markers"]
            for want in t["markers"]:
                ds_expected += 1
                # Several markers may share an id: take the nearest.
                errs = [max(abs(a - b) for gc, wc in zip(g["corners"], want["corners"])
                            for a, b in zip(gc, wc))
                        for g in got if g["id"] == want["id"]]
                if not errs:
                    continue
                if min(errs) <= CORNER_TOL:
                    ds_found += 1
                elif min(errs) < 20:
                    wrong += 1
                    print(f"{img}: marker {want['id']} corners off by {min(errs):.2f} px")
        print(f"{ds}: {ds_found}/{ds_expected}")
        found += ds_found
        expected += ds_expected
    if expected == 0:
        return 77
    recall = found / expected
    print(f"total: {found}/{expected} labelled markers found (recall {recall:.3f}), {wrong} misplaced")
    return 0 if recall >= RECALL_FLOOR and wrong == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
