#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""examples/stream-markers.sh and examples/receive-markers.py on loopback,
the sample video standing in for the camera and x264enc for the Pi's
encoder: the receiver gets all 120 frames with marker 0 at z = 0.27 m (1 %)
(MAX_BYTES=0: one datagram per frame, as receive-markers.py reads them), and
the video branch sends MPEG-TS datagrams (7 packets of 188 bytes) to its
port (check_stream_pairing.py pairs them). Exit 77 when x264enc, mpegtsmux
or the sample's decoder is missing."""
import os
import re
import socket
import subprocess
import sys

MARKER = re.compile(r"id (\d+) at \(([-+\d.]+), ([-+\d.]+), ([-+\d.]+)\) m")


def free_udp_socket():
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    s.bind(("127.0.0.1", 0))
    return s


def main():
    script, receiver, video, calibration = sys.argv[1:5]
    # The video port is held open by us (its packets are counted); the
    # marker port is found free, closed and handed to the receiver.
    video_sock = free_udp_socket()
    video_sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 1 << 22)
    probe = free_udp_socket()
    marker_port = probe.getsockname()[1]
    probe.close()

    recv = subprocess.Popen([sys.executable, receiver, f"udp://127.0.0.1:{marker_port}", "120"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    recv.stderr.readline()  # "receiving on ...": bound before anything is sent
    env = dict(os.environ, HOST="127.0.0.1", VIDEO_PORT=str(video_sock.getsockname()[1]),
               MARKER_PORT=str(marker_port), CALIBRATION=calibration, QUEUE="queue",
               SOURCE=f"filesrc location={video} ! decodebin ! videoconvert",
               MAX_BYTES="0", ENCODER="x264enc tune=zerolatency speed-preset=ultrafast ! h264parse")
    sender = subprocess.run(["sh", script], env=env, capture_output=True, text=True, timeout=120)
    if sender.returncode != 0:
        recv.kill()
        print(sender.stdout + sender.stderr)
        return 77 if "no element" in sender.stderr else 1
    out, err = recv.communicate(timeout=60)
    if recv.returncode != 0:
        print(f"receiver failed: {err}")
        return 1

    frames = out.splitlines()
    if len(frames) != 120 or "lost=0," not in err:
        print(f"expected 120 frames, got {len(frames)}:\n{err}")
        return 1
    worst = 0.0
    for line in frames:
        found = {int(m[0]): float(m[3]) for m in MARKER.findall(line)}
        if sorted(found) != [0, 7, 23, 42]:
            print(f"frame without the four markers and poses: {line}")
            return 1
        worst = max(worst, abs(found[0] - 0.27) / 0.27)

    video_sock.setblocking(False)
    packets = 0
    try:
        while True:
            data = video_sock.recv(65536)
            if len(data) != 7 * 188 or any(data[i] != 0x47 for i in range(0, len(data), 188)):
                print(f"a video datagram of {len(data)} bytes that is not 7 TS packets")
                return 1
            packets += 1
    except BlockingIOError:
        pass
    print(f"receiver: 120 frames, marker 0 depth error {100 * worst:.2f} %; video: {packets} MPEG-TS datagrams")
    return 0 if worst < 0.01 and packets > 0 else 1


if __name__ == "__main__":
    sys.exit(main())
