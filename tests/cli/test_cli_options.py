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


def track_mode(exe, sample, expected, tmp):
    """--mode track over a list in frame order: each marker says whether it
    was tracked, --stats says what the front end read; --threads and
    --repeat fall back to one."""
    listed = os.path.join(tmp, 'video.txt')
    with open(listed, 'w') as f:
        f.write((sample + '\n') * 4)
    out = os.path.join(tmp, 'video.jsonl')
    r = run(exe, '--mode', 'track', '--list', listed, '--out', out, '--json', '--stats', '--threads', '2',
            '--repeat', '3')
    check(r.returncode == 0, '--mode track: exit 0 (%s)' % text(r.stderr))
    check('using --threads 1' in text(r.stderr) and 'using --repeat 1' in text(r.stderr),
          '--mode track: one thread, one repetition, said on stderr')
    lines = json_lines(r)
    ids = sorted(m['id'] for m in expected['markers'])
    check(len(lines) == 4 and all(sorted(m['id'] for m in l['markers']) == ids for l in lines),
          '--mode track: every frame finds the sample\'s markers')
    check(not any(m['tracked'] for m in lines[0]['markers'])
          and all(m['tracked'] for l in lines[1:] for m in l['markers']),
          '--mode track: found afresh on the first frame, tracked after')
    w_h = lines[0]['stats']['bytes_read']
    check(lines[0]['stats']['whole_frame'] and not lines[1]['stats']['whole_frame'],
          '--mode track: the first frame whole, the next in regions')
    check(all('"tracked"' in l for l in open(out)), '--out lines say "tracked" too')
    normal = json_lines(run(exe, '--json', '--stats', sample))[0]
    check('tracked' not in normal['markers'][0] and normal['stats']['bytes_read'] == w_h,
          '--mode normal: no "tracked"; bytes_read is the frame\'s')
    r = run(exe, '--mode', 'fast', sample)
    check(r.returncode == 2 and 'normal, ascale or track' in text(r.stderr), '--mode fast: exit 2, the modes named')
    r = run(exe, '--mode', 'track', '--track-cover-frames', '0', sample)
    check(r.returncode != 0 and 'track_cover_frames' in text(r.stderr), '--track-cover-frames 0 is refused')


def layouts_and_bundles(exe, render, tmp):
    """Issue 32: a layout family rendered and read with its corners; a board
    printed by frappe-render --board and its bundle file read back by
    --bundle: one pose from all its markers, face on at the camera's
    distance."""
    tag = os.path.join(tmp, 'tag41.png')
    check(run(render, '--dictionary', 'tagStandard41h12', '--id', '7', '--cell', '10', tag).returncode == 0,
          'frappe-render draws a tagStandard41h12 marker')
    r = run(exe, '--json', '--dictionary', 'tagStandard41h12', tag)
    m = json_lines(r)[0]['markers']
    # 11 x 11 cells of 10 px with the quiet cell; the found square is cells 3..8.
    check(len(m) == 1 and m[0]['id'] == 7 and
          max(abs(a - b) for p, q in zip(m[0]['corners'], [[29.5, 29.5], [79.5, 29.5], [79.5, 79.5], [29.5, 79.5]])
              for a, b in zip(p, q)) < 0.1,
          'tagStandard41h12 id 7 read with the found square\'s corners: %s' % m)
    board = os.path.join(tmp, 'board.png')
    check(run(render, '--board', '3x4', '--cell', '8', '--first-id', '5', '--marker-size', '0.08', board).returncode == 0,
          'frappe-render --board writes a board and its bundle file')
    bundle = os.path.join(tmp, 'board.yaml')
    # Squares of 64 px for 8 cm: a focal length of 800 px puts the board 1 m away, face on.
    r = run(exe, '--json', '--camera', '800,800,167.5,127.5', '--bundle', bundle, board)
    line = json_lines(r)[0]
    b = line.get('bundle')
    check(r.returncode == 0 and len(line['markers']) == 12 and b and b['used'] == list(range(5, 17))
          and b['rejected'] == [], '--bundle: one pose from the 12 markers: %s' % b)
    check(abs(b['tvec'][2] - 1.0) < 0.01 and b['pose_error'] < 0.5,
          '--bundle: the board 1 m away (%.4f m), reprojected within %.3f px' % (b['tvec'][2], b['pose_error']))
    r = run(exe, '--bundle', bundle, board)
    check(r.returncode == 2 and 'a bundle without a camera' in text(r.stderr), '--bundle without a camera: exit 2')
    bad = os.path.join(tmp, 'bad.yaml')
    with open(bad, 'w') as f:
        f.write('board: hexagon\n')
    r = run(exe, '--camera', '800,800,167.5,127.5', '--bundle', bad, board)
    check(r.returncode == 2 and "board: 'hexagon' is not a known board" in text(r.stderr), '--bundle FILE of no bundle: exit 2')


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
        track_mode(exe, sample, expected, tmp)
        layouts_and_bundles(exe, render, tmp)
    return 0


if __name__ == '__main__':
    sys.exit(main())
