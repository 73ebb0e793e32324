#!/usr/bin/env python3
"""Holds frappe to the floors of tests/data/floors.py on the team's data sets.

usage: test_data.py FRAPPE_DETECT FRAPPE_SWEEP SHARED_DIR CHECK

CHECK is a synthetic subset (synth/images, synth/blur, ...: frappe-detect with
the subset's dictionary), real (the photographs), wrong-ids (every built-in
dictionary over the other families' subsets), track (Mode::Track against
Mode::Normal on the sequences), resolution (every subset
upsampled 2x and 3x) or exposure (every subset darkened and brightened). Each check prints its measurement, the enforced floor
and the issue's target. Exits 77 (skipped) when the shared folder is absent,
as on a user's machine. Scoring is ../shared/tools/eval.py's (needs numpy).
"""
import math
import os
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import floors  # noqa: E402
import measure  # noqa: E402


class Report:
    """Check lines: what was measured, the floor it failed on, the target."""

    def __init__(self, echo=True):
        self.failures = 0
        self.lines = []
        self.echo = echo

    def _add(self, what, shown, ok, floor, target, met):
        if not ok:
            self.failures += 1
        status = 'ok' if ok else 'FAIL'
        if ok:
            status += ', target met' if met else ', target not met yet'
        self.lines.append('%-58s %-30s floor %-9s target %-9s %s' % (what, shown, floor, target, status))
        if self.echo:
            print(self.lines[-1], flush=True)

    def at_least(self, what, value, limit, shown=None, fmt='%.4g'):
        need = floors.enforced(limit)
        self._add(what, shown or fmt % value, value >= need, '>= ' + fmt % need, '>= ' + fmt % limit[1],
                  value >= limit[1])

    def at_most(self, what, value, limit, shown=None, fmt='%.4g'):
        need = floors.enforced(limit)
        self._add(what, shown or fmt % value, value <= need, '<= ' + fmt % need, '<= ' + fmt % limit[1],
                  value <= limit[1])


def check_set(report, name, res):
    f = floors.SETS[name]
    if f.sens:
        report.at_least(name + ' sensitivity', res['sensitivity'], f.sens,
                        '%.4f (%d/%d)' % (res['sensitivity'], res['tp'], res['truth_markers']))
    if f.fp:
        report.at_most(name + ' false positives', res['fp'], f.fp, fmt='%d')
    if f.mae:
        report.at_most(name + ' corner MAE px', res['corner_mae_px'], f.mae, '%.3f' % res['corner_mae_px'])
    if f.large:
        sens, tp, n = measure.large_sensitivity(res)
        assert n, '%s has no markers of 60 px or more' % name
        report.at_least(name + ' sensitivity, markers >= 60 px', sens, f.large, '%.4f (%d/%d)' % (sens, tp, n))
    for effect, limit in sorted((f.light or {}).items()):
        sens, tp, n = measure.light_sensitivity(res, effect)
        assert n, '%s has no images lit with %s' % (name, effect)
        report.at_least('%s sensitivity, %s' % (name, effect), sens, limit, '%.4f (%d/%d)' % (sens, tp, n))


def check_real(report, name, res):
    # Labels from another detector are incomplete: sensitivity is not held.
    if not name.endswith('-detector-labelled'):
        missed = res['truth_markers'] - res['tp']
        report.at_most(name + ' markers missed', missed, floors.REAL_MISSED,
                       '%d (%d/%d found)' % (missed, res['tp'], res['truth_markers']), fmt='%d')
    report.at_most(name + ' detections misplaced', measure.misplaced(res), floors.REAL_MISPLACED, fmt='%d')


def wrong_id_rates(cells, subsets):
    """{dictionary: (wrong ids, shared codes, frames)} over the subsets of
    the other families and the same family's other sizes."""
    frames = {s.name: s.frames for s in subsets}
    out = {}
    for (d, s), cell in cells.items():
        w, sh, n = out.get(d, (0, 0, 0))
        out[d] = (w + cell.count, sh + cell.shared, n + frames[s])
    return out


