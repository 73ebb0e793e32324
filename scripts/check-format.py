#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The C++ lines a change touches, in the house style (.clang-format).

    scripts/check-format.py [BASE]      (the test clang-format; CI runs it)

Only the lines changed since BASE are checked (git clang-format): the tree
is not reformatted wholesale, and every change leaves what it touched in
style. BASE defaults to $FRAPPE_FORMAT_BASE, else the merge base with
origin/main, else with main. Exit 77 (skipped) without git, a checkout or
clang-format. `git clang-format --style=file BASE` applies the fixes.
"""
import os
import shutil
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SKIP = 77


def git(*args):
    return subprocess.run(['git', '-C', ROOT] + list(args), capture_output=True, text=True)


def main():
    if not shutil.which('git') or not shutil.which('git-clang-format') or not shutil.which('clang-format'):
        print('git, git-clang-format or clang-format not found')
        return SKIP
    if git('rev-parse', '--git-dir').returncode != 0:
        print('not a git checkout')
        return SKIP
    base = sys.argv[1] if len(sys.argv) > 1 else os.environ.get('FRAPPE_FORMAT_BASE', '')
    if not base:
        for ref in ('origin/main', 'main'):
            r = git('merge-base', 'HEAD', ref)
            if r.returncode == 0:
                base = r.stdout.strip()
                break
    if not base:
        print('no base to compare with (origin/main, main)')
        return SKIP
    r = git('clang-format', '--diff', '--style=file', base, '--', '*.cpp', '*.h', '*.hpp', '*.c')
    out = r.stdout.strip()
    if r.returncode not in (0, 1) or out.startswith('error'):
        print(r.stdout + r.stderr)
        return 1
    if not out or out.startswith('no modified files') or 'did not modify any files' in out:
        print(f'the lines changed since {base[:12]} are in style')
        return 0
    print(out)
    print(f'\nlines changed since {base[:12]} are not in the house style (.clang-format); '
          f'git clang-format --style=file {base[:12]} fixes them')
    return 1


if __name__ == '__main__':
    sys.exit(main())
