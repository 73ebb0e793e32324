#!/bin/sh
# SPDX-License-Identifier: MIT
# Headless annotated streaming as H.264 over RTP/UDP to HOST:5000.
# Viewer:
#   gst-launch-1.0 udpsrc port=5000 caps="application/x-rtp,media=video,encoding-name=H264,payload=96,clock-rate=90000" ! \
#       rtph264depay ! h264parse ! avdec_h264 ! videoconvert ! autovideosink
#
# On a Raspberry Pi the hardware encoder is v4l2h264enc (bcm2835-codec).
# Pin the level or the encoder fails at run time, repeat the SPS/PPS for
# receivers that join late, and import the camera's dmabufs (keep the
# width a multiple of 64 so the strides match):
#   ENCODER='v4l2h264enc output-io-mode=dmabuf-import extra-controls="controls,repeat_sequence_header=1" ! "video/x-h264,level=(string)4"'
#   SOURCE='libcamerasrc ! video/x-raw,format=I420,width=640,height=480,framerate=30/1'
# Elsewhere x264enc (gstreamer1.0-plugins-ugly) or openh264enc
# (gstreamer1.0-plugins-bad) do the same in software.
set -eu
here="$(cd "$(dirname "$0")" && pwd)"
export GST_PLUGIN_PATH="${GST_PLUGIN_PATH:-$here/../build/gst}"
SOURCE="${SOURCE:-filesrc location=$here/data/markers.webm ! decodebin ! videoconvert ! video/x-raw,format=I420 ! identity sync=true}"
ENCODER="${ENCODER:-x264enc tune=zerolatency speed-preset=ultrafast key-int-max=30}"
HOST="${HOST:-127.0.0.1}"
# SOURCE and ENCODER are pipeline fragments: eval keeps their quoting.
eval exec gst-launch-1.0 "$SOURCE ! frappedetect annotate=true ! $ENCODER ! \
	h264parse config-interval=-1 ! rtph264pay pt=96 ! udpsink host=$HOST port=${PORT:-5000}"
