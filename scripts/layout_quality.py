#!/usr/bin/env python3
"""Issue 32's measure of the AprilTag 3 layout families: scenes rendered by
`frappe-render --scene` (corner truth from the renderer), read by frappe and
by AprilTag 3.3 (`apriltag-peer`, decimate 1) and scored by
../shared/tools/eval.py, the hard scenes also by the found square's side;
then every layout family's detector over the other families' scenes and
../shared's synth subsets, where any marker is a wrong id.

usage: scripts/layout_quality.py BUILD_DIR OUT_DIR [--images 60] [--synth]
    [--families a,b] [--hard-only] [--no-cross]
(the synth subsets: also tests/data's data-wrong-ids; --families, --hard-only
and --no-cross narrow a run while iterating: scenes of the other families
are still rendered for the wrong-id table)
"""
import json
import math
import os
import subprocess
import sys

FAMILIES = ['apriltag_standard41h12', 'apriltag_standard52h13', 'apriltag_circle21h7',
            'apriltag_circle49h12', 'apriltag_custom48h12']
HERE = os.path.dirname(os.path.abspath(__file__))
SHARED = os.path.join(HERE, '..', '..', 'shared')
EVAL = os.path.join(SHARED, 'tools', 'eval.py')


def run(cmd):
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)


def scenes(build, out, family, images, hard=False):
    folder = os.path.join(out, family + ('-hard' if hard else ''))
    os.makedirs(folder, exist_ok=True)
    truth = []
    for k in range(images):
        png = os.path.join(folder, f'{k:05d}.png')
        if not os.path.exists(png):
            run([os.path.join(build, 'tools', 'frappe-render'), '--scene', '--dictionary', family,
                 '--seed', str(3200 + k), '--count', '6', png] + (['--hard'] if hard else []))
        with open(png[:-4] + '.json') as f:
            truth.append(f.read().strip())
    with open(os.path.join(folder, 'truth.jsonl'), 'w') as f:
        f.write('\n'.join(truth) + '\n')
    with open(os.path.join(folder, 'list.txt'), 'w') as f:
        f.write('\n'.join(os.path.join(folder, f'{k:05d}.png') for k in range(images)) + '\n')
    return folder


def score(folder, dets):
    res = subprocess.run(['/usr/bin/python3', EVAL, '--truth', os.path.join(folder, 'truth.jsonl'),
                          '--dets', dets, '--json', dets + '.score.json'],
                         check=True, capture_output=True, text=True)
    with open(dets + '.score.json') as f:
        return json.load(f)


def count_markers(dets):
    n = 0
    with open(dets) as f:
        for line in f:
            n += len(json.loads(line).get('markers', []))
    return n


# The found square's side in pixels: small markers are where the layout
# families are lost (docs/quality.md).
SIDE_BINS = [(0, 12), (12, 15), (15, 20), (20, 30), (30, 1e9)]


def side_of(c):
    return sum(math.dist(c[i], c[(i + 1) % 4]) for i in range(4)) / 4


def by_side(folder, dets):
    """'found/markers' per SIDE_BINS: a marker is found by a detection of
    its id whose corners lie within eval.py's distance of its own."""
    found = {}
    with open(dets) as f:
        for line in f:
            r = json.loads(line)
            found[os.path.basename(r['image'])] = r.get('markers', [])
    counts = [[0, 0] for _ in SIDE_BINS]
    with open(os.path.join(folder, 'truth.jsonl')) as f:
        for line in f:
            t = json.loads(line)
            for m in t['markers']:
                side = side_of(m['corners'])
                b = next(i for i, (lo, hi) in enumerate(SIDE_BINS) if lo <= side < hi)
                counts[b][1] += 1
                counts[b][0] += any(
                    d['id'] == m['id'] and sum(math.dist(p, q) for p, q in zip(d['corners'], m['corners'])) / 4 <
                    max(3.0, 0.1 * side) for d in found.get(os.path.basename(t['image']), []))
    return [f'{a}/{n}' for a, n in counts]


