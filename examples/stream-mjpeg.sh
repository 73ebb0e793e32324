#!/bin/sh
# SPDX-License-Identifier: MIT
# Headless annotated streaming as MJPEG over TCP (multipart, so a browser
# or VLC can show http-less "tcp://HOST:8080"; e.g. on the viewer:
#   gst-launch-1.0 tcpclientsrc host=PI port=8080 ! multipartdemux ! jpegdec ! autovideosink
# ).
# SOURCE defaults to the sample video in a loop-free single pass; on a Pi use
#   SOURCE='libcamerasrc ! video/x-raw,format=I420,width=640,height=480,framerate=30/1'
# and replace jpegenc by v4l2jpegenc (the VideoCore's hardware encoder).
set -eu
here="$(cd "$(dirname "$0")" && pwd)"
export GST_PLUGIN_PATH="${GST_PLUGIN_PATH:-$here/../build/gst}"
SOURCE="${SOURCE:-filesrc location=$here/data/markers.webm ! decodebin ! videoconvert ! video/x-raw,format=I420 ! identity sync=true}"
ENCODER="${ENCODER:-jpegenc quality=80}"
# SOURCE and ENCODER are pipeline fragments: eval keeps their quoting.
eval exec gst-launch-1.0 "$SOURCE ! frappedetect annotate=true ! $ENCODER ! \
	multipartmux boundary=frame ! tcpserversink host=0.0.0.0 port=${PORT:-8080}"
