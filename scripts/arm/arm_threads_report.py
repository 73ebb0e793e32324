#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Tables of scripts/arm-count.sh --bands N or --pipeline N (issue 35 item 4).

--bands: per frame the markers are frappe_begin, then band_begin/band_end
once a band (the bands ran one at a time under a lock), frappe_front,
frappe_back. A band's count is its interval; the front end's serial rest is
the front end's interval less its bands (the region map from the bands'
means, the hand-overs); the back end's stages come from its functions as in
arm_count_report.py. The latency on as many cores as bands is the front
end's serial rest, plus its largest band, plus the back end.

--pipeline: the plugin's vcpus=1 counts (V lines, each thread's count since
the start, after every marker) between pipeline_begin and pipeline_end:
what each thread executed over the whole list.
"""
import argparse
import os
import sys
from collections import defaultdict

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from arm_count_report import (STAGES, object_of, parse_map, parse_syms,  # noqa: E402
                              percentile, stage_of)


def parse(path):
    """[(label, total, {bucket: self + lib}, {vcpu: insns})], {bucket: (addr, name)}"""
    marks, names = [], {}
    with open(path) as f:
        for line in f:
            t = line.split()
            if not t:
                continue
            if t[0] == "M":
                marks.append((t[1], int(t[2]), {}, {}))
            elif t[0] == "B":
                marks[-1][2][int(t[1])] = int(t[2]) + int(t[3])
            elif t[0] == "V":
                marks[-1][3][int(t[1])] = int(t[2])
            elif t[0] == "N":
                names[int(t[1])] = (int(t[2], 16), " ".join(t[3:]))
    return marks, names


def sizes_of(path):
    out = []
    with open(path) as f:
        for line in f:
            t = line.split()
            if t and t[0] == "image":
                out.append((int(t[2]), int(t[3])))
    return out


def bands_report(marks, stage_of_bucket, sizes):
    start = next((i for i, m in enumerate(marks) if m[0] == "warmup"), None)
    if start is None:
        sys.exit("arm_threads_report: no warmup marker")
    frames, cur = [], None
    for label, total, bk, _ in marks[start + 1:]:
        if label == "frappe_begin":
            cur = {"t0": total, "bands": [], "open": None}
        elif cur is None:
            continue
        elif label == "band_begin":
            cur["open"] = total
        elif label == "band_end":
            cur["bands"].append(total - cur["open"])
        elif label == "frappe_front":
            cur["t1"] = total
        elif label == "frappe_back":
            cur["t2"] = total
            st = defaultdict(int)
            for b, n in bk.items():
                st[stage_of_bucket(b)] += n
            cur["be_stages"] = st
            frames.append(cur)
            cur = None
    if len(frames) != len(sizes):
        sys.exit(f"arm_threads_report: {len(frames)} frames counted, {len(sizes)} in the driver's output")
    nb = {len(f["bands"]) for f in frames}
    if len(nb) != 1:
        sys.exit(f"arm_threads_report: frames with different band counts {sorted(nb)}")
    n = nb.pop()
    rows = defaultdict(list)
    csv = []
    for f, (w, h) in zip(frames, sizes):
        px = w * h
        fe = f["t1"] - f["t0"]
        be = f["t2"] - f["t1"]
        bands = f["bands"]
        serial = fe - sum(bands)
        lat = serial + max(bands) + be
        r = {"whole (bands in turn)": fe + be, "front end": fe, "front end: bands, sum": sum(bands),
             "front end: largest band": max(bands), "front end: serial rest": serial, "back end": be}
        for s in STAGES:
            if f["be_stages"].get(s):
                r["back end: " + s] = f["be_stages"][s]
        r[f"latency on {n} cores"] = lat
        for k, v in r.items():
            rows[k].append(v / px)
        rows["speed-up of latency"].append((fe + be) / lat)
        rows["back end's share of latency"].append(be / lat)
        csv.append([w, h, fe, be, serial] + bands + [lat])
    out = [f"{len(frames)} frames, {sizes[0][0]}x{sizes[0][1]} (first), front end in {n} bands\n",
           "| per frame | median insns/px | p90 insns/px |", "|---|---:|---:|"]
    for k, v in rows.items():
        if "share" in k or "speed-up" in k:
            out.append(f"| {k} | {percentile(v, .5):.2f} | {percentile(v, .9):.2f} |")
        else:
            out.append(f"| {k} | {percentile(v, .5):.2f} | {percentile(v, .9):.2f} |")
    head = "width,height,front_end,back_end,front_end_serial," + ",".join(f"band{i}" for i in range(n)) + ",latency"
    return out, head, csv


def pipeline_report(marks, sizes):
    begin = next((m for m in marks if m[0] == "pipeline_begin"), None)
    end = next((m for m in marks if m[0] == "pipeline_end"), None)
    if not begin or not end:
        sys.exit("arm_threads_report: no pipeline_begin/pipeline_end markers")
    if not end[3]:
        sys.exit("arm_threads_report: no per-thread counts (V lines): was the plugin run with vcpus=1?")
    px = sum(w * h for w, h in sizes)
    deltas = {v: end[3][v] - begin[3].get(v, 0) for v in sorted(end[3])}
    total = sum(deltas.values())
    out = [f"{len(sizes)} frames, {sizes[0][0]}x{sizes[0][1]} (first), through the pipeline\n",
           "| thread | insns | insns/px of the list | share |", "|---|---:|---:|---:|"]
    for v, d in deltas.items():
        out.append(f"| {v}{' (caller)' if v == 0 else ''} | {d/1e6:.2f} M | {d/px:.3f} | {100*d/max(1, total):.1f}% |")
    out.append(f"| **all** | **{total/1e6:.2f} M** | **{total/px:.3f}** | 100% |")
    out.append(f"\nper frame: {total/len(sizes)/1e6:.4f} M insns, the caller's {deltas.get(0, 0)/len(sizes):.0f}")
    csv = [[v, d] for v, d in deltas.items()]
    return out, "vcpu,insns", csv


def main():
    ap = argparse.ArgumentParser()
    for k in ("log", "map", "syms", "driver"):
        ap.add_argument("--" + k, required=True)
    ap.add_argument("--md")
    ap.add_argument("--csv")
    a = ap.parse_args()
    marks, names = parse(a.log)
    sizes = sizes_of(a.driver)
    if not sizes:
        sys.exit("arm_threads_report: no images in the driver's output")
    if any(m[0] == "pipeline_begin" for m in marks):
        out, head, csv = pipeline_report(marks, sizes)
    else:
        ranges = parse_map(a.map)
        starts = [r[0] for r in ranges]
        syms = parse_syms(a.syms)
        cache = {}

        def stage_of_bucket(b):
            if b not in cache:
                addr, mangled = names.get(b, (0, "?"))
                cache[b] = stage_of(object_of(ranges, starts, addr), syms.get(addr, mangled)) if b else "other"
            return cache[b]
        out, head, csv = bands_report(marks, stage_of_bucket, sizes)
    text = "\n".join(out)
    print(text)
    if a.md:
        with open(a.md, "w") as f:
            f.write(text + "\n")
    if a.csv:
        with open(a.csv, "w") as f:
            f.write(head + "\n")
            for r in csv:
                f.write(",".join(str(x) for x in r) + "\n")


if __name__ == "__main__":
    main()
