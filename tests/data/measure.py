"""Runs frappe over the team's data sets and scores it with the team's scorer
(../shared/tools/eval.py): the part shared by tests/data/test_data.py, which
holds the floors, and scripts/quality.py, which prints the tables.

Subsets are named as in the floors table: 'synth/blur', 'real/visp_apriltag'.
Scoring is always eval.evaluate(), so the tests, the harness and the team
count a match, a false positive and a size bucket the same way.
"""
import importlib.util
import json
import os
import subprocess
from dataclasses import dataclass, field

SOURCE_ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..'))

SYNTH = ['images', 'apriltag36h11', 'blur', 'blur-apriltag36h11', '4x4_50', '6x6_250',
         'apriltag_16h5', 'seq01', 'seq02', 'lighting', 'lighting-apriltag36h11']
# Upsampled copies: (factor, interpolation), built by frappe-sweep in memory.
VARIANTS = [(2, 'linear'), (2, 'nearest'), (3, 'linear'), (3, 'nearest')]
# The truth's family names that are not frappe's dictionary names.
ALIASES = {'opencv_6x6_250': '6x6_250', 'opencv_5x5_1000': '5x5_1000'}


def family_of(dictionary):
    """4x4_50/100/250/1000 are one family (the smaller are prefixes of the
    larger), likewise 5x5_*, 6x6_*, 7x7_*; every other dictionary is its own."""
    head = dictionary.split('_')[0]
    return head if len(head) == 3 and head[1] == 'x' else dictionary


def load_jsonl(path):
    with open(path) as f:
        return [json.loads(line) for line in f if line.strip()]


@dataclass
class Subset:
    name: str            # 'synth/blur'
    folder: str
    records: list        # truth.jsonl
    dictionary: str      # frappe's name for the truth's family

    @property
    def truth(self):
        return os.path.join(self.folder, 'truth.jsonl')

    @property
    def frames(self):
        return len(self.records)

    def images(self):
        return [os.path.join(self.folder, r['image']) for r in self.records]


def subset(shared, name):
    folder = os.path.join(shared, 'data', name)
    records = load_jsonl(os.path.join(folder, 'truth.jsonl'))
    family = records[0]['family']
    return Subset(name, folder, records, ALIASES.get(family, family))


def synth_subsets(shared):
    return [subset(shared, 'synth/' + s) for s in SYNTH]


def real_subsets(shared):
    real = os.path.join(shared, 'data', 'real')
    return [subset(shared, 'real/' + f) for f in sorted(os.listdir(real))
            if os.path.isfile(os.path.join(real, f, 'truth.jsonl'))]