def main():
    build, out = sys.argv[1], sys.argv[2]
    images = int(sys.argv[sys.argv.index('--images') + 1]) if '--images' in sys.argv else 60
    detect = os.path.join(build, 'tools', 'frappe-detect')
    peer = os.path.join(build, 'tests', 'bench', 'apriltag-peer')
    chosen = sys.argv[sys.argv.index('--families') + 1].split(',') if '--families' in sys.argv else FAMILIES
    folders = {f: scenes(build, out, f, images) for f in FAMILIES}
    hard = {f: scenes(build, out, f, images, True) for f in chosen}
    sets = [] if '--hard-only' in sys.argv else [(f, folders[f]) for f in chosen]
    sets += [(f + ' hard', hard[f]) for f in chosen]
    print('| family | markers | frappe sensitivity | FP | corner mean / median px | ms median '
          '| AprilTag 3.3 d1 sensitivity | FP | corner mean / median px | ms median |')
    print('|---|---|---|---|---|---|---|---|---|---|')
    sizes = []
    for f, folder in sets:
        f = f.split()[0]
        dets = os.path.join(folder, 'frappe.jsonl')
        run([detect, '--dictionary', f, '--list', os.path.join(folder, 'list.txt'), '--out', dets,
             '--repeat', '1', '--threads', '1'])
        a = score(folder, dets)
        row = [os.path.basename(folder), a['truth_markers']]

        def cells(s):
            return [f"{s['sensitivity']:.3f}", s['fp'],
                    f"{s['corner_mae_px']:.3f} / {s['corner_median_px']:.3f}", f"{s['time_ms_median']:.2f}"]
        row += cells(a)
        hard_set = folder == hard.get(f)
        if hard_set:
            sizes.append([f, 'frappe'] + by_side(folder, dets))
        if os.path.exists(peer):
            pd = os.path.join(folder, 'apriltag-d1.jsonl')
            # the peer's reads do not change between runs
            # libapriltag's decode table for the largest families at 2 bits
            # needs gigabytes: 1 bit there, as AprilTag's docs advise.
            bits = '1' if f in ('apriltag_standard52h13', 'apriltag_circle49h12', 'apriltag_custom48h12') else '2'
            if not os.path.exists(pd):
                run([peer, '--dictionary', f, '--list', os.path.join(folder, 'list.txt'), '--out', pd,
                     '--decimate', '1', '--hamming', bits])
            row += cells(score(folder, pd))
            if hard_set:
                sizes.append([f, 'AprilTag 3.3 d1'] + by_side(folder, pd))
        print('| ' + ' | '.join(str(x) for x in row) + ' |')
    print()
    print('| hard scenes | detector | ' + ' | '.join(f'side {lo:g}-{hi:g} px' if hi < 1e9 else f'side {lo:g}+ px'
                                                   for lo, hi in SIDE_BINS) + ' |')
    print('|---|---|' + '---|' * len(SIDE_BINS))
    for row in sizes:
        print('| ' + ' | '.join(row) + ' |')
    if '--no-cross' in sys.argv:
        return
    # Wrong ids: each family over the others' scenes and the shared subsets.
    others = {f'{g} (rendered)': os.path.join(folders[g], 'list.txt') for g in FAMILIES}
    others.update({f'{g} hard (rendered)': os.path.join(scenes(build, out, g, images, True), 'list.txt')
                   for g in FAMILIES})
    synth = os.path.join(SHARED, 'data', 'synth')
    if os.path.isdir(synth) and '--synth' in sys.argv:
        for sub in sorted(os.listdir(synth)):
            t = os.path.join(synth, sub, 'truth.jsonl')
            if not os.path.exists(t):
                continue
            lst = os.path.join(out, f'synth-{sub}.txt')
            with open(t) as fin, open(lst, 'w') as fout:
                for line in fin:
                    fout.write(os.path.join(synth, sub, json.loads(line)['image']) + '\n')
            others[f'synth/{sub}'] = lst
    print()
    print('| detector | ' + ' | '.join(others) + ' |')
    print('|---|' + '---|' * len(others))
    for f in FAMILIES:
        row = [f]
        for name, lst in others.items():
            if name.startswith(f + ' '):
                row.append('-')
                continue
            dets = os.path.join(out, f'cross-{f}-{name.replace("/", "_").replace(" ", "")}.jsonl')
            run([detect, '--dictionary', f, '--list', lst, '--out', dets, '--repeat', '1', '--threads', '1'])
            row.append(count_markers(dets))
        print('| ' + ' | '.join(str(x) for x in row) + ' |', flush=True)


if __name__ == '__main__':
    main()
