#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Links the system's GStreamer plugins of GStreamer itself, -base and -good
(the tests' GST_PLUGIN_LOADING_WHITELIST) into one folder, for the
ThreadSanitizer build's GST_PLUGIN_SYSTEM_PATH. The whitelist alone is not
enough there: the registry is scanned in-process (GST_REGISTRY_FORK=no) and
opens every plugin of the system folder before refusing it, so the library
constructors of -bad's plugins (OpenNI2, DirectFB: their own mutex misuse)
run under TSan and fail the tests. Without dpkg, links every plugin.

usage: link_plugins.py SYSTEM_PLUGIN_DIR OUT_DIR"""
import os
import subprocess
import sys

PACKAGES = ["libgstreamer1.0-0", "gstreamer1.0-plugins-base", "gstreamer1.0-plugins-good"]


def main():
    system, out = sys.argv[1:3]
    try:
        listed = subprocess.run(["dpkg", "-L", *PACKAGES], capture_output=True, text=True, check=True).stdout
        wanted = {os.path.basename(p) for p in listed.split() if os.path.dirname(p) == system and p.endswith(".so")}
    except (OSError, subprocess.CalledProcessError):
        wanted = {f for f in os.listdir(system) if f.endswith(".so")}
    os.makedirs(out, exist_ok=True)
    for f in os.listdir(out):
        os.unlink(os.path.join(out, f))
    for f in sorted(wanted):
        os.symlink(os.path.join(system, f), os.path.join(out, f))
    print(f"{len(wanted)} plugins linked into {out}")


if __name__ == "__main__":
    sys.exit(main())
