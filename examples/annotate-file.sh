#!/bin/sh
# SPDX-License-Identifier: MIT
# A video file through frappedetect annotate=true into an annotated WebM,
# printing every frame's frappedetect message (-m).
#   examples/annotate-file.sh [INPUT] [OUTPUT]   (default: the sample video)
set -eu
here="$(cd "$(dirname "$0")" && pwd)"
in="${1:-$here/data/markers.webm}"
out="${2:-annotated.webm}"
export GST_PLUGIN_PATH="${GST_PLUGIN_PATH:-$here/../build/gst}"
exec gst-launch-1.0 -m filesrc location="$in" ! decodebin ! videoconvert ! \
	video/x-raw,format=I420 ! frappedetect annotate=true ! \
	videoconvert ! vp8enc deadline=1 ! webmmux ! filesink location="$out"