def load_scorer(shared):
    path = os.path.join(shared, 'tools', 'eval.py')
    spec = importlib.util.spec_from_file_location('frappe_team_eval', path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def write_list(sub, path):
    with open(path, 'w') as f:
        f.write(''.join(p + '\n' for p in sub.images()))
    return path


def scaled_truth(sub, scale, path):
    """The subset's truth for the image upsampled `scale` times: corners as
    x' = (x + 0.5) s - 0.5, sizes times s, image paths absolute so that the
    detections (which carry the original paths) find their records."""
    def corners(cs):
        return [[(x + 0.5) * scale - 0.5, (y + 0.5) * scale - 0.5] for x, y in cs]

    def marker(m):
        m = dict(m, corners=corners(m['corners']))
        for k in ('side_px', 'min_side_px'):
            if k in m:
                m[k] = m[k] * scale
        return m
    with open(path, 'w') as f:
        for r in sub.records:
            r = dict(r, image=os.path.join(sub.folder, r['image']),
                     markers=[marker(m) for m in r.get('markers', [])],
                     ignore=[marker(m) for m in r.get('ignore', [])])
            f.write(json.dumps(r) + '\n')
    return path


def run_detect(detect, sub, dictionary, out, workdir, extra=()):
    """frappe-detect at defaults, single thread: the contract's command
    (with `extra` options, e.g. a mode)."""
    lst = write_list(sub, os.path.join(workdir, sub.name.replace('/', '-') + '.txt'))
    subprocess.run([detect, '--dictionary', dictionary, '--list', lst, '--out', out, '--threads', '1'] + list(extra),
                   check=True)
    return out


def run_sweep(sweep, sub, runs, workdir):
    """frappe-sweep over the subset: runs is [(dictionary, scale, interp, out)]."""
    lst = write_list(sub, os.path.join(workdir, sub.name.replace('/', '-') + '.txt'))
    args = [sweep, '--list', lst]
    for d, s, i, out in runs:
        args += ['--run', '%s:%d:%s:%s' % (d, s, i, out)]
    subprocess.run(args, check=True)


def score(scorer, truth, dets):
    res = scorer.evaluate([truth], dets)
    assert res['images_missing_in_dets'] == 0 and res['unknown_images_in_dets'] == 0, \
        'every image scored: %s' % dets
    for d in load_jsonl(dets):
        assert 'error' not in d, d
    return res


def large_sensitivity(res, min_side=60):
    """Sensitivity of the markers of min_side px or more, from the scorer's
    size buckets (the truth's side_px); None when there are none."""
    tp = n = 0
    for k, (t, m) in res['sensitivity_by_side_px'].items():
        if float(k.split('-')[0]) >= min_side:
            tp += t
            n += m
    return (tp / n if n else None), tp, n


def misplaced(res):
    """Unmatched detections on or at a labelled marker: wrong id, orientation,
    duplicate, right id with corners off. 'elsewhere' ones are not counted:
    photographs hold markers nobody labelled."""
    return sum(v for k, v in res['fp_kinds'].items() if k != 'elsewhere')


# ----------------------------------------------------------------------------
# Wrong ids: a dictionary over the subsets of the other families.

def built_in_dictionaries(detect):
    """{name: bits corrected} from frappe-detect --dictionaries."""
    out = subprocess.run([detect, '--dictionaries'], check=True, capture_output=True, text=True).stdout
    corrects = {}
    for line in out.splitlines():
        if line.strip():
            corrects[line.split()[0]] = int(line.rsplit('corrects', 1)[1].split(',')[0].strip(' )'))
    return corrects


def load_codes(name):
    """(bits, [code]) of a dictionary, from the files frappe compiles in."""
    bits, codes = None, []
    with open(os.path.join(SOURCE_ROOT, 'frappe-core', 'dictionaries', name + '.txt')) as f:
        for line in f:
            if line.startswith('# marker_side_bits:'):
                bits = int(line.split(':')[1])
            elif line.strip() and not line.startswith('#'):
                codes.append(int(line, 16))
    return bits, codes


def rotations(code, n):
    out = [code]
    for _ in range(3):
        c, r = out[-1], 0
        for row in range(n):
            for col in range(n):
                if (c >> (n * n - 1 - (row * n + col))) & 1:
                    r |= 1 << (n * n - 1 - (col * n + (n - 1 - row)))
        out.append(r)
    return out


def _inside(p, quad):
    sign = None
    for i in range(4):
        (ax, ay), (bx, by) = quad[i], quad[(i + 1) % 4]
        cross = (bx - ax) * (p[1] - ay) - (by - ay) * (p[0] - ax)
        if cross == 0:
            continue
        if sign is None:
            sign = cross > 0
        elif (cross > 0) != sign:
            return False
    return True


@dataclass
class WrongIds:
    """One cell of the matrix: `dictionary` over `subset`."""
    count: int = 0        # wrong ids charged to the detector
    shared: int = 0       # other-family detections on a printed marker whose code is a code of
                          # the asked dictionary (within its correction): right by that dictionary
    same_family: bool = False
    kinds: dict = field(default_factory=dict)
    at_limit: int = 0     # other family: wrong ids decoded with all the bits the dictionary corrects


class CodeBook:
    """Which printed codes are also codes of another dictionary: a detector
    that decodes them is right by the dictionary it was asked for."""

    def __init__(self, corrects):
        self.corrects = corrects
        self._codes = {}
        self._memo = {}

    def codes(self, name):
        if name not in self._codes:
            self._codes[name] = load_codes(name)
        return self._codes[name]

    def shared(self, printed_dict, printed_id, asked_dict, asked_id):
        key = (printed_dict, printed_id, asked_dict, asked_id)
        if key not in self._memo:
            pb, pc = self.codes(printed_dict)
            ab, ac = self.codes(asked_dict)
            ok = pb == ab and 0 <= printed_id < len(pc) and 0 <= asked_id < len(ac)
            if ok:
                ok = min(bin(r ^ ac[asked_id]).count('1') for r in rotations(pc[printed_id], pb)) \
                    <= self.corrects[asked_dict]
            self._memo[key] = ok
        return self._memo[key]


def wrong_ids(scorer, codebook, sub, dictionary, dets):
    """Other family: every detection is a wrong id, except those on a printed
    marker that is a code of the asked dictionary. Same family (another size,
    e.g. 4x4_1000 over 4x4_50): the scorer's false positives."""
    cell = WrongIds(same_family=family_of(dictionary) == family_of(sub.dictionary))
    if cell.same_family:
        res = score(scorer, sub.truth, dets)
        cell.count, cell.kinds = res['fp'], res['fp_kinds']
        return cell
    by_image = {os.path.realpath(d['image']): d for d in load_jsonl(dets)}
    for rec in sub.records:
        det = by_image[os.path.realpath(os.path.join(sub.folder, rec['image']))]
        assert 'error' not in det, det
        for m in det['markers']:
            cx = sum(p[0] for p in m['corners']) / 4
            cy = sum(p[1] for p in m['corners']) / 4
            on = [t for t in rec.get('markers', []) + rec.get('ignore', []) if _inside((cx, cy), t['corners'])]
            if any(codebook.shared(sub.dictionary, t['id'], dictionary, m['id']) for t in on):
                cell.shared += 1
            else:
                cell.count += 1
                cell.at_limit += int(m.get('hamming') == codebook.corrects[dictionary])
                kind = 'on a marker' if on else 'elsewhere'
                cell.kinds[kind] = cell.kinds.get(kind, 0) + 1
    return cell


def matrix_runs(sub, dictionaries, workdir):
    """frappe-sweep runs of every dictionary but the subset's own at 1x."""
    return [(d, 1, 'linear', os.path.join(workdir, '%s-%s.jsonl' % (sub.name.replace('/', '-'), d)))
            for d in dictionaries if d != sub.dictionary]


def resolution_runs(sub, workdir):
    """frappe-sweep runs of the subset's dictionary at 1x and every variant."""
    stem = os.path.join(workdir, sub.name.replace('/', '-'))
    runs = [(sub.dictionary, 1, 'linear', stem + '-1x.jsonl')]
    runs += [(sub.dictionary, s, i, '%s-%dx-%s.jsonl' % (stem, s, i)) for s, i in VARIANTS]
    return runs


def exposure_runs(sub, workdir, lights, as_read=True):
    """frappe-sweep runs of the subset's dictionary as read (the first,
    unless as_read is False) and exposed each of `lights` times as long
    (frappe-sweep's lightG)."""
    stem = os.path.join(workdir, sub.name.replace('/', '-'))
    runs = [(sub.dictionary, 1, 'linear', stem + '-1x.jsonl')] if as_read else []
    runs += [(sub.dictionary, 1, 'light%g' % g, '%s-light%g.jsonl' % (stem, g)) for g in lights]
    return runs


def light_sensitivity(res, effect):
    """Sensitivity of the markers of the images lit with `effect` (the
    truth's params.light), from the scorer's breakdown; None when none."""
    tp, n = res.get('sensitivity_by_light', {}).get(effect, (0, 0))
    return (tp / n if n else None), tp, n


def score_resolution(scorer, sub, runs, workdir):
    """{(scale, interp): eval result}; (1, 'linear') is the image as read."""
    out = {}
    for d, s, i, dets in runs:
        truth = sub.truth if s == 1 else scaled_truth(
            sub, s, os.path.join(workdir, '%s-truth-%dx.jsonl' % (sub.name.replace('/', '-'), s)))
        out[(s, i)] = score(scorer, truth, dets)
    return out