def check_wrong_ids(report, cells, subsets):
    for d, (wrong, shared, frames) in sorted(wrong_id_rates(cells, subsets).items()):
        limit = floors.WRONG_IDS_PER_300[d]
        rate = 300.0 * wrong / frames
        report.at_most('%s wrong ids per 300 frames' % d, rate, limit,
                       '%.2f (%d in %d, +%d shared)' % (rate, wrong, frames, shared), fmt='%.2f')


def check_resolution(report, name, results):
    """Upsampled sensitivity against its floor; the target is the subset's
    own sensitivity as read, less RESOLUTION_POINTS."""
    base = results[(1, 'linear')]['sensitivity']
    target = base - floors.RESOLUTION_POINTS / 100.0
    for k, (s, i) in enumerate(measure.VARIANTS):
        res = results[(s, i)]
        floor = floors.RESOLUTION[name][k]
        report.at_least('%s %dx %s sensitivity' % (name, s, i), res['sensitivity'],
                        (target if floor is None else floor, target),
                        '%.4f (1x %.4f)' % (res['sensitivity'], base), fmt='%.4g')


def check_exposure(report, name, results):
    """Each exposure's sensitivity within its points of the subset as read,
    and no false positive."""
    base = results[1.0]['sensitivity']
    for g, points in sorted(floors.EXPOSURE_POINTS.items()):
        res = results[g]
        enforced = floors.EXPOSURE_ENFORCED.get((name, g), points)
        report.at_least('%s at %d%% light, sensitivity' % (name, round(100 * g)), res['sensitivity'],
                        (base - enforced / 100.0, base - points / 100.0),
                        '%.4f (1x %.4f)' % (res['sensitivity'], base), fmt='%.4g')
        report.at_most('%s at %d%% light, false positives' % (name, round(100 * g)), res['fp'],
                       (floors.EXPOSURE_FP_ENFORCED.get((name, g), 0), 0), fmt='%d')


def first_found(sub, dets):
    """Per truth marker id, per episode of frames it is visible in a row
    (frame order = the truth's), the first frame a detection matches it
    (the scorer's rule: same id, mean corner distance under max(3 px, 10%
    of its side)), or None."""
    by_image = {os.path.basename(d['image']): d['markers'] for d in measure.load_jsonl(dets)}
    episodes = {}  # (id, first visible frame) -> first found frame
    visible = {}   # id -> first frame of its current episode
    for f, rec in enumerate(sub.records):
        found = by_image.get(os.path.basename(rec['image']), [])
        now = {}
        for t in rec['markers']:
            start = visible.get(t['id'], f)
            now[t['id']] = start
            hit = any(m['id'] == t['id'] and sum(math.dist(a, b) for a, b in zip(m['corners'], t['corners'])) / 4
                      < max(3.0, 0.1 * t['side_px']) for m in found)
            key = (t['id'], start)
            if key not in episodes:
                episodes[key] = None
            if hit and episodes[key] is None:
                episodes[key] = f
        visible = now
    return episodes


def check_track(report, name, sub, normal_res, track_res, normal_dets, track_dets):
    t = floors.TRACK
    report.at_least(name + ' track sensitivity', track_res['sensitivity'],
                    (normal_res['sensitivity'] - floors.enforced(t['sens_below_normal']),
                     normal_res['sensitivity'] - t['sens_below_normal'][1]),
                    '%.4f (normal %.4f)' % (track_res['sensitivity'], normal_res['sensitivity']))
    report.at_most(name + ' track false positives beyond normal', track_res['fp'] - normal_res['fp'],
                   t['fp_above_normal'], '%+d (%d, normal %d)' % (track_res['fp'] - normal_res['fp'], track_res['fp'], normal_res['fp']),
                   fmt='%d')
    report.at_most(name + ' track dropouts beyond normal', track_res['seq_dropouts'] - normal_res['seq_dropouts'],
                   t['dropouts_above_normal'],
                   '%+d (%d, normal %d)' % (track_res['seq_dropouts'] - normal_res['seq_dropouts'],
                                            track_res['seq_dropouts'], normal_res['seq_dropouts']), fmt='%d')
    n, k = first_found(sub, normal_dets), first_found(sub, track_dets)
    late = 0
    for key, f in n.items():
        if f is not None:
            late = max(late, (k[key] if k[key] is not None else len(sub.records)) - f)
    report.at_most(name + ' track frames after normal to find a marker', late, t['frames_late'], fmt='%d')
    print('%s: normal median %.3f ms, track median %.3f ms (a busy machine\'s; not asserted)'
          % (name, normal_res['time_ms_median'], track_res['time_ms_median']))


