#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""gst-inspect-1.0 frappedetect and frappejson must exit 0, print no warnings
or criticals, and list every property and pad the issues ask for; the
plugin's licence must be one GStreamer knows (else every registry scan warns
of an unknown license)."""
import subprocess
import sys

PROPERTIES = ["dictionary", "mode", "edge-threshold", "corner-threshold", "region-contrast", "light-floor", "max-hamming",
              "scaled-size", "max-scaled-frames", "weak-margin", "corner-cluster-radius",
              "min-marker-side", "max-pixels", "max-candidates", "annotate", "post-messages", "pipelined",
              "backend", "marker-size", "camera-matrix", "distortion", "calibration-file",
              "marker-sizes", "dictionary-file", "stats"]
# gst_plugin_check_license()'s list (GStreamer 1.22).
KNOWN_LICENSES = ["LGPL", "GPL", "QPL", "GPL/QPL", "MPL", "BSD", "MIT/X11", "0BSD", "Proprietary",
                  "unknown"]


def missing_formats(element, inspected):
    missing = [f for f in ("GRAY8", "I420", "YV12", "NV12", "NV21") if f not in inspected]
    if missing:
        print(f"{element}: missing formats {missing}")
    return missing


def main():
    inspect = sys.argv[1]
    for args in (["frappedetect"], ["frappejson"], ["frappe"]):
        p = subprocess.run([inspect] + args, capture_output=True, text=True)
        if p.returncode != 0:
            print(f"{args}: exit {p.returncode}\n{p.stderr}")
            return 1
        noise = [l for l in (p.stderr + p.stdout).splitlines()
                 if "WARNING" in l or "CRITICAL" in l or "ERROR" in l]
        if p.stderr.strip() or noise:
            print(f"{args}: unexpected output:\n{p.stderr}\n" + "\n".join(noise))
            return 1
    out = subprocess.run([inspect, "frappedetect"], capture_output=True, text=True).stdout
    missing = [name for name in PROPERTIES if f"\n  {name} " not in out and f"\n  {name}:" not in out]
    if missing:
        print("missing properties: " + ", ".join(missing))
        return 1
    plugin = subprocess.run([inspect, "frappe"], capture_output=True, text=True).stdout
    licence = [l.split(None, 1)[1].strip() for l in plugin.splitlines()
               if l.strip().startswith("License") and len(l.split(None, 1)) == 2]
    if licence != [] and licence[0] not in KNOWN_LICENSES:
        print(f"licence {licence[0]!r} is not one GStreamer knows: {KNOWN_LICENSES}")
        return 1
    if licence == []:
        print("no License line in gst-inspect-1.0 frappe")
        return 1
    if missing_formats("frappedetect", out):
        return 1
    # The dictionary property, a string of any spelling, lists the library's
    # names and defaults to the library's default.
    if "apriltag_36h11" not in out or '"aruco_mip_36h12"' not in out or "dashed" not in out:
        print("the dictionary property should list the library's names and its spellings")
        return 1
    json = subprocess.run([inspect, "frappejson"], capture_output=True, text=True).stdout
    if "application/x-json" not in json or "frappejson" not in plugin:
        print("frappejson: no application/x-json src pad, or not in the plugin")
        return 1
    if missing_formats("frappejson", json):
        return 1
    print("gst-inspect-1.0 frappedetect, frappejson: clean")
    return 0


if __name__ == "__main__":
    sys.exit(main())
