#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Tables of scripts/arm-count.sh from the frappecount plugin's log.

Inputs: the plugin log (M/C/B/N lines, see scripts/arm/frappecount.c), the
linker map and `nm -n -S -C` of the driver (to map each counted function to
its object file, hence its stage, and to demangle it), and the driver's
stdout (image sizes). Per frame: frappe = the intervals frappe_begin ->
frappe_front (front end) -> frappe_back (back end); OpenCV = opencv_begin
-> opencv_end (cv::aruco::detectMarkers). --arch names the target in the
headings (armv6, aarch64 or aarch64-scalar); the instruction classes are
named by the log itself (A line; older logs: the A32 names).
"""
import argparse
import bisect
import re
import sys
from collections import defaultdict

CLASSES = ["alu", "mul", "media_simd32", "branch", "load", "store", "ldm", "stm",
           "vfp", "vfp_ldst", "thumb16", "other"]
# --arch: (how it ran, the frappe heading)
TARGETS = {
    "armv6": ("qemu-arm -cpu arm1176",
              "frappe-core, ARMv6KZ + VFPv2 (-O3, -Dsimd=disabled: the ARMv6 SIMD32 row kernels)"),
    "aarch64": ("qemu-aarch64 -cpu cortex-a53",
                "frappe-core, aarch64 (ARMv8-A, -O3, Highway NEON kernels, static dispatch)"),
    "aarch64-scalar": ("qemu-aarch64 -cpu cortex-a53",
                       "frappe-core, aarch64 (ARMv8-A, -O3, -Dsimd=disabled: the scalar kernels)"),
}
STAGES = ["adaptive_scale", "front_end", "region_map", "trace", "refine", "warp", "decode", "detector", "other"]


def percentile(v, p):
    """Linear interpolation, as tests/bench/frappe_bench.cpp."""
    if not v:
        return 0.0
    v = sorted(v)
    idx = p * (len(v) - 1)
    lo = int(idx)
    hi = min(lo + 1, len(v) - 1)
    return v[lo] + (idx - lo) * (v[hi] - v[lo])


def parse_log(path):
    marks = []  # (label, total, classes[13], {bucket: (self, lib)})
    names = {}
    classes = list(CLASSES)
    cur = None
    with open(path) as f:
        for line in f:
            t = line.split()
            if not t:
                continue
            if t[0] == "A":
                classes = t[1:]
            elif t[0] == "M":
                cur = [t[1], int(t[2]), None, {}]
                marks.append(cur)
            elif t[0] == "C":
                cur[2] = [int(x) for x in t[1:]]
            elif t[0] == "B":
                cur[3][int(t[1])] = (int(t[2]), int(t[3]))
            elif t[0] == "N":
                names[int(t[1])] = (int(t[2], 16), " ".join(t[3:]))
    return marks, names, classes


def parse_map(path):
    """Address ranges of the input .text sections -> object file."""
    ranges = []
    pend = None
    rx = re.compile(r"^\s+(0x[0-9a-f]+)\s+(0x[0-9a-f]+)\s+(\S.*)$")
    with open(path, errors="replace") as f:
        for line in f:
            if line.startswith(" .text"):
                parts = line.split()
                if len(parts) >= 4 and parts[1].startswith("0x"):
                    ranges.append((int(parts[1], 16), int(parts[2], 16), parts[3]))
                    pend = None
                else:
                    pend = parts[0]
                continue
            if pend:
                m = rx.match(line)
                if m:
                    ranges.append((int(m.group(1), 16), int(m.group(2), 16), m.group(3).strip()))
                pend = None
    ranges = [r for r in ranges if r[1] > 0]
    ranges.sort()
    return ranges


def parse_syms(path):
    syms = {}
    with open(path, errors="replace") as f:
        for line in f:
            m = re.match(r"^([0-9a-f]+) (?:[0-9a-f]+ )?([TtWw]) (.*)$", line.rstrip("\n"))
            if m:
                syms.setdefault(int(m.group(1), 16), m.group(3))
    return syms


def object_of(ranges, starts, addr):
    i = bisect.bisect_right(starts, addr) - 1
    if i >= 0 and ranges[i][0] <= addr < ranges[i][0] + ranges[i][1]:
        obj = ranges[i][2]
        m = re.search(r"\(([^)]*)\)$", obj)
        return m.group(1) if m else obj.rsplit("/", 1)[-1]
    return "?"


# Object files are named after their source's path: src_<room>_<file>.cpp.o
# (frappe-core/src/<room>/<file>.cpp).
ROOM = r"^src_(?:(?:base|dictionary|front_end|trace|read|detector|pose|render)_(?=.))?"


def stage_of(obj, name):
    base = re.sub(ROOM, "", obj.replace(".cpp.o", "").replace(".o", ""))
    if base.startswith("front_end"):
        return "front_end"
    if base.startswith("region_map"):
        return "region_map"
    if base == "adaptive_scale":
        return "adaptive_scale"
    if base == "contour_trace" or base.startswith("trace_kernels"):
        return "trace"
    if base == "corner_refine":
        return "refine"
    if base == "decode":
        # as detector.cpp times them: insetQuad is part of "refine"
        if "insetQuad" in name:
            return "refine"
        if "warpMarker" in name:
            return "warp"
        return "decode"
    if base in ("homography", "fixed_warp") or base.startswith("warp_kernels"):
        return "warp"
    if base in ("dictionary", "dictionaries"):
        return "decode"
    if base in ("detector", "candidate_reader", "pipeline"):
        return "detector"
    return "other"


def short(name, n=70):
    full = name.replace("(anonymous namespace)::", "")
    base = full.split("(", 1)[0]
    if "{lambda" in full:
        base += "::{lambda}"
    clone = re.search(r"\[clone [^\]]*\]$", full)
    if clone:
        base += " " + clone.group(0)
    base = base.replace("frappe::detail::", "").replace("frappe::", "")
    return base if len(base) <= n else base[: n - 3] + "..."


# What the driver calls, in order: once warmup, then for each image the
# frappe markers and, with OpenCV, its two; exit is written by the plugin.
NEXT = {
    None: ("warmup", "frappe_begin"),
    "warmup": ("frappe_begin", "exit"),
    "frappe_begin": ("frappe_front",),
    "frappe_front": ("frappe_back",),
    "frappe_back": ("frappe_begin", "opencv_begin", "exit"),
    "opencv_begin": ("opencv_end",),
    "opencv_end": ("frappe_begin", "exit"),
}


def split_frames(marks):
    """The frames of a well-formed marker sequence; stops with what broke it
    (a marker firing twice, a missing one) instead of miscounting."""
    frames = []
    prev = None
    for i, (label, total, cls, bk) in enumerate(marks):
        expect = NEXT.get(prev, ())
        if label not in expect:
            counts = defaultdict(int)
            for m in marks:
                counts[m[0]] += 1
            seen = ", ".join(f"{k} x{v}" for k, v in counts.items())
            sys.exit(f"arm_count_report: marker #{i} is {label} after {prev or 'the start'}, expected "
                     f"{' or '.join(expect) or 'nothing'} (frame {max(len(frames) - 1, 0)}, from 0). Markers in the log: {seen}. "
                     "A marker counted more often than frappe_begin fires more than once a call: "
                     "is the plugin older than scripts/arm/frappecount.c, or its marks file of another build?")
        if label == "frappe_begin":
            frames.append({"fe": None, "be": None, "cv": None})
        elif label == "frappe_front":
            frames[-1]["fe"] = (cls, bk)
        elif label == "frappe_back":
            frames[-1]["be"] = (cls, bk)
        elif label == "opencv_end":
            frames[-1]["cv"] = (cls, bk)
        prev = label
    if prev is not None and prev != "exit":
        print(f"warning: the log ends after {prev}, not at the plugin's exit marker", file=sys.stderr)
    return [f for f in frames if f["be"] is not None]


def check_classes(classes, path):
    if len(classes) != 12:
        sys.exit(f"arm_count_report: {path} names {len(classes)} instruction classes, expected 12")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--log", required=True)
    ap.add_argument("--map", required=True)
    ap.add_argument("--syms", required=True)
    ap.add_argument("--driver", required=True)
    ap.add_argument("--md")
    ap.add_argument("--csv")
    ap.add_argument("--top", type=int, default=25)
    ap.add_argument("--arch", default="armv6", choices=list(TARGETS))
    a = ap.parse_args()
    target = TARGETS[a.arch]

    marks, names, classes = parse_log(a.log)
    ranges = parse_map(a.map)
    starts = [r[0] for r in ranges]
    syms = parse_syms(a.syms)
    sizes = []
    with open(a.driver) as f:
        for line in f:
            t = line.split()
            if t and t[0] == "image":
                sizes.append((int(t[2]), int(t[3]), int(t[4]), int(t[5]), " ".join(t[6:])))

    binfo = {}  # bucket -> (demangled name, object, stage)
    for b, (addr, mangled) in names.items():
        dem = syms.get(addr, mangled)
        obj = object_of(ranges, starts, addr)
        binfo[b] = (dem, obj, stage_of(obj, dem))
    binfo[0] = ("[library code before any call site]", "?", "other")

    # A marker seen twice in a row (an older plugin fired again where the
    # marker function straddles a page): the second one's deltas belong to
    # the interval that ends at the next marker.
    merged = []
    carry = None
    for m in marks:
        label, total, cls, bk = m
        if carry is not None:
            cls = [x + y for x, y in zip(cls, carry[2])]
            bk = dict(bk)
            for b, (s_, l_) in carry[3].items():
                o = bk.get(b, (0, 0))
                bk[b] = (o[0] + s_, o[1] + l_)
            carry = None
        if merged and merged[-1][0] == label and label != "exit":
            carry = [label, total, cls, bk]
            continue
        merged.append([label, total, cls, bk])
    if len(merged) != len(marks):
        print(f"warning: {len(marks) - len(merged)} repeated markers merged", file=sys.stderr)
    marks = merged

    frames = split_frames(marks)
    if not frames:
        sys.exit("arm_count_report: no counted frames (was the plugin loaded? is the driver unstripped?)")
    if len(frames) != len(sizes):
        # per-pixel numbers would pair frames with the wrong image sizes
        sys.exit(f"arm_count_report: {len(frames)} counted frames but {len(sizes)} images in the driver "
                 f"output ({a.driver}): the run or the log is incomplete")
    n = len(frames)
    check_classes(classes, a.log)

    per_stage = defaultdict(list)      # stage -> per-frame insns
    per_stage_px = defaultdict(list)
    fn_total = defaultdict(lambda: [0, 0])  # bucket -> [self, lib] over all frames (frappe)
    cls_fe = [0] * 13
    cls_be = [0] * 13
    cls_cv = [0] * 13
    whole, whole_px, fe_l, be_l, cv_l, cv_px = [], [], [], [], [], []
    own_px, lib_px = [], []
    total_px = 0
    csv_rows = []
    for fr, (w, h, nf, no, path) in zip(frames, sizes):
        px = w * h
        total_px += px
        st = defaultdict(int)
        own = lib = 0
        fe = sum(fr["fe"][0][:12])
        be = sum(fr["be"][0][:12])
        for part in ("fe", "be"):
            cls, bk = fr[part]
            for b, (s, l) in bk.items():
                info = binfo.get(b, ("?", "?", "other"))
                st[info[2]] += s + l
                own += s
                lib += l
                fn_total[b][0] += s
                fn_total[b][1] += l
        for k in range(13):
            cls_fe[k] += fr["fe"][0][k]
            cls_be[k] += fr["be"][0][k]
        for s in STAGES:
            per_stage[s].append(st[s])
            per_stage_px[s].append(st[s] / px)
        own_px.append(own / px)
        lib_px.append(lib / px)
        whole.append(fe + be)
        whole_px.append((fe + be) / px)
        fe_l.append(fe / px)
        be_l.append(be / px)
        cvi = None
        if fr["cv"]:
            cvi = sum(fr["cv"][0][:12])
            cv_l.append(cvi)
            cv_px.append(cvi / px)
            for k in range(13):
                cls_cv[k] += fr["cv"][0][k]
        csv_rows.append([path, w, h, nf, no, fe + be, fe, be] + [st[s] for s in STAGES] + [cvi if cvi is not None else ""])

    out = []
    P = out.append
    P(f"{n} frames, {sizes[0][0]}x{sizes[0][1]} (first), instructions counted under {target[0]}\n")
    P(f"### {target[1]}\n")
    P("| stage | median insns/frame | p90 insns/frame | median insns/px | p90 insns/px | share |")
    P("|---|---:|---:|---:|---:|---:|")
    grand = sum(whole)
    for s in STAGES:
        tot = sum(per_stage[s])
        if tot == 0:
            continue
        P(f"| {s} | {percentile(per_stage[s], .5)/1e6:.2f} M | {percentile(per_stage[s], .9)/1e6:.2f} M | "
          f"{percentile(per_stage_px[s], .5):.2f} | {percentile(per_stage_px[s], .9):.2f} | {100*tot/grand:.1f}% |")
    P(f"| **whole frame** | **{percentile(whole, .5)/1e6:.2f} M** | **{percentile(whole, .9)/1e6:.2f} M** | "
      f"**{percentile(whole_px, .5):.2f}** | **{percentile(whole_px, .9):.2f}** | 100% |")
    P(f"| whole frame, frappe's own code | | | {percentile(own_px, .5):.2f} | {percentile(own_px, .9):.2f} | |")
    P(f"| whole frame, library code it calls (libm, libc, libgcc) | | | {percentile(lib_px, .5):.2f} | {percentile(lib_px, .9):.2f} | |")
    P(f"| (check: front-end interval) | | | {percentile(fe_l, .5):.2f} | {percentile(fe_l, .9):.2f} | |")
    P(f"| (check: back-end interval) | | | {percentile(be_l, .5):.2f} | {percentile(be_l, .9):.2f} | |")
    P("")
    if a.arch == "armv6":
        P("Library code is Debian armel's (ARMv5TE, soft-float libm: an atan2f call costs ~1500 instructions "
          "there, a sin/cos/atan2 in double ~2700): on a hard-float Pi OS build it costs a fraction of this.\n")
    P("Stages by the object file / function each instruction's function belongs to (library and libgcc "
      "code counted to its caller); `detector` = detector.cpp's and candidate_reader.cpp's own code (checks, the back end's loop). "
      "Medians of each row are taken separately, so they do not add up to the whole frame's median.\n")
    if cv_l:
        P("### OpenCV 4.6 aruco (Debian armel: ARMv5TE, soft-float; reference only)\n" if a.arch == "armv6"
          else "### OpenCV 4.6 aruco (Debian arm64; reference only)\n")
        P("| | median insns/frame | p90 insns/frame | median insns/px | p90 insns/px |")
        P("|---|---:|---:|---:|---:|")
        P(f"| detectMarkers | {percentile(cv_l, .5)/1e6:.1f} M | {percentile(cv_l, .9)/1e6:.1f} M | "
          f"{percentile(cv_px, .5):.1f} | {percentile(cv_px, .9):.1f} |")
        P(f"\nratio of medians (OpenCV / frappe, whole frame): {percentile(cv_l, .5)/percentile(whole, .5):.1f}x\n")

    P("### Instruction classes (all frames, insns per pixel)\n")
    # the first ten slots, less those the target has no instructions for ("-")
    cols = [k for k in range(10) if classes[k] != "-"]
    hdr = [classes[k] for k in cols] + ["mem accesses"]
    P("| part | total | " + " | ".join(hdr) + " |")
    P("|---|---:|" + "---:|" * len(hdr))
    for label, c in (("frappe front end", cls_fe), ("frappe back end", cls_be), ("opencv aruco", cls_cv)):
        if sum(c[:12]) == 0:
            continue
        vals = [c[k] for k in cols] + [c[12]]
        P(f"| {label} | {sum(c[:12])/total_px:.2f} | " + " | ".join(f"{v/total_px:.2f}" for v in vals) + " |")
    P("")

    P("### frappe front end by function (all frames, mean insns per pixel)\n")
    P("| function | insns/px | share of front end |")
    P("|---|---:|---:|")
    fe_total = sum(s_ + l_ for b, (s_, l_) in fn_total.items() if binfo.get(b, ("", "", ""))[2] == "front_end")
    for b, (s_, l_) in sorted(fn_total.items(), key=lambda kv: -(kv[1][0] + kv[1][1])):
        dem, obj, stage = binfo.get(b, ("?", "?", "other"))
        if stage == "front_end" and s_ + l_ > 0:
            P(f"| `{short(dem)}` | {(s_ + l_)/total_px:.2f} | {100*(s_ + l_)/max(1, fe_total):.1f}% |")
    P("")
    P(f"### frappe: top {a.top} functions (all frames; self = own code, lib = library/libgcc code it called)\n")
    P("| function | object | stage | insns/px | self | lib | share |")
    P("|---|---|---|---:|---:|---:|---:|")
    ranked = sorted(fn_total.items(), key=lambda kv: -(kv[1][0] + kv[1][1]))
    for b, (s, l) in ranked[: a.top]:
        dem, obj, stage = binfo.get(b, ("?", "?", "other"))
        tot = s + l
        P(f"| `{short(dem)}` | {re.sub(ROOM, '', obj.replace('.cpp.o', ''))} | {stage} | {tot/total_px:.2f} | {s/total_px:.2f} | "
          f"{l/total_px:.2f} | {100*tot/grand:.1f}% |")
    P("")
    text = "\n".join(out)
    print(text)
    if a.md:
        with open(a.md, "w") as f:
            f.write(text + "\n")
    if a.csv:
        with open(a.csv, "w") as f:
            f.write(",".join(["image", "width", "height", "frappe_markers", "opencv_markers", "frappe_insns",
                              "front_end_call", "back_end_call"] + STAGES + ["opencv_insns"]) + "\n")
            for r in csv_rows:
                f.write(",".join(str(x) for x in r) + "\n")


if __name__ == "__main__":
    main()
