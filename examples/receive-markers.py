#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The host's side of stream-markers.sh with frappe.stream: every frame's
markers and poses, reconnecting through robot restarts (TCP), parts put back
together and lost frames counted (docs/host.md).

  receive-markers.py udp://:5001 [FRAMES]          # the robot's udpsink host=THIS_HOST port=5001
  receive-markers.py tcp://robot.local:5001        # the robot's tcpserversink port=5001"""
import os
import sys

try:
    from frappe import stream
except ImportError:  # from a checkout: the package's pure-Python part is enough
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "python"))
    from frappe import stream

url, count = sys.argv[1], int(sys.argv[2]) if len(sys.argv) > 2 else 0
with stream.open_url(url) as markers:
    print(f"receiving on {markers.address}", file=sys.stderr, flush=True)
    for n, frame in enumerate(markers, 1):  # for ever, or FRAMES frames
        print(f"frame {frame.number}:", "; ".join(
            f"id {m.id} at ({m.pose.tvec[0]:+.4f}, {m.pose.tvec[1]:+.4f}, {m.pose.tvec[2]:.4f}) m" if m.pose
            else f"id {m.id} at pixel {m.center}" for m in frame.markers), flush=True)
        if n == count:
            break
print(markers.stats, file=sys.stderr)
