#!/usr/bin/env python3
"""Runs frappe-detect over a shared data set and holds it to the floors.

usage: test_data.py FRAPPE_DETECT SHARED_DIR SET

SET is synth/images, synth/apriltag36h11, synth/seq01, synth/seq02 or real.
Exits 77 (skipped) when the shared folder is absent. Scoring follows
shared/design/DETECTOR-CONTRACT.md: a detection matches a truth marker of the
same id when the mean corner distance is below max(3 px, 10% of the side).
"""
import json
import math
import os
import subprocess
import sys
import tempfile

# set -> (min sensitivity, max false positives, max corner mean error px)
FLOORS = {
    'synth/images': (0.90, 1, 0.25),
    'synth/apriltag36h11': (0.93, 0, 0.20),
    'synth/seq01': (0.97, 2, None),
    'synth/seq02': (0.97, 2, None),
}
DICTIONARY_ALIASES = {'opencv_6x6_250': '6x6_250', 'opencv_5x5_1000': '5x5_1000'}


def load(path):
    with open(path) as f:
        return [json.loads(line) for line in f if line.strip()]


def side(corners):
    return sum(math.dist(corners[i], corners[(i + 1) % 4]) for i in range(4)) / 4


def mean_dist(a, b):
    return sum(math.dist(p, q) for p, q in zip(a, b)) / 4


def score(truth_records, root, dets):
    """Returns (matched, truth, false positives, corner errors)."""
    by_image = {os.path.realpath(d['image']): d for d in dets}
    matched = total = fps = 0
    errors = []
    for rec in truth_records:
        det = by_image.get(os.path.realpath(os.path.join(root, rec['image'])), {'markers': []})
        assert 'error' not in det, det
        truth = rec.get('markers', [])
        ignore = rec.get('ignore', [])
        found = det['markers']
        total += len(truth)
        pairs = []
        for i, t in enumerate(truth):
            thr = max(3.0, 0.1 * side(t['corners']))
            for j, d in enumerate(found):
                if d['id'] == t['id']:
                    md = mean_dist(d['corners'], t['corners'])
                    if md < thr:
                        pairs.append((md, i, j))
        pairs.sort()
        ti, dj = set(), set()
        for md, i, j in pairs:
            if i in ti or j in dj:
                continue
            ti.add(i)
            dj.add(j)
            errors.extend(math.dist(p, q) for p, q in zip(found[j]['corners'], truth[i]['corners']))
        matched += len(ti)
        for j, d in enumerate(found):
            if j in dj:
                continue
            if any(d['id'] == g['id'] and
                   min(mean_dist(d['corners'], g['corners'][k:] + g['corners'][:k]) for k in range(4))
                   < max(10.0, 0.5 * side(g['corners'])) for g in ignore):
                continue
            fps += 1
    return matched, total, fps, errors


def run(detect, truth_path, family, workdir):
    root = os.path.dirname(truth_path)
    records = load(truth_path)
    lst = os.path.join(workdir, 'list.txt')
    out = os.path.join(workdir, 'dets.jsonl')
    with open(lst, 'w') as f:
        for r in records:
            f.write(os.path.join(root, r['image']) + '\n')
    family = DICTIONARY_ALIASES.get(family, family)
    subprocess.run([detect, '--dictionary', family, '--list', lst, '--out', out, '--threads', '1'],
                   check=True)
    dets = load(out)
    assert len(dets) == len(records), 'one output line per listed image'
    return records, root, dets


def main():
    detect, shared, name = sys.argv[1], sys.argv[2], sys.argv[3]
    data = os.path.join(shared, 'data')
    if not os.path.isdir(data):
        print('shared data not found at %s: skipping' % data)
        return 77
    failures = []
    with tempfile.TemporaryDirectory() as tmp:
        if name == 'real':
            for folder in sorted(os.listdir(os.path.join(data, 'real'))):
                truth = os.path.join(data, 'real', folder, 'truth.jsonl')
                family = load(truth)[0]['family']
                records, root, dets = run(detect, truth, family, tmp)
                matched, total, fps, errors = score(records, root, dets)
                print('%-50s %3d/%3d found, %d unmatched detections' % (folder, matched, total, fps))
                # Labels from another detector are incomplete: sensitivity only.
                # Every marker of the folders with source ground truth must be found.
                if not folder.endswith('-detector-labelled') and matched < total:
                    failures.append('%s: %d of %d markers found' % (folder, matched, total))
        else:
            truth = os.path.join(data, name, 'truth.jsonl')
            records, root, dets = run(detect, truth, load(truth)[0]['family'], tmp)
            matched, total, fps, errors = score(records, root, dets)
            sens = matched / total
            mae = sum(errors) / len(errors) if errors else 0.0
            print('%s: sensitivity %.4f (%d/%d), false positives %d, corner mean error %.3f px'
                  % (name, sens, matched, total, fps, mae))
            min_sens, max_fp, max_err = FLOORS[name]
            if sens < min_sens:
                failures.append('sensitivity %.4f below %.2f' % (sens, min_sens))
            if fps > max_fp:
                failures.append('%d false positives, at most %d allowed' % (fps, max_fp))
            if max_err is not None and mae > max_err:
                failures.append('corner error %.3f px above %.2f' % (mae, max_err))
    for f in failures:
        print('FAIL: ' + f)
    return 1 if failures else 0


if __name__ == '__main__':
    sys.exit(main())
