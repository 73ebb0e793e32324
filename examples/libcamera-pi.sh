#!/bin/sh
# SPDX-License-Identifier: MIT
# Raspberry Pi camera through libcamerasrc (package gstreamer1.0-libcamera),
# headless: marker messages on stdout, nothing displayed.
#
# libcamera 0.0.3 (Debian 12) offers no GRAY8: ask for NV12 or I420 and
# frappedetect reads the luma plane only, zero-copy (the dmabuf is mapped
# read-only). Keep the width a multiple of 64: that libcamera attaches no
# GstVideoMeta, so other widths would be read with the wrong stride.
#
# The default backend=auto runs the front end on the QPUs when the GPU can be
# used (legacy firmware stack, no vc4-kms-v3d overlay: vc4/BRINGUP.md) and on the
# CPU otherwise, with one warning saying why.
#
# Pose: set marker-size (metres) and your camera's calibration-file (ROS
# camera_calibration's YAML or OpenCV's, at any size of the same aspect
# ratio) or camera-matrix (the numbers below are only a plausible guess for
# a v2 camera at 640x480).
set -eu
export GST_PLUGIN_PATH="${GST_PLUGIN_PATH:-$(cd "$(dirname "$0")/.." && pwd)/build/gst}"
exec gst-launch-1.0 -m libcamerasrc ! \
	video/x-raw,format=NV12,width=640,height=480,framerate=30/1 ! \
	frappedetect pipelined=true dictionary=aruco_mip_36h12 marker-size=0.05 \
		camera-matrix="<500.0,0.0,319.5,0.0,500.0,239.5,0.0,0.0,1.0>" ! \
	fakesink sync=false
