#!/bin/sh
# SPDX-License-Identifier: MIT
# Headless annotated video for a browser: frappe-watch serves a page at
# http://THIS_HOST:${PORT:-8080}/ with the annotated video (MJPEG over HTTP, a
# multipart/x-mixed-replace answer any browser shows, also at /video.mjpeg for
# VLC or an <img>) and the markers listed beside it (/markers.json).
# SOURCE defaults to the sample video, looping; on a Pi use
#   SOURCE='libcamerasrc ! video/x-raw,width=640,height=480,framerate=30/1' FORMAT=NV12 \
#   ENCODER=v4l2jpegenc examples/stream-mjpeg.sh
# (v4l2jpegenc: the VideoCore's hardware encoder). DETECT adds frappedetect's
# properties, e.g. DETECT='marker-size=0.05 calibration-file=camera.yaml'.
# From a build tree (GST_PLUGIN_PATH, the Python package in python/) or installed
# (frappe-watch on PATH, from python3-frappe).
set -eu
here="$(cd "$(dirname "$0")" && pwd)"
export GST_PLUGIN_PATH="${GST_PLUGIN_PATH:-$here/../build/gst}"
set -- --port "${PORT:-8080}" --format "${FORMAT:-I420}" --encoder "${ENCODER:-jpegenc quality=80}" \
	--detect "${DETECT:-}"
if [ -n "${SOURCE:-}" ]; then
	set -- "$@" --source "$SOURCE"
else
	set -- "$@" --file "$here/data/markers.webm" --loop
fi
if [ -f "$here/../python/frappe/watch.py" ]; then
	PYTHONPATH="$here/../python${PYTHONPATH:+:$PYTHONPATH}" exec /usr/bin/python3 -m frappe.watch "$@"
fi
exec frappe-watch "$@"
