#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Issue 35's peer table in one go: frappe-peers on synth/images, seq01 and
seq02 (the sequences in frame order), three invocations each, interleaved,
glibc's trimming off, then eval.py on the first invocation's detections.

    tests/bench/peer_table.py [--build build] [--out /tmp/peers] [--invocations 3]

Needs a build configured with -Daruco3_prefix (docs/speed.md). Prints, per
set and detector: sensitivity, false positives, dropouts, and the medians of
the invocations' ms (CPU time, wall) and of their peer / frappe ratios.
eval.py needs numpy: it runs under /usr/bin/python3.
"""
import argparse
import os
import re
import statistics
import subprocess

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SHARED = os.path.join(os.path.dirname(ROOT), 'shared')
TUNABLES = 'glibc.malloc.trim_threshold=268435456:glibc.malloc.mmap_threshold=33554432'
SETS = (('images', '*.png', False), ('seq01', '*.jpg', True), ('seq02', '*.jpg', True))


def parse(text):
    """{detector: {'wall': ms, 'cpu': ms}} from frappe-peers' two tables."""
    out = {}
    for head, key in (('wall clock:', 'wall'), ("this thread's CPU time:", 'cpu')):
        for line in text.split(head)[1].splitlines()[2:]:
            m = re.match(r'(\S+)\s+([\d.]+)\s+([\d.]+)', line)
            if not m:
                break
            out.setdefault(m.group(1), {})[key] = float(m.group(2))
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('--build', default=os.path.join(ROOT, 'build'))
    ap.add_argument('--out', default='/tmp/peers')
    ap.add_argument('--invocations', type=int, default=3)
    a = ap.parse_args()
    peers = os.path.join(a.build, 'tests', 'bench', 'frappe-peers')
    os.makedirs(a.out, exist_ok=True)
    env = dict(os.environ, GLIBC_TUNABLES=TUNABLES)
    lists = {}
    for name, pattern, _ in SETS:
        folder = os.path.join(SHARED, 'data', 'synth', name)
        frames = sorted(f for f in os.listdir(folder) if f.endswith(pattern[1:]))
        lists[name] = os.path.join(a.out, name + '.txt')
        with open(lists[name], 'w') as f:
            f.writelines(os.path.join(folder, x) + '\n' for x in frames)
    runs = {name: [] for name, _, _ in SETS}
    for i in range(1, a.invocations + 1):  # interleaved, so drift hits every set
        load = open('/proc/loadavg').read().split()[:3]
        print(f'invocation {i}, load {" ".join(load)}', flush=True)
        for name, _, sequence in SETS:
            cmd = [peers, '--list', lists[name], '--out', os.path.join(a.out, f'{name}-{i}')]
            cmd += ['--sequence'] if sequence else []
            text = subprocess.run(cmd, env=env, capture_output=True, text=True, check=True).stdout
            open(os.path.join(a.out, f'{name}-{i}.txt'), 'w').write(text)
            runs[name].append(parse(text))
    for name, _, _ in SETS:
        truth = os.path.join(SHARED, 'data', 'synth', name, 'truth.jsonl')
        ours = [o for o in ('normal', 'track') if o in runs[name][0]]
        print(f'== {name}: sensitivity, FP, dropouts; median CPU ms [wall]; peer / frappe (CPU)')
        for det in runs[name][0]:
            dets = os.path.join(a.out, f'{name}-1-{det}.jsonl')
            ev = subprocess.run(['/usr/bin/python3', os.path.join(SHARED, 'tools', 'eval.py'), '--truth', truth,
                                 '--dets', dets], capture_output=True, text=True, check=True).stdout
            sens = re.search(r'sensitivity ([\d.]+) \((\d+)/(\d+)\)\s+false positives (\d+)', ev)
            drop = re.search(r'dropouts[^:]*: (\d+) of', ev)
            cpu = statistics.median(r[det]['cpu'] for r in runs[name])
            wall = statistics.median(r[det]['wall'] for r in runs[name])
            ratios = '  '.join(f'/{o} {statistics.median(r[det]["cpu"] / r[o]["cpu"] for r in runs[name]):.2f}x'
                               for o in ours)
            print(f'{det:14s} {sens.group(1)} FP {sens.group(4)}' + (f' drop {drop.group(1)}' if drop else '')
                  + f'  {cpu:.3f} [{wall:.3f}]  {ratios}')


if __name__ == '__main__':
    main()
