#!/usr/bin/env bash
# Checks the Python package as a new user gets it: pip install . into a
# fresh virtual environment (with the system's meson-python, pybind11 and
# numpy, --no-build-isolation: no network needed), then, from outside the
# source tree, imports frappe, detects a rendered marker and estimates its
# pose; frappe-receive, a console script, runs. Prints the time taken; about
# 4 minutes of compiling on two cores.
#   scripts/check-pip-install.sh [PYTHON]     (default /usr/bin/python3)
set -euo pipefail

src=$(cd "$(dirname "$0")/.." && pwd)
python=${1:-/usr/bin/python3}
work=$(mktemp -d "${TMPDIR:-/tmp}/frappe-pip.XXXXXX")
trap 'rm -rf "$work"' EXIT
start=$(date +%s)

"$python" -m venv --system-site-packages "$work/venv"
"$work/venv/bin/pip" install --no-build-isolation --no-index --quiet "$src"

# Nothing but the package and its two commands went into the environment.
"$work/venv/bin/pip" show --files frappe-markers | sed -n '/^Files:/,$p' | tail -n +2 | sed 's/^ *//' |
	grep -v -e '^frappe/' -e '^frappe_markers-.*\.dist-info/' -e '^\.\./\.\./\.\./bin/frappe-receive$' \
		-e '^\.\./\.\./\.\./bin/frappe-watch$' && {
	echo "check-pip-install: files outside the package were installed" >&2
	exit 1
}

cd "$work"
"$work/venv/bin/frappe-receive" --help | grep -q -- '--udp PORT' || {
	echo "check-pip-install: frappe-receive --help does not list --udp" >&2
	exit 1
}
FRAPPE_SRC=$src "$work/venv/bin/python" - <<'PY'
import numpy as np
import frappe

assert frappe.__file__.startswith(__import__("sys").prefix), frappe.__file__
marker = frappe.render_marker("aruco_mip_36h12", 42, cell_px=12)
image = np.full((300, 400), 200, np.uint8)
image[100:100 + marker.shape[0], 150:150 + marker.shape[1]] = marker
found = frappe.Detector("aruco_mip_36h12").detect(image)
assert [m.id for m in found] == [42], found
# The border's outer corners: 12 px of quiet zone, pixel centres at integers.
truth = np.array([[161.5, 111.5], [257.5, 111.5], [257.5, 207.5], [161.5, 207.5]])
assert np.abs(found[0].corners - truth).max() < 0.5, found[0].corners
# Seen by a 600 px pinhole centred at (199.5, 149.5), a 96 px marker of
# 9.6 cm is 0.6 m away, its centre (209.5, 159.5) 1 cm right and down.
pose = frappe.estimate_pose(found[0], 0.096, frappe.Camera.pinhole(600, 600, 199.5, 149.5))
assert np.abs(pose.tvec - [0.01, 0.01, 0.6]).max() < 1e-3, pose
cam = frappe.read_calibration(__import__("os").environ["FRAPPE_SRC"] + "/examples/data/camera-700.yaml")
assert (cam.fx, cam.width) == (700.0, 640), cam
print(f"check-pip-install: frappe {frappe.__version__} from {frappe.__file__}: {found[0]}, {pose}")
PY
echo "check-pip-install: passed in $(($(date +%s) - start)) s"