def measure_wrong_ids(sweep, scorer, codebook, subsets, dictionaries, tmp):
    """{(dictionary, subset name): WrongIds} for every dictionary but each
    subset's own."""
    cells = {}
    for sub in subsets:
        runs = measure.matrix_runs(sub, dictionaries, tmp)
        measure.run_sweep(sweep, sub, runs, tmp)
        for d, _, _, dets in runs:
            cells[(d, sub.name)] = measure.wrong_ids(scorer, codebook, sub, d, dets)
    return cells


def main():
    detect, sweep, shared, check = sys.argv[1:5]
    if not os.path.isdir(os.path.join(shared, 'data')):
        print('shared data not found at %s: skipping' % os.path.join(shared, 'data'))
        return 77
    if floors.at_target():
        print('FRAPPE_DATA_FLOORS=target: every check held to its target')
    scorer = measure.load_scorer(shared)
    report = Report()
    with tempfile.TemporaryDirectory() as tmp:
        if check.startswith('synth/'):
            sub = measure.subset(shared, check)
            dets = measure.run_detect(detect, sub, sub.dictionary, os.path.join(tmp, 'dets.jsonl'), tmp)
            res = measure.score(scorer, sub.truth, dets)
            print(scorer.fmt(res))
            check_set(report, check, res)
        elif check == 'track':
            # Mode::Track against Mode::Normal on the sequences, same run.
            for name in ('synth/seq01', 'synth/seq02'):
                sub = measure.subset(shared, name)
                normal = measure.run_detect(detect, sub, sub.dictionary, os.path.join(tmp, 'normal.jsonl'), tmp)
                track = measure.run_detect(detect, sub, sub.dictionary, os.path.join(tmp, 'track.jsonl'), tmp,
                                           ['--mode', 'track'])
                check_track(report, name, sub, measure.score(scorer, sub.truth, normal),
                            measure.score(scorer, sub.truth, track), normal, track)
        elif check == 'real':
            for sub in measure.real_subsets(shared):
                dets = measure.run_detect(detect, sub, sub.dictionary, os.path.join(tmp, 'dets.jsonl'), tmp)
                check_real(report, sub.name, measure.score(scorer, sub.truth, dets))
        elif check == 'wrong-ids':
            subsets = measure.synth_subsets(shared)
            corrects = measure.built_in_dictionaries(detect)
            missing = set(corrects) ^ set(floors.WRONG_IDS_PER_300)
            assert not missing, 'floors.WRONG_IDS_PER_300 and the built-in dictionaries differ: %s' % missing
            cells = measure_wrong_ids(sweep, scorer, measure.CodeBook(corrects), subsets, sorted(corrects), tmp)
            check_wrong_ids(report, cells, subsets)
        elif check == 'exposure':
            for sub in measure.synth_subsets(shared):
                runs = measure.exposure_runs(sub, tmp, sorted(floors.EXPOSURE_POINTS))
                measure.run_sweep(sweep, sub, runs, tmp)
                results = {1.0: measure.score(scorer, sub.truth, runs[0][3])}
                for (_, _, i, dets), g in zip(runs[1:], sorted(floors.EXPOSURE_POINTS)):
                    results[g] = measure.score(scorer, sub.truth, dets)
                check_exposure(report, sub.name, results)
        elif check == 'resolution':
            for sub in measure.synth_subsets(shared):
                runs = measure.resolution_runs(sub, tmp)
                measure.run_sweep(sweep, sub, runs, tmp)
                check_resolution(report, sub.name, measure.score_resolution(scorer, sub, runs, tmp))
        else:
            print('unknown check ' + check)
            return 2
    print('%d of %d checks failed' % (report.failures, len(report.lines)))
    return 1 if report.failures else 0


if __name__ == '__main__':
    sys.exit(main())
