#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Every repository path the docs, READMEs and comments name exists.

    scripts/check-paths.py          (the test repo-paths; CI runs it)

A path is a word with a slash that ends in a file name with one of the
repository's extensions (docs/arm.md, frappe/settings.h, tests/core/...):
it must exist from the root, from the naming file's folder, or under one
of the roots the code names paths from (frappe-core/include, frappe-core,
vc4/backend, vc4/toolchain, gst, tests). Paths of the build tree, of the
shared data folder (../shared) and of the system are not the repository's
and are left alone, as are names that hold a pattern (*, <, {, $).
"""
import os
import re
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
EXTENSIONS = ('md', 'cpp', 'h', 'hpp', 'c', 'py', 'sh', 'txt', 'yaml', 'yml', 'ini', 'build', 'cmake', 'in',
              'json', 'csv', 'png', 'webm', 'xml', 'toml', 'pyi')
PATH = re.compile(r'(?<![\w./$<{*-])((?:\.\./|\./)?(?:[\w.+-]+/)+[\w.+-]+\.(?:' + '|'.join(EXTENSIONS) + r'))\b')
ROOTS = ['', 'frappe-core/include', 'frappe-core', 'frappe-core/src', 'vc4/backend', 'vc4/toolchain', 'vc4',
         'gst', 'gst/meta', 'tests', 'python', 'scripts', 'backend', 'tools', 'examples']
# Not the repository's: the build tree, the shared folder, the system,
# what a program writes, another project's files.
FOREIGN = re.compile(r'^(\.\./\.\.|build[\w-]*/|/|~|usr/|lib/|LIB/|cmake/frappe/|include/uapi/|include/soc/|drivers/|hello_fft/|include/gst|gst/video/|gst/check/|gst/app/'
                     r'|gst/allocators/|opencv2/|Eigen/|hwy/|pybind11/|gtest/|gmock/|linux/|sys/|drm/|benchmark/'
                     r'|apriltag/|numpy/|share/|etc/|dev/|proc/|tmp/|runs/|out/|data/|synth/|real/)')
SOURCES = ('.cpp', '.h', '.hpp', '.c', '.py', '.sh', '.build', '.md', '.in', '.ini', '.txt', '.yml', '.yaml')


def tracked():
    out = subprocess.run(['git', '-C', ROOT, 'ls-files'], capture_output=True, text=True)
    if out.returncode != 0:
        return None
    # Not prose: the data lists name files of ../shared/data relative to it.
    return [f for f in out.stdout.splitlines() if f.endswith(SOURCES) and '/corpus/' not in f
            and f not in ('tests/cross/detections.txt', 'tests/cross/frames.txt')
            and not (f.startswith('frappe-core/dictionaries/') and f.endswith('.txt'))]


# Made by the build: named, never in the tree.
GENERATED = {'frappe/version.h'}
# Bare document names in capitals (README.md): each must be some tracked file's.
BARE = re.compile(r'(?<![\w./-])([A-Z][A-Z0-9_-]+\.md)\b')
SHARED = os.path.normpath(os.path.join(ROOT, '..', 'shared'))


def exists(path, where):
    if path in GENERATED:
        return True
    if path.startswith('../shared/'):
        # The team's folder: checked where it is, as the data tests are.
        return not os.path.isdir(SHARED) or os.path.exists(os.path.join(SHARED, path[len('../shared/'):]))
    if FOREIGN.match(path):
        return True
    for base in [where] + ROOTS:
        if os.path.exists(os.path.normpath(os.path.join(ROOT, base, path))):
            return True
    return False


def main():
    files = tracked()
    if files is None:
        print('not a git checkout')
        return 77
    missing = []
    names = {os.path.basename(f) for f in files}
    for rel in files:
        try:
            text = open(os.path.join(ROOT, rel), encoding='utf-8').read()
        except (UnicodeDecodeError, FileNotFoundError):
            continue
        where = os.path.dirname(rel)
        for n, line in enumerate(text.splitlines(), 1):
            if 'http://' in line or 'https://' in line or 'check-paths: ignore' in line:
                continue
            for m in PATH.finditer(line):
                path = m.group(1)
                if not exists(path, where):
                    missing.append(f'{rel}:{n}: {path}')
            for m in BARE.finditer(line):
                if m.group(1) not in names:
                    missing.append(f'{rel}:{n}: {m.group(1)} (no such document)')
    for line in missing:
        print(line)
    if missing:
        print(f'\n{len(missing)} paths named that are not in the repository: fix the name, or mark the line '
              '"check-paths: ignore" when it names something outside it')
        return 1
    print(f'{len(files)} files: every repository path they name exists')
    return 0


if __name__ == '__main__':
    sys.exit(main())
