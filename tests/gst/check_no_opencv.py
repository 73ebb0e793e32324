#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The frappe plugin must not need OpenCV, itself or through the libraries
it loads: its ELF NEEDED entries (objdump -p) and everything the loader
maps for it (ldd) must name no libopencv. Both lists must name GStreamer,
so that a tool printing nothing cannot pass. Exit 77 without the tools."""
import shutil
import subprocess
import sys


def main():
    plugin = sys.argv[1]
    if not shutil.which("objdump") or not shutil.which("ldd"):
        print("objdump or ldd not found")
        return 77
    dump = subprocess.run(["objdump", "-p", plugin], capture_output=True, text=True, check=True).stdout
    needed = [l.split()[1] for l in dump.splitlines() if l.strip().startswith("NEEDED")]
    loaded = subprocess.run(["ldd", plugin], capture_output=True, text=True, check=True).stdout.splitlines()
    failed = False
    for what, names in (("NEEDED", needed), ("ldd", loaded)):
        if not any("libgstreamer-1.0" in n for n in names):
            print(f"{what}: no libgstreamer-1.0 among {names}: the check would see nothing")
            failed = True
        opencv = [n.strip() for n in names if "opencv" in n.lower()]
        if opencv:
            print(f"{what}: the plugin loads OpenCV: " + ", ".join(opencv))
            failed = True
    if failed:
        return 1
    print(f"{plugin}: {len(needed)} NEEDED, {len(loaded)} loaded, no OpenCV")
    return 0


if __name__ == "__main__":
    sys.exit(main())
