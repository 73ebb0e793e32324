#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Issue 31: a typo in any property on a gst-launch-1.0 line is visible on
the terminal. Every writable property of frappedetect and frappejson (listed
through gi, so a new one is covered by itself) is given a bad value on a
gst-launch-1.0 line:

* frappedetect's strings and arrays (the values it parses or reads itself:
  dictionary, mode, marker-sizes, camera-matrix, distortion, the files):
  gst-launch-1.0 exits non-zero and prints an error naming the property, the
  value, "refused" and what the property takes (its blurb);
* numbers out of range, booleans, enums and flags that do not parse: GLib
  or gst-launch-1.0 itself names the property.

Run with /usr/bin/python3 (Debian's gi); exit 77 without gi."""
import subprocess
import sys

try:
    import gi
    gi.require_version("Gst", "1.0")
    from gi.repository import GObject, Gst
except (ImportError, ValueError):
    print("no gi or Gst for this python: skipped")
    sys.exit(77)

LINE = ("videotestsrc num-buffers=1 ! video/x-raw,format=GRAY8,width=64,height=48 ! "
        "frappedetect {} ! frappejson {} ! fakesink")
OWN = {"frappedetect": "GstFrappeDetect", "frappejson": "GstFrappeJson"}


def bad_value(spec):
    """A value the property cannot take, and whether the element itself
    refuses it (an error at start) rather than GLib or gst-launch."""
    t = spec.value_type
    if t == GObject.TYPE_STRING:
        return "7=0.1", True
    if t.name == "GstValueArray":
        return "<1.0, 2.0, 3.0>", True
    if t in (GObject.TYPE_INT, GObject.TYPE_UINT, GObject.TYPE_INT64, GObject.TYPE_UINT64, GObject.TYPE_FLOAT,
             GObject.TYPE_DOUBLE):
        if t in (GObject.TYPE_FLOAT, GObject.TYPE_DOUBLE) and spec.maximum > 1e30:
            return str(spec.minimum - 1), False
        return str(int(spec.maximum) + 1) if spec.maximum < 1e15 else "-1", False
    return "bogus", False


def main():
    launch = sys.argv[1]
    Gst.init(None)
    cases = []
    for element, type_name in OWN.items():
        e = Gst.ElementFactory.make(element, None)
        if e is None:
            print(f"{element} not found")
            return 1
        for spec in e.list_properties():
            if spec.owner_type.name != type_name or not spec.flags & GObject.ParamFlags.WRITABLE:
                continue
            value, own = bad_value(spec)
            if element == "frappejson" and spec.value_type == GObject.TYPE_STRING:
                continue  # frame-id takes any name
            cases.append((element, spec.name, value, own, spec.blurb))
    if len(cases) < 20:
        print(f"only {len(cases)} properties found")
        return 1

    failures = 0
    for element, name, value, own, blurb in cases:
        setting = f'{name}="{value}"'
        line = LINE.format(setting if element == "frappedetect" else "", setting if element == "frappejson" else "")
        # Through a shell, as a user types it.
        p = subprocess.run(f"{launch} {line}", shell=True, capture_output=True, text=True, timeout=60)
        out = p.stdout + p.stderr
        want = [name]
        if own:
            want += [f'{name}="', "refused", blurb]
            if not value.startswith("<"):
                want.append(f'"{value}"')
        missing = [w for w in want if w not in out]
        if missing or (own and p.returncode == 0):
            failures += 1
            print(f"{element} {setting}: exit {p.returncode}, missing {missing}:\n{out}")
        else:
            print(f"{element} {setting}: exit {p.returncode}, {'refused by the element' if own else 'named'}")
    print(f"{len(cases) - failures} passed, {failures} failed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
