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
	# the data tests' scorer (../shared/tools/eval.py) and scripts/quality.py
	python3-numpy
	# the GStreamer element and its examples
	libgstreamer1.0-dev libgstreamer-plugins-base1.0-dev
	gstreamer1.0-tools gstreamer1.0-plugins-base gstreamer1.0-plugins-good
)

if [ "$(id -u)" -ne 0 ]; then
	exec sudo "$0" "$@"
fi
export DEBIAN_FRONTEND=noninteractive
missing=()
for p in "${packages[@]}"; do
	dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
	apt-get update -qq
	apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
