#!/usr/bin/env bash
# Installs everything Frappe needs to build and test on Debian 12 (bookworm).
# Run as root (or through sudo). Safe to run again.
set -euo pipefail

packages=(
	# build
	g++ meson ninja-build pkg-config python3
	# frappe-core, the CLI and the benchmarks
	libopencv-dev libeigen3-dev libhwy-dev
	# tests
	libgtest-dev libgmock-dev libbenchmark-dev libapriltag-dev
	# the fuzzers (tests/fuzz: libFuzzer is clang's, its runtime in
	# libclang-rt) and the ThreadSanitizer build of CI
	clang libclang-rt-14-dev
	# the style of changed C++ files (.clang-format, the test clang-format)
	clang-format
	# the data tests' scorer (../shared/tools/eval.py) and scripts/quality.py
	python3-numpy
	# the Python module (python/: pip install --no-build-isolation ., its
	# tests, scripts/check-pip-install.sh)
	python3-dev pybind11-dev python3-mesonpy python3-pytest python3-venv python3-pip
	# the CMake package (its version file comes from cmake's templates) and
	# its test; dpkg-shlibdeps for scripts/build-debs.sh
	cmake dpkg-dev
	# the GStreamer element and its examples
	libgstreamer1.0-dev libgstreamer-plugins-base1.0-dev
	gstreamer1.0-tools gstreamer1.0-plugins-base gstreamer1.0-plugins-good
	# video and markers in one MPEG-TS (examples/stream-markers.sh and its
	# test: mpegtsmux, tsdemux, h264parse, pnmdec; x264enc; avdec_h264)
	gstreamer1.0-plugins-bad gstreamer1.0-plugins-ugly gstreamer1.0-libav
	# the typelib GstFrappe-1.0 of gstfrappemeta and its Python test
	gobject-introspection libgirepository1.0-dev gir1.2-gstreamer-1.0 gir1.2-gst-plugins-base-1.0
	python3-gi python3-gst-1.0
	# the examples' test (stream-h264-rtp.sh: x264enc, avdec_h264), the page in
	# a real browser (frappe-watch, tests/host), the man pages rendered (groff)
	gstreamer1.0-plugins-ugly gstreamer1.0-libav chromium groff-base
	# the Raspberry Pis' CPUs, emulated: the core and vc4 suites cross-built
	# for ARMv6 (scripts/arm/armv6-armel.ini) and aarch64
	# (scripts/arm/armv8-arm64.ini), and the ARMv6 kernels' test (tests/armv6)
	qemu-user crossbuild-essential-armel crossbuild-essential-arm64
	libgtest-dev:armel libgmock-dev:armel
	libhwy-dev:arm64 libgtest-dev:arm64 libgmock-dev:arm64
	# (scripts/arm-count.sh --arch aarch64 --setup adds its image decoding,
	# libpng, libjpeg and zlib for arm64: not needed to build or test, and
	# installing them moves the host's copies to the same version)
)

if [ "$(id -u)" -ne 0 ]; then
	exec sudo "$0" "$@"
fi
export DEBIAN_FRONTEND=noninteractive
# The cross builds' libraries through multiarch: GoogleTest for armel (the
# cross toolchain's own libc and libstdc++ are used there), GoogleTest and
# Highway for arm64 (the update below then lists their packages).
for arch in armel arm64; do
	dpkg --print-foreign-architectures | grep -qx "$arch" || dpkg --add-architecture "$arch"
done
missing=()
for p in "${packages[@]}"; do
	dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
	apt-get update -qq
	# --force-unsafe-io: dpkg skips its fsync of every unpacked file (about
	# 470 packages on a fresh machine; reinstalling chromium and libllvm14
	# took 49 s with it against 59 s); a crash mid-install means running
	# this again.
	apt-get install -y -qq --no-install-recommends -o Dpkg::Options::=--force-unsafe-io "${missing[@]}"
fi
