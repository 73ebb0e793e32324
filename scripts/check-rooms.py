#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""frappe-core/src's rooms include downwards only (the test rooms).

    scripts/check-rooms.py

A room's files may include headers of the rooms below it, never of one
above or beside it unless listed: base at the bottom; dictionary,
front_end, trace, pose and render on it; read on the front end (halved
frames) and the trace (its quads); the detector on all of the stages.
Nothing sits above the detector.
"""
import os
import re
import sys

SRC = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), 'frappe-core', 'src')
MAY_INCLUDE = {
    'base': set(),
    'dictionary': {'base'},
    'front_end': {'base'},
    'trace': {'base'},
    'pose': {'base'},
    'render': {'base'},
    'read': {'base', 'front_end', 'trace'},
    'detector': {'base', 'dictionary', 'front_end', 'trace', 'read'},
}
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"')


def main():
    rooms = sorted(d for d in os.listdir(SRC) if os.path.isdir(os.path.join(SRC, d)))
    unknown = [r for r in rooms if r not in MAY_INCLUDE]
    if unknown:
        print(f'rooms without a place in the order: {unknown} (add them to MAY_INCLUDE)')
        return 1
    where = {f: r for r in rooms for f in os.listdir(os.path.join(SRC, r))}
    bad = []
    for room in rooms:
        for name in sorted(os.listdir(os.path.join(SRC, room))):
            with open(os.path.join(SRC, room, name), encoding='utf-8') as f:
                for n, line in enumerate(f, 1):
                    m = INCLUDE.match(line)
                    if not m or m.group(1).startswith('frappe/'):
                        continue
                    to = where.get(os.path.basename(m.group(1)))
                    if to and to != room and to not in MAY_INCLUDE[room]:
                        bad.append(f'src/{room}/{name}:{n}: includes {m.group(1)} of {to}/')
    for line in bad:
        print(line)
    if bad:
        print('\na room includes one above or beside it: move the shared part down (base/), or the '
              'caller up')
        return 1
    print('frappe-core/src: ' + ', '.join(rooms) + ': every include goes down')
    return 0


if __name__ == '__main__':
    sys.exit(main())
