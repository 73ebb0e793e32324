#!/bin/sh
# SPDX-License-Identifier: MIT
# Builds the peers of frappe-peers (issue 35) outside the tree: ArUco 3's
# detector and aruco_nano, against the system's OpenCV 4, into a prefix that
# meson's -Daruco3_prefix takes (docs/speed.md says where the sources come
# from and which build fixes they need).
#
#   tests/bench/build-aruco3.sh SRC PREFIX
#
# SRC holds the peers' own files as fetched: include/aruco/*.h,
# src/aruco/{markerdetector,marker,dictionary,markerlabeler,debug}.cpp,
# src/aruco/markerlabelers/dictionary_based.{h,cpp}, and aruco_nano.h in
# the folder aruco_nano.
# Only the detector is built: no camera calibration, pose, boards or SVM
# labeler, so a few symbols the detector's camera-parameter overloads name
# are stubbed here (never called without camera parameters), and
# dictionary.cpp is compiled from a trimmed copy (below): as published it
# includes the boards' markermap.h, which is not fetched.
set -eu
[ $# -eq 2 ] || { echo "usage: $0 SRC PREFIX" >&2; exit 2; }
SRC=$(cd "$1" && pwd)
PREFIX=$2
OBJ=$PREFIX/obj
mkdir -p "$OBJ" "$PREFIX/lib" "$PREFIX/include/aruco"
cat > "$OBJ/aruco3_stubs.cpp" <<'EOF'
// Link stubs (not ArUco's code): cameraparameters.cpp is not built.
#include "cameraparameters.h"
#include <cstdlib>
#include <iostream>
namespace aruco
{
CameraParameters::CameraParameters() : CamSize(-1, -1) {}
CameraParameters::CameraParameters(const CameraParameters &CI) { *this = CI; }
CameraParameters &CameraParameters::operator=(const CameraParameters &CI)
{
  CI.CameraMatrix.copyTo(CameraMatrix);
  CI.Distorsion.copyTo(Distorsion);
  CI.ExtrinsicMatrix.copyTo(ExtrinsicMatrix);
  CamSize = CI.CamSize;
  return *this;
}
void CameraParameters::resize(cv::Size)
{
  std::cerr << "aruco3 scratch build: CameraParameters::resize is not built\n";
  std::abort();
}
} // namespace aruco
EOF
# As CMake's Release build would. ArUco 3.0's dictionary_based.cpp names
# OpenCV 3's C constant CV_BGR2GRAY, which OpenCV 4 keeps in types_c.h.
CXXFLAGS="-O3 -DNDEBUG -std=c++11 -fPIC -I$SRC/include/aruco -I$SRC/src/aruco $(pkg-config --cflags opencv4)"
# dictionary.cpp as published (276 KB) holds thirteen dictionaries' tables and
# two functions that need the boards' markermap.h (createMarkerMap; and
# getMarkerImage_id, whose definition no longer matches dictionary.h at
# 02badc8). The copy compiled keeps loadPredefined's ARUCO_MIP_36h12, CUSTOM
# and ALL_DICTS cases and drops the include and those two functions; an
# already trimmed file passes through unchanged.
awk '
	$0 == "#include \"markermap.h\"" { next }
	/^(cv::Mat Dictionary::getMarkerImage_id|MarkerMap Dictionary::createMarkerMap)\(/ { drop = 1 }
	drop { if ($0 == "}") drop = 0; next }
	/^Dictionary Dictionary::loadPredefined\(DICT_TYPES type\)/ { inlp = 1 }
	inlp && $0 == "}" { inlp = 0 }
	inlp && /^    case [A-Za-z0-9_]+:$/ { skip = ($0 !~ /case (ARUCO_MIP_36h12|CUSTOM|ALL_DICTS):$/) }
	inlp && /^    default:$/ { skip = 0 }
	!skip { print }
' "$SRC/src/aruco/dictionary.cpp" > "$OBJ/dictionary.cpp"
grep -q '0xd2b63a09dUL, 0x6001134e5UL, 0x1206fbe72UL' "$OBJ/dictionary.cpp" ||
	{ echo "$0: ARUCO_MIP_36h12's table not found in $SRC/src/aruco/dictionary.cpp" >&2; exit 1; }
for f in "$SRC"/src/aruco/markerdetector.cpp "$SRC"/src/aruco/marker.cpp "$OBJ/dictionary.cpp" \
	"$SRC"/src/aruco/markerlabeler.cpp "$SRC"/src/aruco/markerlabelers/dictionary_based.cpp \
	"$SRC"/src/aruco/debug.cpp "$OBJ/aruco3_stubs.cpp"; do
	# shellcheck disable=SC2086
	g++ $CXXFLAGS -include opencv2/imgproc/types_c.h -c "$f" -o "$OBJ/$(basename "$f" .cpp).o"
done
rm -f "$PREFIX/lib/libaruco3.a"
ar rcs "$PREFIX/lib/libaruco3.a" "$OBJ"/*.o
cp "$SRC"/include/aruco/*.h "$PREFIX/include/aruco/"
cp "$SRC/aruco_nano/aruco_nano.h" "$PREFIX/include/"
echo "$PREFIX/lib/libaruco3.a; now: meson setup --reconfigure build -Daruco3_prefix=$PREFIX"
