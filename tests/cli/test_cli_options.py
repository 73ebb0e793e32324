#!/usr/bin/env python3
"""frappe-detect's options of issue 13: --json --stats lines that stay JSON,
the untimed warm-up, an image on standard input, --dictionary FILE.

usage: test_cli_options.py FRAPPE_DETECT FRAPPE_RENDER
"""
import json
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.join(HERE, '..', '..')
SAMPLES = os.path.join(ROOT, 'examples', 'images')


def run(*args, stdin=None):
    return subprocess.run(list(args), capture_output=True, input=stdin)


def text(b):
    return b.decode('utf-8', errors='replace')


def check(cond, what):
    if not cond:
        print('FAIL: ' + what)
        sys.exit(1)
    print('ok: ' + what)


def json_lines(r):
    return [json.loads(l) for l in text(r.stdout).splitlines()]


def stats_and_warm_up(exe, sample, scene):
    r = run(exe, '--json', '--stats', sample, scene)
    try:
        lines = json_lines(r)
    except ValueError as e:
        check(False, '--json --stats: every line is JSON (%s)' % e)
    check(r.returncode == 0 and len(lines) == 2, '--json --stats: one JSON line per image')
    stages = ['adaptive_scale_ms', 'front_end_ms', 'trace_ms', 'refine_ms', 'warp_ms', 'decode_ms', 'total_ms']
    for line in lines:
        check(all(isinstance(line['stats'].get(k), float) for k in stages), 'the stages in "stats": %s'
              % sorted(line['stats']))
        total = sum(line['stats'][k] for k in stages[:-1])
        check(abs(total - line['stats']['total_ms']) < 0.01, 'total_ms is the sum of the stages')
    # The warm-up is a detection of the first image, before its timed one.
    check('warm_up_ms' in lines[0]['stats'] and lines[0]['stats']['warm_up_ms'] > 0,
          'the first image reports the untimed warm-up run before it')
    check('warm_up_ms' not in lines[1]['stats'], 'the second image had none')
    r = run(exe, '--stats', sample)
    out = text(r.stdout)
    check(r.returncode == 0 and '  stages: adaptive_scale' in out and 'warm-up before it, untimed' in out,
          '--stats without --json: the text lines, the warm-up named')
    r = run(exe, '--json', sample)
    check('stats' not in json_lines(r)[0], 'no "stats" without --stats')


def standard_input(exe, sample):
    png = open(sample, 'rb').read()
    from_file = json_lines(run(exe, '--json', sample))[0]
    r = run(exe, '--json', '-', stdin=png)
    check(r.returncode == 0, '- reads standard input: exit 0 (%s)' % text(r.stderr).strip())
    line = json_lines(r)[0]
    check(line['image'] == '-' and line['markers'] == from_file['markers'],
          '- with the PNG on standard input: the markers of the file, exactly')
    r = run(exe, '-', stdin=b'')
    check(r.returncode == 1 and 'standard input is empty' in text(r.stderr), 'empty standard input: exit 1, named')
    r = run(exe, '--json', '-', stdin=png[:len(png) // 2])
    check(r.returncode == 1 and 'standard input: truncated PNG' in json_lines(r)[0]['error'],
          'a truncated PNG on standard input: an error line')
    r = run(exe, '-', '-', stdin=png)
    check(r.returncode == 2 and 'standard input' in text(r.stderr), '- twice: exit 2')


def dictionary_files(exe, render, sample, expected, tmp):
    # Three codes of aruco_mip_36h12 as a dictionary of its own: ids 0, 1, 2
    # are the sample's 17, 23 and 10; its 242, 216, 224 are not in it.
    codes = [l.strip() for l in open(os.path.join(ROOT, 'frappe-core', 'dictionaries', 'aruco_mip_36h12.txt'))
             if l.startswith('0x')]
    mine = os.path.join(tmp, 'three.txt')
    with open(mine, 'w') as f:
        f.write('# three of aruco_mip_36h12\n# marker_side_bits: 6\n%s\n%s\n%s\n' % (codes[17], codes[23], codes[10]))
    r = run(exe, '--json', '--dictionary', mine, sample)
    markers = json_lines(r)[0]['markers']
    check(r.returncode == 0 and sorted(m['id'] for m in markers) == [0, 1, 2],
          '--dictionary FILE: exactly its ids 0, 1, 2 (%s)' % [m['id'] for m in markers])
    truth = {t['id']: t['corners'] for t in expected['markers']}
    for m in markers:
        want = truth[[17, 23, 10][m['id']]]
        err = max(abs(a - b) for p, q in zip(m['corners'], want) for a, b in zip(p, q))
        check(err < 0.5, 'custom id %d at the corners of its marker (%.3f px)' % (m['id'], err))
    r = run(exe, '--dictionary', mine, sample)
    check('3 markers (three)' in text(r.stdout), 'the text output names the dictionary by its file')

    # OpenCV's YAML, as its writeDictionary wrote it.
    marker = os.path.join(tmp, 'm7.png')
    check(run(render, '--dictionary', '4x4_50', '--id', '7', '--cell', '12', marker).returncode == 0,
          'frappe-render draws 4x4_50 id 7')
    yml = os.path.join(ROOT, 'tests', 'core', 'dictionaries', 'opencv_4x4_50.yml')
    r = run(exe, '--json', '--dictionary', yml, marker)
    check([m['id'] for m in json_lines(r)[0]['markers']] == [7], '--dictionary OpenCV YAML: id 7')

    bad = os.path.join(tmp, 'bad.txt')
    with open(bad, 'w') as f:
        f.write('0x0ba\n0xnot\n')
    r = run(exe, '--dictionary', bad, sample)
    check(r.returncode == 2 and (bad + ':2:') in text(r.stderr), 'a bad dictionary file: exit 2, file and line')
    r = run(exe, '--dictionary', 'nope', sample)
    check(r.returncode == 2 and "unknown dictionary 'nope'" in text(r.stderr) and 'apriltag_36h11' in text(r.stderr),
          'neither a name nor a file: exit 2, the names listed')


def main():
    exe, render = sys.argv[1], sys.argv[2]
    sample = os.path.join(SAMPLES, 'markers-36h12.png')
    expected = json.load(open(os.path.join(SAMPLES, 'markers-36h12.json')))
    with tempfile.TemporaryDirectory() as tmp:
        scene = os.path.join(tmp, 'scene.png')
        check(run(render, '--scene', '--seed', '3', scene).returncode == 0, 'frappe-render writes a scene')
        stats_and_warm_up(exe, sample, scene)
        standard_input(exe, sample)
        dictionary_files(exe, render, sample, expected, tmp)
    return 0


if __name__ == '__main__':
    sys.exit(main())
