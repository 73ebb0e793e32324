#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The committed files' generated blocks, from the settings table.

    scripts/generated.py BUILD/tests/docs/frappe-settings-doc --check   (the test generated-files)
    scripts/generated.py BUILD/tests/docs/frappe-settings-doc --write   (ninja -C BUILD update-generated)

Each block lies between a line holding "BEGIN generated: KIND" and one
holding "END generated"; KIND is what frappe-settings-doc prints it from.
"""
import os
import re
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FILES = ['python/frappe/__init__.pyi', 'docs/settings.md']
BLOCK = re.compile(r'(^[^\n]*BEGIN generated: (\w+)[^\n]*\n)(.*?)(^[^\n]*END generated)', re.M | re.S)


def main():
    if len(sys.argv) != 3 or sys.argv[2] not in ('--check', '--write'):
        print(__doc__, file=sys.stderr)
        return 2
    program, mode = sys.argv[1], sys.argv[2]
    made = {}
    stale = []
    for rel in FILES:
        path = os.path.join(ROOT, rel)
        with open(path, encoding='utf-8') as f:
            text = f.read()

        def fill(m):
            kind = m.group(2)
            if kind not in made:
                made[kind] = subprocess.run([program, kind], check=True, capture_output=True,
                                            text=True).stdout
            return m.group(1) + made[kind] + m.group(4)

        new, count = BLOCK.subn(fill, text)
        if count == 0:
            print(f'{rel}: no generated block', file=sys.stderr)
            return 1
        if new != text:
            stale.append(rel)
            if mode == '--write':
                with open(path, 'w', encoding='utf-8') as f:
                    f.write(new)
    if stale and mode == '--check':
        print('out of date with frappe/settings.h: ' + ', '.join(stale) +
              '\n(ninja -C BUILD update-generated rewrites them)', file=sys.stderr)
        return 1
    for rel in stale:
        print(f'rewrote {rel}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
