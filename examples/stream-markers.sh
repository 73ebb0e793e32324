#!/bin/sh
# SPDX-License-Identifier: MIT
# The robot's side of "video and markers side by side": one camera, one
# detection (frappedetect annotate=true), then a tee:
#   video:   the annotated frames as H.264 and, beside them, each frame's
#            marker lines (frappejson as KLV) in one MPEG transport stream,
#            UDP datagrams of 7 TS packets to HOST:VIDEO_PORT. The host's
#            tsdemux gives a decoded frame and its markers the same PTS:
#            python/frappe/video.py pairs them (docs/streaming.md).
#   markers: the same lines alone, datagrams of at most MAX_BYTES (a frame
#            in parts when it needs more: 1400 fits an Ethernet frame) to
#            HOST:MARKER_PORT, or with TRANSPORT=tcp whole lines from a
#            tcpserversink on MARKER_PORT that the host connects to.
# Each line carries the frame's number since start, its PTS, running time,
# size, FRAME_ID and capture time (docs/streaming.md, "The marker line").
# On the host:
#   python3 -c 'from frappe.video import receive_ts
#   for f in receive_ts(port=5000): print(f.line["frame"], [m["id"] for m in f.markers])'
#   gst-launch-1.0 udpsrc port=5000 caps=video/mpegts,systemstream=true ! tsdemux ! \
#       h264parse ! avdec_h264 ! videoconvert ! autovideosink     (or: vlc udp://@:5000)
#   examples/receive-markers.py udp://:5001   (the markers alone; tcp://ROBOT:5001)
#
# CALIBRATION must be your camera's (ROS camera_calibration's YAML or an
# OpenCV one) at any size of the same aspect ratio: the default is the
# sample video's 700 px pinhole. MARKER_SIZE is the black square's side in
# metres. The queues are leaky so that a slow branch drops frames rather
# than stalling the camera (a dropped frame is a missing `frame` number on
# the host); set QUEUE=queue to keep every frame (files). SOURCE, ENCODER
# and QUEUE are pipeline fragments (a file stands in for the camera with
# SOURCE='filesrc location=... ! decodebin ! videoconvert'; on a PC,
# ENCODER='x264enc tune=zerolatency speed-preset=ultrafast ! h264parse').
set -eu
here="$(cd "$(dirname "$0")" && pwd)"
export GST_PLUGIN_PATH="${GST_PLUGIN_PATH:-$here/../build/gst}"
HOST="${HOST:-192.168.1.10}"
VIDEO_PORT="${VIDEO_PORT:-5000}"
MARKER_PORT="${MARKER_PORT:-5001}"
SOURCE="${SOURCE:-libcamerasrc ! video/x-raw,format=NV12,width=640,height=480,framerate=30/1}"
ENCODER="${ENCODER:-v4l2h264enc extra-controls=\"controls,repeat_sequence_header=1\" ! \
\"video/x-h264,level=(string)4\" ! h264parse}"
CALIBRATION="${CALIBRATION:-$here/data/camera-700.yaml}"
MARKER_SIZE="${MARKER_SIZE:-0.05}"
FRAME_ID="${FRAME_ID:-camera}"
MAX_BYTES="${MAX_BYTES:-1400}"
QUEUE="${QUEUE:-queue leaky=downstream max-size-buffers=2}"
if [ "${TRANSPORT:-udp}" = tcp ]; then
	MARKERS="frappejson frame-id=$FRAME_ID max-bytes=0 ! tcpserversink host=0.0.0.0 port=$MARKER_PORT sync=false"
else
	MARKERS="frappejson frame-id=$FRAME_ID max-bytes=$MAX_BYTES ! udpsink host=$HOST port=$MARKER_PORT sync=false"
fi
# eval keeps the fragments' quoting.
eval exec gst-launch-1.0 -e "$SOURCE ! \
	frappedetect annotate=true marker-size=$MARKER_SIZE calibration-file=\"$CALIBRATION\" ! tee name=t \
	t. ! $QUEUE ! videoconvert ! $ENCODER ! mpegtsmux name=mux alignment=7 ! \
		udpsink host=$HOST port=$VIDEO_PORT sync=false \
	t. ! $QUEUE ! frappejson frame-id=$FRAME_ID max-bytes=0 ! meta/x-klv,parsed=true ! mux. \
	t. ! $QUEUE ! $MARKERS"
