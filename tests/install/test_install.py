#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""`meson install --destdir` of this build into a scratch directory, then the
consumers in consumer/ built against the staged tree twice, with pkg-config
and with CMake's find_package(frappe), and run: each must print the project's
version, and load libfrappe-core from the staged tree. Fails when a header,
a library, a .pc file or the CMake package is missing or wrong. Exits 77
(skipped) in a static-only build (not run at all in a cross one), or without cmake, pkg-config or
the compiler.

In a sanitized build (b_sanitize) the staged libraries need the sanitizer
runtimes loaded first, so the consumers are built with the same -fsanitize
flags."""
import argparse
import os
import shlex
import shutil
import subprocess
import sys
import tempfile
import time

SKIP = 77
HERE = os.path.dirname(os.path.abspath(__file__))


class Failure(Exception):
    pass


def run(cmd, env=None, expect_fail=None):
    """Runs cmd; with expect_fail, it must fail saying that."""
    p = subprocess.run(cmd, env=env, capture_output=True, text=True)
    if expect_fail is None and p.returncode == 0:
        return p.stdout
    # (CMake wraps its messages: compare with the line breaks as spaces)
    if expect_fail is not None and p.returncode != 0 and expect_fail in " ".join((p.stdout + p.stderr).split()):
        return p.stdout
    raise Failure(f"{shlex.join(cmd)}: exit {p.returncode}{', expected to fail' if expect_fail else ''}"
                  f"\n{p.stdout}{p.stderr}")


def check_tree(args, prefix, libdir, includedir):
    """Every file an application needs, where it should be."""
    # The soversion: major.minor until 1.0 (docs/install.md).
    numbers = args.version.split(".")
    major = ".".join(numbers[:2]) if numbers[0] == "0" else numbers[0]
    want = [os.path.join(libdir, f) for f in (f"libfrappe-core.so.{args.version}", f"libfrappe-core.so.{major}",
                                              "libfrappe-core.so", "pkgconfig/frappe-core.pc",
                                              "cmake/frappe/frappeConfig.cmake",
                                              "cmake/frappe/frappeConfigVersion.cmake")]
    # the headers in the source tree, and version.h, which meson makes from version.h.in
    headers = sorted(h for h in os.listdir(os.path.join(args.source_root, "frappe-core", "include", "frappe"))
                     if h.endswith(".h")) + ["version.h"]
    want += [os.path.join(includedir, "frappe", h) for h in headers]
    if args.gstmeta:
        want += [os.path.join(libdir, f) for f in (f"libgstfrappemeta-1.0.so.{args.version}",
                                                   f"libgstfrappemeta-1.0.so.{major}", "libgstfrappemeta-1.0.so",
                                                   "pkgconfig/gstfrappemeta.pc", "gstreamer-1.0/libgstfrappe.so")]
        want.append(os.path.join(includedir, "gstreamer-1.0", "gst", "frappe", "gstfrappemeta.h"))
    missing = [os.path.relpath(f, prefix) for f in want if not os.path.exists(f)]
    if missing:
        raise Failure("not installed: " + ", ".join(missing))


def run_consumers(what, exes, libdir, args, env):
    """Runs the consumers built by `what` and checks what they print and
    which libfrappe-core they load."""
    expected = {
        "consumer": f"frappe {args.version} markers 0",
        "consumer-meta": "GstFrappeMarkerMetaAPI id 7 dictionary apriltag_36h11 count 1",
    }
    for name, exe in exes.items():
        out = run([exe], env=env).strip()
        if out != expected[name]:
            raise Failure(f"{what} {name} printed {out!r}, not {expected[name]!r}")
        print(f"{what}: {name}: {out}")
    # ldd resolves with the same LD_LIBRARY_PATH: the staged library, not an
    # older one installed on the machine.
    for line in run(["ldd", exes["consumer"]], env=env).splitlines():
        if line.strip().startswith("libfrappe-core.so"):
            path = line.split("=>")[1].split("(")[0].strip()
            if not os.path.realpath(path).startswith(os.path.realpath(libdir) + os.sep):
                raise Failure(f"{what} consumer loads {path}, not the staged library")
            break
    else:
        raise Failure(f"{what} consumer does not link libfrappe-core")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--meson", default="")
    ap.add_argument("--build-root", required=True)
    ap.add_argument("--source-root", required=True)
    ap.add_argument("--prefix", required=True)
    ap.add_argument("--libdir", required=True)
    ap.add_argument("--includedir", required=True)
    ap.add_argument("--version", required=True)
    ap.add_argument("--cxx", required=True, help="the build's C++ compiler command, shell-quoted")
    ap.add_argument("--sanitize", default="none")
    ap.add_argument("--static", action="store_true")
    ap.add_argument("--gstmeta", action="store_true")
    args = ap.parse_args()

    if args.static:
        print("static build: the CMake package describes shared libraries")
        return SKIP
    cxx = shlex.split(args.cxx)
    cmake, pkg_config = shutil.which("cmake"), shutil.which("pkg-config")
    for name, found in (("meson", args.meson), ("cmake", cmake), ("pkg-config", pkg_config),
                        ("C++ compiler " + cxx[-1], shutil.which(cxx[-1]))):
        if not found:
            print(f"{name} not found")
            return SKIP

    sanitize = [] if args.sanitize in ("", "none") else [f"-fsanitize={args.sanitize}"]
    env = dict(os.environ)
    if sanitize:
        # gst_init() keeps blocks LeakSanitizer would report (as in .ci/run).
        env["ASAN_OPTIONS"] = ":".join(filter(None, [env.get("ASAN_OPTIONS", ""), "detect_leaks=0"]))

    with tempfile.TemporaryDirectory(prefix="frappe-install-") as tmp:
        start = time.monotonic()
        stage = os.path.join(tmp, "stage")
        run([args.meson, "install", "-C", args.build_root, "--no-rebuild", "--quiet", "--destdir", stage])
        prefix = stage + args.prefix
        under = lambda d: stage + d if os.path.isabs(d) else os.path.join(prefix, d)
        libdir, includedir = under(args.libdir), under(args.includedir)
        check_tree(args, prefix, libdir, includedir)
        # The Python package's commands find it wherever meson put it, on
        # the Python's path or not (/usr/local on Debian).
        receive = os.path.join(prefix, "bin", "frappe-receive")
        if os.path.exists(receive):
            py_env = {k: v for k, v in env.items() if k != "PYTHONPATH"}
            if "--udp PORT" not in run([receive, "--help"], env=py_env):
                raise Failure("the installed frappe-receive --help lists no --udp")
            print("frappe-receive: runs from the staged prefix")
        print(f"meson install --destdir: {time.monotonic() - start:.1f} s")
        # Only the staged libdir: meson test's own LD_LIBRARY_PATH points
        # into the build tree, which would hide a library missing from it.
        run_env = dict(env, LD_LIBRARY_PATH=libdir)

        # pkg-config: relocatable .pc files (the default, pkgconfig.relocatable)
        # find the staged prefix themselves; others are given it as the sysroot.
        start = time.monotonic()
        pc_dir = os.path.join(libdir, "pkgconfig")
        pc_env = dict(env, PKG_CONFIG_PATH=pc_dir)
        relocatable = "${pcfiledir}" in open(os.path.join(pc_dir, "frappe-core.pc")).read()
        if not relocatable:
            pc_env["PKG_CONFIG_SYSROOT_DIR"] = stage
        modversion = run([pkg_config, "--modversion", "frappe-core"], env=pc_env).strip()
        if modversion != args.version:
            raise Failure(f"pkg-config --modversion frappe-core: {modversion}, not {args.version}")
        exes = {}
        sources = {"consumer": ("consumer.cpp", ["frappe-core"])}
        if args.gstmeta:
            sources["consumer-meta"] = ("consumer_meta.cpp", ["gstfrappemeta"])
        for name, (src, modules) in sources.items():
            flags = shlex.split(run([pkg_config, "--cflags", "--libs"] + modules, env=pc_env))
            if not relocatable and "gstfrappemeta" in modules:
                # the sysroot also moved GStreamer's own directories
                flags += shlex.split(run([pkg_config, "--cflags", "--libs", "gstreamer-video-1.0"], env=env))
            exes[name] = os.path.join(tmp, name + "-pkgconfig")
            run(cxx + ["-std=c++20", "-O1"] + sanitize + [os.path.join(HERE, "consumer", src), "-o", exes[name]]
                + flags)
        run_consumers("pkg-config", exes, libdir, args, run_env)
        print(f"pkg-config: {time.monotonic() - start:.1f} s")

        # CMake: find_package(frappe MAJOR.MINOR) from the staged prefix only.
        start = time.monotonic()
        major, minor = args.version.split(".")[:2]
        generator = ["-G", "Ninja"] if shutil.which("ninja") else []
        configure = [cmake, "-S", os.path.join(HERE, "consumer")] + generator + [
            f"-DCMAKE_PREFIX_PATH={prefix}", f"-DCMAKE_CXX_COMPILER={shutil.which(cxx[-1])}",
            "-DCMAKE_BUILD_TYPE=Release", "-DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF",
            f"-DWITH_GSTMETA={'ON' if args.gstmeta else 'OFF'}"]
        if len(cxx) > 1:
            configure.append(f"-DCMAKE_CXX_COMPILER_LAUNCHER={';'.join(cxx[:-1])}")
        if sanitize:
            configure += [f"-DCMAKE_CXX_FLAGS={sanitize[0]}", f"-DCMAKE_EXE_LINKER_FLAGS={sanitize[0]}"]
        # The version file must refuse a newer minor version (0.x breaks at minor).
        run(configure + ["-B", os.path.join(tmp, "cmake-newer"), f"-DFRAPPE_WANT_VERSION={major}.{int(minor) + 1}"],
            env=env, expect_fail="compatible with requested version")
        build = os.path.join(tmp, "cmake-build")
        run(configure + ["-B", build, f"-DFRAPPE_WANT_VERSION={major}.{minor}"], env=env)
        cache = open(os.path.join(build, "CMakeCache.txt")).read()
        found_dir = [l.split("=", 1)[1] for l in cache.splitlines() if l.startswith("frappe_DIR:")]
        if not found_dir or not os.path.realpath(found_dir[0]).startswith(os.path.realpath(prefix) + os.sep):
            raise Failure(f"find_package(frappe) used {found_dir}, not the staged package")
        run([cmake, "--build", build], env=env)
        exes = {name: os.path.join(build, name) for name in sources}
        run_consumers("cmake", exes, libdir, args, run_env)
        print(f"cmake: {time.monotonic() - start:.1f} s")
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main())
    except Failure as e:
        print(f"FAIL: {e}")
        sys.exit(1)
