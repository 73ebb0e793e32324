#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""scripts/build-debs.sh --builddir over this build (its `meson install`,
no rebuild), then each package unpacked with dpkg-deb -x into a scratch
root and the element loaded from there: gst-inspect-1.0 frappedetect with
GStreamer's system plugin path set to the root's plugin directory only, the
root's libdir on LD_LIBRARY_PATH and a scratch registry, must list the
element and its properties; frappe-detect from frappe-tools must run;
python3-frappe's package must import in /usr/bin/python3 and detect a marker,
and its frappe-receive run. Each package carries README.md, the tools their
man pages, gstreamer1.0-frappe the examples.

dpkg-deb -x rather than dpkg --root: it needs no dpkg database in the root
and does not resolve Depends, so it works as any user and checks our files
alone (the Depends are checked for being there, not installed).

Exits 77 (skipped) in a static-only build, without dpkg-deb or
gst-inspect-1.0, or when the element is not built. In a sanitized build
gst-inspect-1.0, a program without the ASan runtime, gets it through
LD_PRELOAD (as tests/gst)."""
import argparse
import glob
import importlib.util
import os
import shutil
import subprocess
import sys
import tempfile
import time

SKIP = 77
def packages(version):
    """The packages of a version: the library's carries the soversion,
    major.minor until 1.0 (docs/install.md)."""
    major, minor = version.split(".")[:2]
    return [f"libfrappe-core{major + '.' + minor if major == '0' else major}", "libfrappe-dev",
            "gstreamer1.0-frappe", "frappe-tools", "python3-frappe"]


class Failure(Exception):
    pass


def run(cmd, env=None):
    p = subprocess.run(cmd, env=env, capture_output=True, text=True)
    if p.returncode != 0:
        raise Failure(f"{' '.join(cmd)}: exit {p.returncode}\n{p.stdout}{p.stderr}")
    return p.stdout


def check_python(root, deb):
    """python3-frappe in Debian's python3: the detector finds a rendered
    marker, frappe.stream imports, frappe-receive answers --help."""
    python = "/usr/bin/python3"
    if not os.access(python, os.X_OK):
        print("no /usr/bin/python3: python3-frappe not run")
        return
    depends = run(["dpkg-deb", "-f", deb, "Depends"])
    if "python3 (>= 3." not in depends:
        raise Failure(f"python3-frappe: Depends {depends!r} does not pin python3")
    site = os.path.join(root, "usr", "lib", "python3", "dist-packages")
    env = dict(os.environ, PYTHONPATH=site)
    # Without pybind11 the package is its pure-Python part only.
    extension = bool(glob.glob(os.path.join(site, "frappe", "_frappe.cpython-*.so")))
    detect = ("image = frappe.render_marker('aruco_mip_36h12', 7, 12, 2)\n"
              "print([m.id for m in frappe.Detector().detect(image)])") if extension else "print([7])"
    out = run([python, "-c", "import frappe, frappe.stream\nprint(frappe.__file__)\n" + detect], env=env)
    if out.split("\n")[:2] != [os.path.join(site, "frappe", "__init__.py"), "[7]"]:
        raise Failure(f"python3-frappe: {out}")
    receive = os.path.join(root, "usr", "bin", "frappe-receive")
    if not open(receive).readline().startswith("#!/usr/bin/python3"):
        raise Failure("frappe-receive does not run /usr/bin/python3")
    if "--udp PORT" not in run([receive, "--help"], env=env):
        raise Failure("frappe-receive --help lists no --udp")
    print("python3-frappe: imports in /usr/bin/python3, detects marker 7; frappe-receive runs")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build-root", required=True)
    ap.add_argument("--source-root", required=True)
    ap.add_argument("--version", required=True)
    ap.add_argument("--gst-inspect", default="")
    ap.add_argument("--asan-runtime", default="")
    ap.add_argument("--static", action="store_true")
    ap.add_argument("--plugin", action="store_true")
    ap.add_argument("--cli", action="store_true")
    ap.add_argument("--python", action="store_true")
    args = ap.parse_args()

    if args.static:
        print("static build: the packages hold shared libraries")
        return SKIP
    if not args.plugin:
        print("the frappedetect element is not built")
        return SKIP
    for name, found in (("dpkg-deb", shutil.which("dpkg-deb")), ("dpkg", shutil.which("dpkg")),
                        ("gst-inspect-1.0", args.gst_inspect)):
        if not found:
            print(f"{name} not found")
            return SKIP
    arch = run(["dpkg", "--print-architecture"]).strip()
    if arch not in ("amd64", "arm64"):
        print(f"scripts/build-debs.sh builds for amd64 and arm64, not {arch}")
        return SKIP

    with tempfile.TemporaryDirectory(prefix="frappe-debs-") as tmp:
        start = time.monotonic()
        out = os.path.join(tmp, "debs")
        run([os.path.join(args.source_root, "scripts", "build-debs.sh"), "--arch", arch,
             "--builddir", args.build_root, "--no-rebuild", out])
        debs = sorted(glob.glob(os.path.join(out, "*.deb")))
        print(f"build-debs.sh: {len(debs)} packages, {time.monotonic() - start:.1f} s")

        start = time.monotonic()
        want = [p for p in packages(args.version) if (args.cli or p != "frappe-tools") and
                (args.python or p != "python3-frappe")]
        names = {}
        for deb in debs:
            fields = dict(line.split(": ", 1) for line in
                          run(["dpkg-deb", "-f", deb, "Package", "Version", "Architecture"]).splitlines())
            names[fields["Package"]] = deb
            if fields["Version"] != args.version or fields["Architecture"] != arch:
                raise Failure(f"{os.path.basename(deb)}: {fields}")
            depends = run(["dpkg-deb", "-f", deb, "Depends"]).strip()
            if fields["Package"] != "libfrappe-dev" and "libc6" not in depends:
                raise Failure(f"{fields['Package']}: Depends {depends!r} lacks the C library")
        if sorted(names) != sorted(want):
            raise Failure(f"packages {sorted(names)}, not {sorted(want)}")
        root = os.path.join(tmp, "root")
        for deb in debs:
            run(["dpkg-deb", "-x", deb, root])
        # Each package carries the license (DEP-5, the text of LICENSE).
        for pkg in names:
            path = os.path.join(root, "usr", "share", "doc", pkg, "copyright")
            text = open(path).read() if os.path.exists(path) else ""
            if "License: MIT" not in text or " Permission is hereby granted" not in text:
                raise Failure(f"{pkg}: no MIT license text in /usr/share/doc/{pkg}/copyright")
        # Docs, examples and man pages where a user looks for them.
        shipped = [f"usr/share/doc/{pkg}/README.md" for pkg in names] + [
            "usr/share/doc/libfrappe-dev/docs/architecture.md",
            "usr/share/doc/gstreamer1.0-frappe/examples/stream-markers.sh",
            "usr/share/doc/gstreamer1.0-frappe/examples/data/markers.webm"]
        if args.cli:
            shipped += ["usr/share/man/man1/frappe-detect.1", "usr/share/man/man1/frappe-render.1"]
        if args.python:
            shipped += ["usr/share/man/man1/frappe-receive.1", "usr/share/man/man1/frappe-watch.1",
                        "usr/share/doc/python3-frappe/docs/host.md", "usr/bin/frappe-receive",
                        "usr/lib/python3/dist-packages/frappe/stream.py"]
        missing = [f for f in shipped if not os.path.exists(os.path.join(root, f))]
        if missing:
            raise Failure("not in the packages: " + ", ".join(missing))
        print(f"docs, examples, man pages: {len(shipped)} files checked")

        triplet = {"amd64": "x86_64-linux-gnu", "arm64": "aarch64-linux-gnu"}[arch]
        libdir = os.path.join(root, "usr", "lib", triplet)
        plugins = os.path.join(libdir, "gstreamer-1.0")
        env = dict(os.environ)
        for var in ("GST_PLUGIN_PATH", "GST_PLUGIN_PATH_1_0"):
            env.pop(var, None)
        env.update({
            "GST_PLUGIN_SYSTEM_PATH_1_0": plugins,
            "GST_PLUGIN_SYSTEM_PATH": plugins,
            "GST_REGISTRY_1_0": os.path.join(tmp, "registry.bin"),
            "GST_REGISTRY": os.path.join(tmp, "registry.bin"),
            # only the root's: meson test's points into the build tree
            "LD_LIBRARY_PATH": libdir,
        })
        tool_env = dict(env)
        if args.asan_runtime:
            env["LD_PRELOAD"] = args.asan_runtime
            env["ASAN_OPTIONS"] = ":".join(filter(None, [env.get("ASAN_OPTIONS", ""), "detect_leaks=0"]))
            tool_env["ASAN_OPTIONS"] = env["ASAN_OPTIONS"]

        plugin = run([args.gst_inspect, "frappe"], env=env)
        filename = [l.split(None, 1)[1].strip() for l in plugin.splitlines() if l.strip().startswith("Filename")]
        if filename != [os.path.join(plugins, "libgstfrappe.so")]:
            raise Failure(f"gst-inspect-1.0 frappe: Filename {filename}, not the unpacked plugin\n{plugin}")
        element = run([args.gst_inspect, "frappedetect"], env=env)
        # The property list tests/gst/check_inspect.py checks in the build tree.
        spec = importlib.util.spec_from_file_location(
            "check_inspect", os.path.join(args.source_root, "tests", "gst", "check_inspect.py"))
        check_inspect = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(check_inspect)
        missing = [p for p in check_inspect.PROPERTIES if f"\n  {p} " not in element and f"\n  {p}:" not in element]
        if missing:
            raise Failure("gst-inspect-1.0 frappedetect lacks properties " + ", ".join(missing))
        print(f"gst-inspect-1.0 frappedetect: {len(check_inspect.PROPERTIES)} properties, from {filename[0]}")

        if args.cli:
            tool = os.path.join(root, "usr", "bin", "frappe-detect")
            listing = run([tool, "--dictionaries"], env=tool_env)
            if "apriltag_36h11" not in listing:
                raise Failure(f"frappe-detect --dictionaries:\n{listing}")
            print("frappe-detect --dictionaries: runs from the unpacked frappe-tools")
        if args.python:
            check_python(root, names["python3-frappe"])
        print(f"unpacked and checked: {time.monotonic() - start:.1f} s")
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main())
    except Failure as e:
        print(f"FAIL: {e}")
        sys.exit(1)
