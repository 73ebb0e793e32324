# SPDX-License-Identifier: MIT
"""frappe-receive: prints a robot's marker stream (frappejson over UDP or TCP)
frame by frame, or writes it as JSON lines, one whole frame a line; counts the
frames lost on the way.

  frappe-receive --udp 5001                 # the robot: frappejson ! udpsink host=THIS_HOST port=5001
  frappe-receive --tcp robot.local:5001     # the robot: frappejson ! tcpserversink port=5001
  frappe-receive --tcp robot.local:5001 --jsonl markers.jsonl

TCP connects again, with back-off, while the robot is not up and after it goes
away. One line a frame: its number, its PTS (seconds), then per marker its id and,
when the robot knows the pose, the marker centre in the camera frame (metres; x
right, y down, z forward) and its distance. At the end (Ctrl-C, --count,
--timeout) a summary on stderr: frames, lost, incomplete, restarts, reconnects.
"""

import argparse
import dataclasses
import json
import sys

from . import stream


def describe(frame: stream.Frame) -> str:
    """A frame on one line, for people."""
    head = f"frame {frame.number}"
    if frame.pts is not None:
        head += f" t={frame.pts / 1e9:.3f}s"
    if not frame.complete:
        head += " (incomplete)"
    parts = []
    for m in frame.markers:
        if m.pose is not None:
            x, y, z = m.pose.tvec
            parts.append(f"id {m.id} at ({x:+.4f}, {y:+.4f}, {z:.4f}) m, {m.pose.distance:.3f} m away")
        else:
            cx, cy = m.center
            parts.append(f"id {m.id} at pixel ({cx:.1f}, {cy:.1f}), no pose")
    return head + ": " + ("; ".join(parts) if parts else "no markers")


def as_json(frame: stream.Frame) -> str:
    """A frame as one JSON line: the Frame's fields, markers with their pose."""
    return json.dumps(dataclasses.asdict(frame), separators=(",", ":"))


def parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="frappe-receive", description=__doc__.split("\n\n")[0],
                                epilog="See docs/host.md (the Python module frappe.stream).")
    src = p.add_mutually_exclusive_group(required=True)
    src.add_argument("--udp", type=int, metavar="PORT", help="receive datagrams on PORT")
    src.add_argument("--tcp", metavar="HOST:PORT", help="connect to the robot's tcpserversink at HOST:PORT")
    p.add_argument("--bind", default="0.0.0.0", metavar="ADDRESS",
                   help="address to receive UDP on (default: all)")
    p.add_argument("--jsonl", metavar="FILE",
                   help="write each frame as a JSON line to FILE ('-': standard output) instead of printing")
    p.add_argument("--count", type=int, default=0, metavar="N", help="stop after N frames (default: never)")
    p.add_argument("--timeout", type=float, default=None, metavar="SECONDS",
                   help="stop when no frame came for SECONDS (default: wait for ever)")
    p.add_argument("--incomplete", action="store_true",
                   help="also deliver frames with parts missing, flagged incomplete (default: count them lost)")
    p.add_argument("--no-reconnect", action="store_true", help="TCP: stop when the connection closes")
    return p


def main(argv=None) -> int:
    args = parser().parse_args(argv)
    try:
        if args.udp is not None:
            receiver = stream.udp(args.udp, args.bind, incomplete=args.incomplete)
        else:
            host, _, port = args.tcp.rpartition(":")
            if not port.isdigit():
                print(f"frappe-receive: --tcp {args.tcp}: expected HOST:PORT", file=sys.stderr)
                return 2
            receiver = stream.tcp(host.strip("[]") or "127.0.0.1", int(port), reconnect=not args.no_reconnect,
                                  incomplete=args.incomplete,
                                  log=lambda text: print(f"frappe-receive: {text}", file=sys.stderr, flush=True))
    except OSError as e:
        print(f"frappe-receive: cannot listen on udp {args.bind}:{args.udp}: {e}", file=sys.stderr)
        return 1
    out = None
    if args.jsonl:
        out = sys.stdout if args.jsonl == "-" else open(args.jsonl, "w", encoding="utf-8")
    print(f"frappe-receive: {'listening on' if args.udp is not None else 'connecting to'} {receiver.address}",
          file=sys.stderr, flush=True)
    frames = 0
    try:
        for frame in receiver.frames(args.timeout):
            print(as_json(frame) if out else describe(frame), file=out or sys.stdout, flush=True)
            frames += 1
            if args.count and frames >= args.count:
                break
    except KeyboardInterrupt:
        pass
    finally:
        receiver.flush()
        receiver.close()
        if out not in (None, sys.stdout):
            out.close()
    s = receiver.stats
    print(f"frappe-receive: {s.frames} frames, {s.lost} lost, {s.incomplete} incomplete, {s.late} late parts, "
          f"{s.restarts} restarts, {s.reconnects} reconnects, {s.bad_lines} bad lines", file=sys.stderr)
    for error in receiver.errors:
        print(f"frappe-receive: {error}", file=sys.stderr)
    if frames == 0 and args.timeout is not None:
        print(f"frappe-receive: no frame in {args.timeout} s", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
