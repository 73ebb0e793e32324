#!/bin/sh
# SPDX-License-Identifier: MIT
# The robot's side of "video and markers side by side": one camera, a tee,
# two streams to the host.
#   video:   H.264 over RTP/UDP to HOST:VIDEO_PORT (the Pi's v4l2h264enc);
#   markers: frappedetect ! frappejson, one JSON line per frame, as one UDP
#            datagram each to HOST:MARKER_PORT, or with TRANSPORT=tcp from a
#            tcpserversink on MARKER_PORT that the host connects to.
# On the host:
#   examples/receive-markers.py --udp 5001          (or --tcp ROBOT:5001)
#   gst-launch-1.0 udpsrc port=5000 caps="application/x-rtp,media=video,encoding-name=H264,clock-rate=90000" ! \
#       rtpjitterbuffer ! rtph264depay ! avdec_h264 ! videoconvert ! autovideosink
# Both carry the frame's PTS (RTP timestamp, "pts" in the JSON) to match them.
#
# CALIBRATION must be your camera's (ROS camera_calibration's YAML or an
# OpenCV one) at any size of the same aspect ratio: the default is the
# sample video's 700 px pinhole. MARKER_SIZE is the black square's side in
# metres. The queues are leaky so that a slow branch drops frames rather
# than stalling the camera; set QUEUE=queue to keep every frame (files).
# SOURCE, ENCODER and QUEUE are pipeline fragments (a file stands in for
# the camera with SOURCE='filesrc location=... ! decodebin ! videoconvert').
set -eu
here="$(cd "$(dirname "$0")" && pwd)"
export GST_PLUGIN_PATH="${GST_PLUGIN_PATH:-$here/../build/gst}"
HOST="${HOST:-192.168.1.10}"
VIDEO_PORT="${VIDEO_PORT:-5000}"
MARKER_PORT="${MARKER_PORT:-5001}"
SOURCE="${SOURCE:-libcamerasrc ! video/x-raw,format=NV12,width=640,height=480,framerate=30/1}"
ENCODER="${ENCODER:-v4l2h264enc extra-controls=\"controls,repeat_sequence_header=1\" ! \
\"video/x-h264,level=(string)4\" ! h264parse ! rtph264pay config-interval=1 pt=96}"
CALIBRATION="${CALIBRATION:-$here/data/camera-700.yaml}"
MARKER_SIZE="${MARKER_SIZE:-0.05}"
QUEUE="${QUEUE:-queue leaky=downstream max-size-buffers=2}"
if [ "${TRANSPORT:-udp}" = tcp ]; then
	MARKERS="tcpserversink host=0.0.0.0 port=$MARKER_PORT sync=false"
else
	MARKERS="udpsink host=$HOST port=$MARKER_PORT sync=false"
fi
# eval keeps the fragments' quoting.
eval exec gst-launch-1.0 -e "$SOURCE ! tee name=t \
	t. ! $QUEUE ! $ENCODER ! udpsink host=$HOST port=$VIDEO_PORT sync=false \
	t. ! $QUEUE ! frappedetect marker-size=$MARKER_SIZE calibration-file=\"$CALIBRATION\" ! \
		frappejson ! $MARKERS"
