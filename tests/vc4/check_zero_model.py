#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
# vc4-zero-model on the first frames of a shared sequence with their ARMv6 counts (a
# frames.csv excerpt of scripts/arm-count.sh): the program runs, emulates the QPU front end
# on every frame and finds its counts the same, reads the ARM run's marker counts back, and
# its per-frame lines add up to its summary. Exit 77 without the shared folder.
#
#   check_zero_model.py VC4_ZERO_MODEL COUNTS.csv SHARED_DIR
import os
import re
import subprocess
import sys


def main():
    model, counts, shared = sys.argv[1:4]
    seq = os.path.join(shared, "data", "synth", "seq01")
    if not os.path.isdir(seq):
        print("no shared sequence at %s: skipped" % seq)
        return 77
    n = sum(1 for line in open(counts) if line.strip()) - 1
    out = subprocess.run([model, "--counts", counts, "--images", seq, "--max", str(n), "--emulate-each",
                          "--per-frame", "--name", "seq01"], check=True, capture_output=True, text=True).stdout
    print(out)
    bad = []

    def need(cond, what):
        if not cond:
            bad.append(what)

    need(re.search(r"0 frames without counts skipped; 0 frames whose marker count differs", out),
         "every frame found its counts and the ARM run's markers")
    need("QPU counts differed between frames of one geometry on 0 frames" in out,
         "QPU counts follow the geometry alone")
    rows = re.findall(r"^\S+\.jpg\s+\d+x\d+\s+\d+\s+" + r"\s+".join([r"([\d.]+) /\s+([\d.]+)"] * 3) + r"$", out, re.M)
    need(len(rows) == n, "one line per frame (%d of %d)" % (len(rows), n))
    for i, r in enumerate(rows):
        ft = [float(x) for x in r]
        # Unpipelined, a frame's time is its latency, and overlap never makes latency shorter.
        need(abs(ft[0] - ft[1]) <= 0.011, "frame %d: unpipelined frame time = latency" % i)
        need(ft[3] >= ft[1] - 0.011 and ft[5] >= ft[1] - 0.011, "frame %d: overlap adds latency" % i)
    summary = {}
    for name in ("unpipelined", "whole frames", "staged"):
        m = re.search(r"^%s\s+\|\s+([\d.]+)\s+([\d.]+)\s+([\d.]+)\s+(\d+)\s+(\d+)\s+(\d+)\s+\|" % name, out, re.M)
        need(m is not None, "summary row " + name)
        if m:
            summary[name] = [float(x) for x in m.groups()]
    if len(rows) == n and "unpipelined" in summary:
        # The mean frame time is the mean interval between outputs, from the first on.
        mean = sum(float(r[0]) for r in rows[1:]) / (n - 1)
        need(abs(mean - summary["unpipelined"][1]) <= 0.02, "unpipelined mean %.2f = per-frame mean %.2f" % (
            summary["unpipelined"][1], mean))
    for name, s in summary.items():
        need(s[0] <= s[1] <= s[2], name + ": fast <= central <= slow")
        need(abs(1000.0 / s[1] - s[4]) <= 1.0, name + ": Hz = 1000 / ms")
    if "staged" in summary and "unpipelined" in summary:
        need(summary["staged"][1] < summary["unpipelined"][1], "staging hides QPU time")
    for b in bad:
        print("FAILED:", b)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
