#!/usr/bin/env python3
"""frappe-detect's options of issue 13: --json --stats lines that stay JSON,
the untimed warm-up, an image on standard input, --dictionary FILE, and
pose (--camera, --calibration, --marker-size, --marker-sizes) on the sample
image against the geometry it was rendered with.

usage: test_cli_options.py FRAPPE_DETECT FRAPPE_RENDER
"""
import json
import math
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


def diagonal_centre(c):
    """Where the quad's diagonals cross: the projection of the square's centre."""
    (x0, y0), (x1, y1), (x2, y2), (x3, y3) = c
    d1x, d1y, d2x, d2y = x2 - x0, y2 - y0, x3 - x1, y3 - y1
    t = ((x1 - x0) * d2y - (y1 - y0) * d2x) / (d1x * d2y - d1y * d2x)
    return x0 + t * d1x, y0 + t * d1y


def rendering_camera(corners):
    """frappe-render --scene draws each marker with perspectiveSquare: a
    pinhole camera on the square's axis, 4 sides away, of focal length 4 x
    the side in pixels, its centre where the square's centre projects;
    tilted about the square's x axis, rolled about the optical axis. The top
    and bottom edges lie at depths 4 -+ sin(tilt) / 2 sides, so their
    lengths give the tilt and then the side. The marker's centre is at (0, 0,
    4 sides) in that camera."""
    cx, cy = diagonal_centre(corners)
    top, bottom = math.dist(corners[0], corners[1]), math.dist(corners[3], corners[2])
    s = 8 * (top - bottom) / (top + bottom)
    side = top * (4 - 0.5 * s) / 4
    return 4 * side, cx, cy


def pose(exe, sample, expected, tmp):
    size = 0.05
    for truth in expected['markers']:
        f, cx, cy = rendering_camera(truth['corners'])
        r = run(exe, '--json', '--camera', '%.6f,%.6f,%.6f,%.6f' % (f, f, cx, cy), '--marker-size', str(size), sample)
        m = next(m for m in json_lines(r)[0]['markers'] if m['id'] == truth['id'])
        t = m['tvec']
        off = math.dist(t, (0, 0, 4 * size))
        check(r.returncode == 0 and off < 0.01 * 4 * size and m['reprojection_error'] < 0.5,
              'id %d: tvec %s within 1%% of (0, 0, %.2f) m in its rendering camera; reprojection %.3f px'
              % (truth['id'], ['%.4f' % v for v in t], 4 * size, m['reprojection_error']))
        check(len(m['rvec']) == 3, 'rvec given')

    # One camera for all: the id 17's; --marker-sizes gives 10 cm to id 17.
    truth = next(t for t in expected['markers'] if t['id'] == 17)
    f, cx, cy = rendering_camera(truth['corners'])
    camera = '%.6f,%.6f,%.6f,%.6f' % (f, f, cx, cy)
    r = run(exe, '--json', '--camera', camera, '--marker-sizes', '17:0.1', sample)
    markers = json_lines(r)[0]['markers']
    with_pose = [m['id'] for m in markers if 'tvec' in m]
    check(with_pose == [17], 'only the ids with a size get a pose (%s)' % with_pose)
    m17 = next(m for m in markers if m['id'] == 17)
    check(abs(m17['tvec'][2] - 0.4) < 0.004, '--marker-sizes 17:0.1: twice as far (%.4f m)' % m17['tvec'][2])
    r = run(exe, '--camera', camera, '--marker-size', '0.05', sample)
    check(r.returncode == 0 and 'distance 0.2' in text(r.stdout), 'the text output gives the distance')

    # A calibration of twice the size is scaled, with a note; another
    # aspect ratio is an error line.
    def ros(path, w, h, fx, cx_, cy_):
        with open(path, 'w') as out:
            out.write('image_width: %d\nimage_height: %d\ncamera_name: test\ncamera_matrix:\n  rows: 3\n  cols: 3\n'
                      '  data: [%.6f, 0, %.6f, 0, %.6f, %.6f, 0, 0, 1]\ndistortion_model: plumb_bob\n'
                      'distortion_coefficients:\n  rows: 1\n  cols: 5\n  data: [0, 0, 0, 0, 0]\n'
                      % (w, h, fx, cx_, fx, cy_))
    double = os.path.join(tmp, 'double.yaml')
    ros(double, 1280, 960, 2 * f, (cx + 0.5) * 2 - 0.5, (cy + 0.5) * 2 - 0.5)
    r = run(exe, '--json', '--calibration', double, '--marker-size', '0.05', sample)
    m17 = next(m for m in json_lines(r)[0]['markers'] if m['id'] == 17)
    check(r.returncode == 0 and math.dist(m17['tvec'], (0, 0, 0.2)) < 0.002,
          '--calibration for 1280 x 960 scaled to 640 x 480: the same pose')
    check('scaled to the image\'s 640 x 480' in text(r.stderr), 'the scaling noted on stderr')
    wide = os.path.join(tmp, 'wide.yaml')
    ros(wide, 1280, 720, f, cx, cy)
    r = run(exe, '--json', '--calibration', wide, '--marker-size', '0.05', sample)
    line = json_lines(r)[0]
    check(r.returncode == 1 and 'another aspect ratio' in line.get('error', ''),
          'a calibration of another aspect ratio: an error line, exit 1')

    # Bad pose options: exit 2, saying what.
    garbage = os.path.join(tmp, 'garbage.yaml')
    with open(garbage, 'w') as out:
        out.write('hello: world\n')
    for args, what in ((['--calibration', garbage, '--marker-size', '0.05'], garbage),
                       (['--calibration', os.path.join(tmp, 'none.yaml'), '--marker-size', '0.05'], 'none.yaml'),
                       (['--camera', camera, '--marker-sizes', '17:0.1,x'], '--marker-sizes'),
                       (['--camera', camera, '--marker-sizes', '17:-1'], '--marker-sizes'),
                       (['--camera', '700,700,320', '--marker-size', '0.05'], '--camera'),
                       (['--camera', camera, '--marker-size', '0'], '--marker-size'),
                       (['--camera', camera], 'without marker sizes'),
                       (['--marker-size', '0.05'], 'without a camera'),
                       (['--camera', camera, '--calibration', double, '--marker-size', '0.05'], 'give one')):
        r = run(exe, *args, sample)
        check(r.returncode == 2 and what in text(r.stderr) and 'terminate' not in text(r.stderr),
              '%s: exit 2, "%s"' % (' '.join(args), what))


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
        pose(exe, sample, expected, tmp)
    return 0


if __name__ == '__main__':
    sys.exit(main())
