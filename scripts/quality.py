#!/usr/bin/python3
"""The quality harness of issue 17: how trustworthy frappe's detections are,
next to its peers, on every data set of the team's shared folder.

usage: scripts/quality.py [--build DIR] [--shared DIR] [--jobs N] [--json OUT] [--keep DIR]

Runs, all at defaults and single-threaded:
  * frappe-detect over every synthetic subset and real folder with the
    truth's dictionary;
  * OpenCV 4.6 aruco and AprilTag 3.3 (decimate 1, AprilTag families) on the
    same images through frappe-bench; on synth/images with 5 repeats, alone,
    for the speed ratio;
  * frappe-sweep over every synthetic subset: every built-in dictionary (the
    wrong-id matrix) and the subset upsampled 2x and 3x, bilinear and nearest
    (made in memory, truth corners scaled as x' = (x + 0.5) s - 0.5);
scores everything with ../shared/tools/eval.py and prints Markdown tables, then
the checks of tests/data/floors.py (measured, enforced floor, issue target).
See docs/quality.md. Needs python3-numpy (the scorer) and a build with
OpenCV (frappe-sweep, frappe-bench). About a minute on two quiet cores.
"""
import argparse
import concurrent.futures
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), '..'))
sys.path.insert(0, os.path.join(ROOT, 'tests', 'data'))
import floors  # noqa: E402
import measure  # noqa: E402
import test_data  # noqa: E402

LIGHT_BUCKETS = ['blinds', 'cast', 'lowlight', 'glare', 'overexposed']
EXPOSURES = sorted(floors.EXPOSURE_POINTS)
BLUR_BUCKETS = ['sharp (motion < 2 px, sigma < 1)', 'motion blur < 5 px', 'motion blur >= 5 px',
                'defocus sigma < 1.5', 'defocus sigma >= 1.5']
SIZE_BUCKETS = ['0-30', '30-60', '60-120', '120-9999']
PEERS = [('frappe', 'frappe'), ('opencv', 'OpenCV 4.6'), ('apriltag', 'AprilTag 3.3 d1')]


def table(head, rows):
    """A Markdown table; the first column left-aligned, the rest right."""
    rows = [[str(c) for c in r] for r in rows]
    w = [max(len(r[i]) for r in [head] + rows) for i in range(len(head))]
    line = lambda r: '| ' + ' | '.join(c.ljust(w[i]) if i == 0 else c.rjust(w[i]) for i, c in enumerate(r)) + ' |'
    out = [line(head), '|' + '|'.join(('-' * (n + 1) + ':') if i else '-' * (n + 2) for i, n in enumerate(w)) + '|']
    return '\n'.join(out + [line(r) for r in rows])


def short(name):
    return name.split('/', 1)[1]


