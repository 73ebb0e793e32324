#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The C++ lines a change touches, in the house style (.clang-format).

    scripts/check-format.py [BASE]         (the test clang-format; CI runs it)
    scripts/check-format.py --fix [BASE]   (formats those lines in place)

Only the lines changed since BASE are checked (clang-format --lines, moved
files followed): the tree is not reformatted wholesale, and every change
leaves what it touched in style. BASE defaults to $FRAPPE_FORMAT_BASE, else the merge base with
origin/main, else with main. Exit 77 (skipped) without git, a checkout or
clang-format. `git clang-format --style=file BASE` applies the fixes.
"""
import os
import re
import shutil
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SKIP = 77


def git(*args):
    return subprocess.run(['git', '-C', ROOT] + list(args), capture_output=True, text=True)


def main():
    if not shutil.which('git') or not shutil.which('clang-format'):
        print('git or clang-format not found')
        return SKIP
    if git('rev-parse', '--git-dir').returncode != 0:
        print('not a git checkout')
        return SKIP
    args = sys.argv[1:]
    fix = '--fix' in args
    args = [a for a in args if a != '--fix']
    base = args[0] if args else os.environ.get('FRAPPE_FORMAT_BASE', '')
    if not base:
        for ref in ('origin/main', 'main'):
            r = git('merge-base', 'HEAD', ref)
            if r.returncode == 0:
                base = r.stdout.strip()
                break
    if not base:
        print('no base to compare with (origin/main, main)')
        return SKIP
    # The lines changed, renames followed (a moved file is not a changed
    # one; git clang-format would take it as new).
    r = git('diff', '-M', '-U0', '--no-color', '--diff-filter=AMR', base, '--', '*.cpp', '*.h', '*.hpp', '*.c')
    if r.returncode != 0:
        print(r.stderr)
        return 1
    lines = {}
    path = None
    for line in r.stdout.splitlines():
        if line.startswith('+++ '):
            path = line[6:] if line.startswith('+++ b/') else None
        elif line.startswith('@@') and path:
            m = re.match(r'@@ -\S+ \+(\d+)(?:,(\d+))? @@', line)
            start, count = int(m.group(1)), int(m.group(2) or 1)
            if count:
                lines.setdefault(path, []).append(f'--lines={start}:{start + count - 1}')
    bad = []
    for path, ranges in sorted(lines.items()):
        check = ['-i'] if fix else ['--dry-run', '--Werror']
        p = subprocess.run(['clang-format', '--style=file'] + check + ranges + [path],
                           cwd=ROOT, capture_output=True, text=True)
        if p.returncode != 0:
            bad.append(path)
            print(p.stderr.strip())
    if not bad:
        print(f'the lines changed since {base[:12]} are in style ({len(lines)} files)')
        return 0
    print(f'\nlines changed since {base[:12]} are not in the house style (.clang-format) in: ' + ', '.join(bad) +
          f'\n(scripts/check-format.py --fix {base[:12]} formats them)')
    return 1


if __name__ == '__main__':
    sys.exit(main())
