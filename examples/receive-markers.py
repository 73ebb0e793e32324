#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Host side of stream-markers.sh: reads frappejson's lines (one JSON object
per frame) from UDP or TCP and prints each frame's markers and poses.
Python's standard library only.

  receive-markers.py --udp 5001                 # udpsink host=THIS_HOST port=5001
  receive-markers.py --tcp robot.local:5001     # tcpserversink port=5001 on the robot

One line per frame: the time (the buffer's PTS, seconds), then per marker its
id and, when the robot knows the pose, the marker centre in the camera frame
(metres; x right, y down, z forward) and its distance."""
import argparse
import json
import math
import socket
import sys


def describe(frame):
    pts = frame.get("pts")
    head = "t=?" if pts is None else f"t={pts / 1e9:.3f}s"
    parts = []
    for m in frame.get("markers", []):
        tvec = m.get("tvec")
        if tvec and all(v is not None for v in tvec):
            x, y, z = tvec
            parts.append(f"id {m['id']} at ({x:+.4f}, {y:+.4f}, {z:.4f}) m, {math.sqrt(x*x + y*y + z*z):.3f} m away")
        else:
            cx = sum(c[0] for c in m["corners"]) / 4
            cy = sum(c[1] for c in m["corners"]) / 4
            parts.append(f"id {m['id']} at pixel ({cx:.1f}, {cy:.1f}), no pose")
    return head + ": " + ("; ".join(parts) if parts else "no markers")


def lines_udp(port, bind, timeout):
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 1 << 20)
    sock.bind((bind, port))
    sock.settimeout(timeout)
    print(f"listening on udp {bind}:{port}", file=sys.stderr, flush=True)
    while True:
        data, _ = sock.recvfrom(65536)  # one datagram per frame
        yield from data.decode("utf-8").splitlines()


def lines_tcp(address, timeout):
    host, _, port = address.rpartition(":")
    sock = socket.create_connection((host or "127.0.0.1", int(port)), timeout=timeout)
    print(f"connected to tcp {host}:{port}", file=sys.stderr, flush=True)
    pending = b""
    while True:
        data = sock.recv(65536)
        if not data:
            return  # the robot stopped
        pending += data
        *complete, pending = pending.split(b"\n")
        for line in complete:
            yield line.decode("utf-8")


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    src = p.add_mutually_exclusive_group(required=True)
    src.add_argument("--udp", type=int, metavar="PORT", help="receive datagrams on PORT")
    src.add_argument("--tcp", metavar="HOST:PORT", help="connect to tcpserversink at HOST:PORT")
    p.add_argument("--bind", default="0.0.0.0", help="UDP address to listen on (default all)")
    p.add_argument("--count", type=int, default=0, help="stop after COUNT frames (default: never)")
    p.add_argument("--timeout", type=float, default=None, help="give up after TIMEOUT s without data")
    p.add_argument("--raw", action="store_true", help="print the JSON lines as they come")
    args = p.parse_args()

    lines = lines_udp(args.udp, args.bind, args.timeout) if args.udp else lines_tcp(args.tcp, args.timeout)
    frames = 0
    try:
        for line in lines:
            if not line.strip():
                continue
            try:
                frame = json.loads(line)
            except json.JSONDecodeError as e:
                print(f"not JSON ({e}): {line[:80]!r}", file=sys.stderr)
                continue
            print(line if args.raw else describe(frame), flush=True)
            frames += 1
            if args.count and frames >= args.count:
                break
    except socket.timeout:
        print(f"no data for {args.timeout} s after {frames} frames", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        pass
    return 0


if __name__ == "__main__":
    sys.exit(main())