def sens(res, bucket=None, key='sensitivity_by_blur'):
    if res is None:
        return '-'
    if bucket is None:
        return '%.3f' % res['sensitivity']
    tp, n = res[key].get(bucket, (0, 0))
    return '%.3f' % (tp / n) if n else '-'


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('--build', default=os.path.join(ROOT, 'build'))
    ap.add_argument('--shared', default=os.path.join(ROOT, '..', 'shared'))
    ap.add_argument('--jobs', type=int, default=2, help='processes at once after the speed run (default 2)')
    ap.add_argument('--json', help='write every score here')
    ap.add_argument('--keep', help='keep the detections (JSONL) in this folder')
    a = ap.parse_args()

    detect = os.path.join(a.build, 'tools', 'frappe-detect')
    sweep = os.path.join(a.build, 'tests', 'frappe-sweep')
    bench = os.path.join(a.build, 'tests', 'bench', 'frappe-bench')
    for exe in (detect, sweep, bench):
        if not os.access(exe, os.X_OK):
            sys.exit('quality.py: %s not built (a build with OpenCV and the tests)' % exe)
    if not os.path.isdir(os.path.join(a.shared, 'data')):
        sys.exit('quality.py: no shared data at %s' % a.shared)
    scorer = measure.load_scorer(a.shared)
    synth = measure.synth_subsets(a.shared)
    real = measure.real_subsets(a.shared)
    corrects = measure.built_in_dictionaries(detect)
    dictionaries = sorted(corrects)
    started = time.monotonic()

    work = a.keep or tempfile.mkdtemp(prefix='frappe-quality-')
    os.makedirs(work, exist_ok=True)
    stem = lambda sub: os.path.join(work, sub.name.replace('/', '-'))

    # The speed ratio first and alone: nothing else on the cores.
    images = next(s for s in synth if s.name == 'synth/images')

    def run_bench(sub, repeat):
        lst = measure.write_list(sub, stem(sub) + '-bench.txt')
        out = subprocess.run([bench, '--dictionary', sub.dictionary, '--list', lst, '--repeat', str(repeat),
                              '--no-extras', '--out-frappe', stem(sub) + '-bench-frappe.jsonl',
                              '--out-opencv', stem(sub) + '-opencv.jsonl',
                              '--out-apriltag', stem(sub) + '-apriltag'],
                             check=True, capture_output=True, text=True).stdout
        return out
    print('speed run (frappe-bench, synth/images, 5 repeats) ...', file=sys.stderr, flush=True)
    speed_text = run_bench(images, 5)

    # Then everything else, `jobs` processes at once, the longest first.
    tasks = []
    for sub in synth:
        tasks.append(('sweep', sub))
    for sub in synth + real:
        if sub is not images:
            tasks.append(('bench', sub))
        tasks.append(('detect', sub))
    sweep_runs = {sub.name: measure.matrix_runs(sub, dictionaries, work) + measure.resolution_runs(sub, work)
                  + measure.exposure_runs(sub, work, EXPOSURES, as_read=False)
                  for sub in synth}

    def do(task):
        kind, sub = task
        if kind == 'sweep':
            measure.run_sweep(sweep, sub, sweep_runs[sub.name], work)
        elif kind == 'bench':
            run_bench(sub, 1)
        else:
            measure.run_detect(detect, sub, sub.dictionary, stem(sub) + '-frappe.jsonl', work)
    print('%d runs on %d processes ...' % (len(tasks), a.jobs), file=sys.stderr, flush=True)
    with concurrent.futures.ThreadPoolExecutor(a.jobs) as pool:
        for f in [pool.submit(do, t) for t in tasks]:
            f.result()
    run_s = time.monotonic() - started

    # Scores.
    scores = {}
    for sub in synth + real:
        scores[sub.name] = {}
        for key, path in (('frappe', '-frappe.jsonl'), ('opencv', '-opencv.jsonl'), ('apriltag', '-apriltag-d1.jsonl')):
            if os.path.exists(stem(sub) + path):
                scores[sub.name][key] = measure.score(scorer, sub.truth, stem(sub) + path)
    resolution, exposure, cells, mismatched = {}, {}, {}, []
    codebook = measure.CodeBook(corrects)
    for sub in synth:
        runs = sweep_runs[sub.name]
        res_runs = [r for r in runs if r[0] == sub.dictionary and not r[2].startswith('light')]
        resolution[sub.name] = measure.score_resolution(scorer, sub, res_runs, work)
        exposure[sub.name] = {float(r[2][5:]): measure.score(scorer, sub.truth, r[3])
                              for r in runs if r[2].startswith('light')}
        for d, _, _, dets in runs:
            if d != sub.dictionary:
                cells[(d, sub.name)] = measure.wrong_ids(scorer, codebook, sub, d, dets)
        # frappe-sweep must detect what frappe-detect does.
        a1 = [json.dumps(r['markers']) for r in measure.load_jsonl(stem(sub) + '-frappe.jsonl')]
        b1 = [json.dumps(r['markers']) for r in measure.load_jsonl(res_runs[0][3])]
        if a1 != b1:
            mismatched.append(sub.name)

    # Tables.
    out = []
    p = out.append
    p('# Frappe quality, %s' % time.strftime('%Y-%m-%d %H:%M'))
    git = subprocess.run(['git', '-C', ROOT, 'describe', '--always', '--dirty'], capture_output=True, text=True)
    p('commit %s, build %s, shared %s; %.0f s of runs' % (git.stdout.strip() or '?', a.build, a.shared, run_s))
    if mismatched:
        p('\nWARNING: frappe-sweep and frappe-detect disagree on %s' % ', '.join(mismatched))

    p('\n## Detection at defaults, single thread, the truth\'s dictionary\n')
    p('sens = sensitivity, FP = false positives (for `-detector-labelled` folders, unlabelled markers count), '
      'MAE = corner mean error of matched markers, px; AprilTag at decimate 1, its families only.\n')
    rows = []
    for sub in synth + real:
        s = scores[sub.name]
        row = [short(sub.name) if sub.name.startswith('synth/') else sub.name, s['frappe']['truth_markers']]
        for key, _ in PEERS:
            r = s.get(key)
            row += ['%.3f' % r['sensitivity'], r['fp'], '%.3f' % r['corner_mae_px']] if r else ['-', '-', '-']
        row.append(', '.join('%s %d' % kv for kv in sorted(s['frappe']['fp_kinds'].items())) or '-')
        rows.append(row)
    head = ['set', 'markers']
    for _, title in PEERS:
        head += [title + ' sens', 'FP', 'MAE']
    p(table(head + ['frappe FP kinds'], rows))

    p('\n## Sensitivity by blur (the scorer\'s buckets, from each image\'s params)\n')
    rows = []
    for sub in synth:
        s = scores[sub.name]
        n = s['frappe']['sensitivity_by_blur']
        rows.append([short(sub.name) + ' (markers)'] + [n.get(b, (0, 0))[1] or '-' for b in BLUR_BUCKETS])
        for key, title in PEERS:
            if key in s:
                rows.append(['  ' + title] + [sens(s[key], b) for b in BLUR_BUCKETS])
    p(table(['set / detector'] + BLUR_BUCKETS, rows))

    p('\n## Sensitivity by lighting (the scorer\'s buckets, from each image\'s params.light)\n')
    rows = []
    for sub in synth:
        s = scores[sub.name]
        n = s['frappe'].get('sensitivity_by_light', {})
        if not n:
            continue
        rows.append([short(sub.name) + ' (markers)'] + [n.get(b, (0, 0))[1] or '-' for b in LIGHT_BUCKETS])
        for key, title in PEERS:
            if key in s:
                rows.append(['  ' + title] + [sens(s[key], b, 'sensitivity_by_light') for b in LIGHT_BUCKETS])
    p(table(['set / detector'] + LIGHT_BUCKETS, rows))

    p('\n## Any exposure: frappe\'s sensitivity (false positives) with the light scaled\n')
    p('Each subset exposed G times as long in memory (frappe-sweep\'s lightG: v G plus sensor noise of 1.5 '
      'grey levels, seeded, clipped); the issue holds 30%% within 3 points, 15%% within 10, 200%% within 3.\n')
    rows = []
    for sub in synth:
        base = scores[sub.name]['frappe']
        r = exposure[sub.name]
        rows.append([short(sub.name), '%.3f (%d)' % (base['sensitivity'], base['fp'])]
                    + ['%.3f (%d)' % (r[g]['sensitivity'], r[g]['fp']) for g in EXPOSURES]
                    + ['%+.1f' % (100 * (r[g]['sensitivity'] - base['sensitivity'])) for g in EXPOSURES])
    p(table(['set', '100%'] + ['%d%%' % round(100 * g) for g in EXPOSURES]
            + ['points at %d%%' % round(100 * g) for g in EXPOSURES], rows))

    p('\n## Sensitivity by marker side, px (the truth\'s side_px)\n')
    rows = []
    for sub in synth:
        s = scores[sub.name]
        n = s['frappe']['sensitivity_by_side_px']
        big = measure.large_sensitivity(s['frappe'])[2]
        rows.append([short(sub.name) + ' (markers)'] + [n[b][1] or '-' for b in SIZE_BUCKETS] + [big])
        for key, title in PEERS:
            if key in s:
                large = measure.large_sensitivity(s[key])[0]
                rows.append(['  ' + title] + [sens(s[key], b, 'sensitivity_by_side_px') for b in SIZE_BUCKETS]
                            + ['%.3f' % large if large is not None else '-'])
    p(table(['set / detector', '< 30', '30-60', '60-120', '>= 120', '>= 60'], rows))

    p('\n## Any resolution: frappe\'s sensitivity (false positives) upsampled\n')
    p('Each subset upsampled in memory with OpenCV\'s resize; the truth scaled to match.\n')
    rows = []
    for sub in synth:
        r = resolution[sub.name]
        rows.append([short(sub.name)] + ['%.3f (%d)' % (r[v]['sensitivity'], r[v]['fp'])
                                         for v in [(1, 'linear')] + measure.VARIANTS]
                    + ['%.1f' % (100 * (r[(1, 'linear')]['sensitivity']
                                        - min(r[v]['sensitivity'] for v in measure.VARIANTS)))])
    p(table(['set', '1x', '2x linear', '2x nearest', '3x linear', '3x nearest', 'worst points lost'], rows))
    rows = []
    for sub in synth:
        r = resolution[sub.name]
        rows.append([short(sub.name)] + ['%.3f' % r[v]['corner_mae_px'] if r[v]['tp'] else '-'
                                         for v in [(1, 'linear')] + measure.VARIANTS])
    p('\nCorner MAE, px of the upsampled image:\n')
    p(table(['set', '1x', '2x linear', '2x nearest', '3x linear', '3x nearest'], rows))

    p('\n## Wrong ids: every dictionary over the other families\' subsets\n')
    p('Detections of each dictionary on each synthetic subset at 1x. Another family: every detection '
      'counts; `+N` are detections of a printed marker whose code is also a code of the asked '
      'dictionary within what it corrects (right by that dictionary, not counted). Same family, '
      'another size (`*`): the scorer\'s false positives. `.` = the subset\'s own dictionary. '
      '`at limit`: the other-family wrong ids decoded with every bit the dictionary corrects.\n')
    rates = test_data.wrong_id_rates(cells, synth)
    rows = []
    col_total = {s.name: 0 for s in synth}
    for d in dictionaries:
        row = [d]
        for sub in synth:
            c = cells.get((d, sub.name))
            if c is None:
                row.append('.')
                continue
            col_total[sub.name] += c.count
            row.append('%d%s%s' % (c.count, '*' if c.same_family else '', ' +%d' % c.shared if c.shared else ''))
        wrong, shared, frames = rates[d]
        at_limit = sum(c.at_limit for (cd, _), c in cells.items() if cd == d)
        row += [wrong, at_limit, shared, frames, '%.2f' % (300.0 * wrong / frames)]
        rows.append(row)
    rows.append(['total'] + [col_total[s.name] for s in synth]
                + [sum(r[0] for r in rates.values()), sum(c.at_limit for c in cells.values()),
                   sum(r[1] for r in rates.values()), '', ''])
    rows.append(['frames'] + [s.frames for s in synth] + ['', '', '', '', ''])
    p(table(['dictionary'] + [short(s.name) for s in synth] + ['wrong', 'at limit', 'shared', 'frames', 'per 300'],
            rows))
    kinds = {}
    for c in cells.values():
        if not c.same_family:
            for k, v in c.kinds.items():
                kinds[k] = kinds.get(k, 0) + v
    p('\nOther-family wrong ids by place: ' + ', '.join('%s %d' % kv for kv in sorted(kinds.items())))

    p('\n## Speed: synth/images, single thread, same run (frappe-bench, 5 repeats, medians)\n')
    speed = {}
    for label, key in (('frappe', 'frappe'), ('opencv aruco', 'opencv')):
        m = re.search(r'^%s\s+([\d.]+)\s+([\d.]+)' % re.escape(label), speed_text, re.M)
        speed[key] = (float(m.group(1)), float(m.group(2))) if m else (float('nan'),) * 2
    p(table(['detector', 'median ms', 'p90 ms'], [['frappe', '%.3f' % speed['frappe'][0], '%.3f' % speed['frappe'][1]],
                                                   ['OpenCV 4.6 aruco', '%.3f' % speed['opencv'][0],
                                                    '%.3f' % speed['opencv'][1]]]))
    p('\nspeed ratio, OpenCV / frappe medians: %.2fx' % (speed['opencv'][0] / speed['frappe'][0]))

    p('\n## The checks of tests/data/floors.py\n')
    report = test_data.Report(echo=False)
    for sub in synth:
        test_data.check_set(report, sub.name, scores[sub.name]['frappe'])
    for sub in real:
        test_data.check_real(report, sub.name, scores[sub.name]['frappe'])
    test_data.check_wrong_ids(report, cells, synth)
    for sub in synth:
        test_data.check_resolution(report, sub.name, resolution[sub.name])
    p('```')
    out.extend(report.lines)
    p('```')
    met = sum(1 for line in report.lines if line.endswith('target met'))
    p('%d checks: %d failed, %d at target, %d held at a floor below it'
      % (len(report.lines), report.failures, met, len(report.lines) - met - report.failures))
    print('\n'.join(out))

    if a.json:
        with open(a.json, 'w') as f:
            json.dump({'scores': scores,
                       'resolution': {k: {'%dx-%s' % v: r for v, r in rs.items()} for k, rs in resolution.items()},
                       'wrong_ids': {'%s on %s' % k: vars(c) for k, c in cells.items()},
                       'speed_ms': speed, 'checks': report.lines}, f, indent=1)
    if not a.keep:
        shutil.rmtree(work)
    return 0


if __name__ == '__main__':
    sys.exit(main())
