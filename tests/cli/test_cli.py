#!/usr/bin/env python3
"""frappe-detect as a user meets it: the contract mode, the human mode,
unreadable files and bad options; hostile input (issue 16): an image whose
header claims 30000 x 30000, truncated files, names that are not UTF-8,
lists that are not files, an --out that cannot be written, long lists in
bounded memory; frappe-render's arguments.

usage: test_cli.py FRAPPE_DETECT FRAPPE_RENDER
"""
import json
import os
import struct
import subprocess
import sys
import tempfile
import time
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))
SAMPLES = os.path.join(HERE, '..', '..', 'examples', 'images')


def run(*args, cwd=None):
    # stderr echoes names that need not be UTF-8
    return subprocess.run(list(args), capture_output=True, text=True, errors='replace', cwd=cwd)


def check(cond, what):
    if not cond:
        print('FAIL: ' + what)
        sys.exit(1)
    print('ok: ' + what)


def png_claiming(path, width, height):
    """A valid PNG header claiming width x height over a few rows of data:
    what the attack used (a 1 MB file of 30000 x 30000)."""
    def chunk(kind, data):
        return struct.pack('>I', len(data)) + kind + data + struct.pack('>I', zlib.crc32(kind + data))
    rows = zlib.compress(b'\0' * (width + 1) * 4)
    with open(path, 'wb') as f:
        f.write(b'\x89PNG\r\n\x1a\n' + chunk(b'IHDR', struct.pack('>IIBBBBB', width, height, 8, 0, 0, 0, 0))
                + chunk(b'IDAT', rows) + chunk(b'IEND', b''))


def max_rss_kb(*args):
    """The peak resident memory of one run of a command, in a fresh child
    (RUSAGE_CHILDREN only grows). In an AddressSanitizer build freed memory
    waits in a quarantine of up to 256 MB before reuse, which would be
    counted as ours: the run gets none (the option means nothing elsewhere)."""
    code = ('import resource, subprocess, sys\n'
            'r = subprocess.run(sys.argv[1:], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)\n'
            'print(r.returncode, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)\n')
    env = dict(os.environ)
    env['ASAN_OPTIONS'] = ':'.join(o for o in (env.get('ASAN_OPTIONS', ''), 'quarantine_size_mb=0') if o)
    rc, kb = subprocess.run([sys.executable, '-c', code] + list(args), capture_output=True,
                            text=True, env=env).stdout.split()
    return int(rc), int(kb)


def hostile_input(exe, render, sample, tmp):
    out = os.path.join(tmp, 'hostile.jsonl')

    # 1. Refused from the header, before decoding; the other images go on.
    big = os.path.join(tmp, 'big.png')
    png_claiming(big, 30000, 30000)
    lst = os.path.join(tmp, 'big-list.txt')
    with open(lst, 'w') as f:
        f.write('%s\n%s\n%s\n' % (sample, big, sample))
    t0 = time.monotonic()
    r = run(exe, '--list', lst, '--out', out)
    elapsed = time.monotonic() - t0
    lines = [json.loads(l) for l in open(out)]
    check(r.returncode == 1 and len(lines) == 3, 'a too-large image in a list: one line each, then exit 1')
    check('error' in lines[1] and '30000 x 30000' in lines[1]['error'] and 'not decoded' in lines[1]['error'],
          'the too-large image is an error line: %s' % lines[1].get('error'))
    check(len(lines[0]['markers']) > 0 and len(lines[2]['markers']) > 0, 'the images around it are detected')
    check(elapsed < 20, 'refused without decoding (%.1f s)' % elapsed)
    rc, kb = max_rss_kb(exe, big)
    check(rc == 1 and kb < 300 * 1024, 'human mode: exit 1, %d MB at most (900 MB to decode it)' % (kb // 1024))
    r = run(exe, big)
    check('more than the limit of 67108864 pixels' in r.stderr, 'the limit named on stderr')
    # A format whose header is not read: bounded by its file size (sparse here).
    sparse = os.path.join(tmp, 'huge.tif')
    with open(sparse, 'wb') as f:
        f.write(b'II*\0')
        f.truncate(600 * 1024 * 1024)
    r = run(exe, sparse)
    check(r.returncode == 1 and 'more than the limit of 553648128' in r.stderr,
          'an unknown format over 528 MiB is refused unread')
    os.remove(sparse)

    # 4. Truncated images: an error each, not half the markers.
    scene = os.path.join(tmp, 'scene.jpg')
    r = run(render, '--scene', '--seed', '3', scene)
    check(r.returncode == 0, 'frappe-render writes a JPEG scene')
    r = run(exe, '--json', scene)
    check(r.returncode == 0 and len(json.loads(r.stdout)['markers']) > 0, 'the whole JPEG is detected')
    data = open(scene, 'rb').read()
    half_jpg = os.path.join(tmp, 'half.jpg')
    open(half_jpg, 'wb').write(data[:len(data) // 2])
    data = open(sample, 'rb').read()
    half_png = os.path.join(tmp, 'half.png')
    open(half_png, 'wb').write(data[:len(data) // 2])
    for path, what in ((half_jpg, 'truncated JPEG: no end-of-image marker (FFD9)'),
                       (half_png, 'truncated PNG')):
        r = run(exe, path)
        check(r.returncode == 1 and what in r.stderr, '%s: exit 1, "%s"' % (os.path.basename(path), what))
        r = run(exe, '--json', path)
        line = json.loads(r.stdout)
        check(line['markers'] == [] and what in line['error'], '%s: an error line' % os.path.basename(path))

    # 5. Names: valid UTF-8 exactly as listed, other bytes as \u00XX.
    latin1 = os.path.join(tmp.encode(), b'caf\xe9.png')
    utf8 = os.path.join(tmp, 'caf\u00e9-\u65e5.png')
    for name in (latin1, utf8):
        with open(name, 'wb') as f:
            f.write(open(sample, 'rb').read())
    lst = os.path.join(tmp, 'names.txt')
    with open(lst, 'wb') as f:
        f.write(latin1 + b'\n' + utf8.encode() + b'\n' + os.path.join(tmp.encode(), b'missing-\xff.png') + b'\n')
    r = run(exe, '--list', lst, '--out', out)
    raw = open(out, 'rb').read().splitlines()
    try:
        lines = [json.loads(l.decode('utf-8')) for l in raw]
    except ValueError as e:
        check(False, 'every line valid UTF-8 JSON (%s)' % e)
    check(len(lines) == 3, 'names that are not UTF-8: every line valid JSON')
    check(lines[0]['image'] == os.path.join(tmp, 'caf\u00e9.png') and b'caf\\u00e9.png' in raw[0],
          'a byte that is not UTF-8 is written \\u00XX')
    check(lines[1]['image'] == utf8 and utf8.encode() in raw[1], 'a UTF-8 name printed exactly as listed')
    check('\\u00ff' in raw[2].decode() and 'error' in lines[2], 'the same in an error line')

    # 6. --list must be a regular file of bounded size.
    fifo = os.path.join(tmp, 'fifo')
    os.mkfifo(fifo)
    for what, path, message in (('a directory', tmp, 'a directory, not a file'),
                                ('/dev/zero', '/dev/zero', 'not a regular file'),
                                ('a FIFO', fifo, 'not a regular file')):
        t0 = time.monotonic()
        r = run(exe, '--list', path, '--out', out)
        check(r.returncode == 2 and message in r.stderr and time.monotonic() - t0 < 20,
              '--list on %s: exit 2 at once, "%s"' % (what, message))
    huge = os.path.join(tmp, 'huge-list.txt')
    with open(huge, 'wb') as f:
        f.truncate(64 * 1024 * 1024 + 1)
    r = run(exe, '--list', huge, '--out', out)
    check(r.returncode == 2 and 'more than the limit' in r.stderr, '--list over 64 MiB: exit 2')
    with open(huge, 'w') as f:
        f.write('a\n' * 1000001)
    r = run(exe, '--list', huge, '--out', out)
    check(r.returncode == 2 and 'more than 1000000 images' in r.stderr, '--list of more than 1000000 images: exit 2')

    # 3. --out is opened before the run.
    for path in (os.path.join(tmp, 'no-such-dir', 'x.jsonl'), tmp):
        r = run(exe, '--list', lst, '--out', path)
        check(r.returncode == 2 and ('cannot write --out ' + path) in r.stderr and 'caf' not in r.stderr,
              '--out %s: exit 2 before any image is read' % path)

    # 2. A long list streams: memory stays that of a few frames (300 KB each
    # here), with one thread or two, one repeat or three; the order holds.
    lst = os.path.join(tmp, 'long.txt')
    with open(lst, 'w') as f:
        f.write(('%s\n' % sample) * 400)
    rc, one = max_rss_kb(exe, '--list', lst, '--out', out, '--threads', '1')
    check(rc == 0 and len(open(out).readlines()) == 400, '400 images, 400 lines')
    rc, two = max_rss_kb(exe, '--list', lst, '--out', out, '--threads', '2', '--repeat', '3')
    check(rc == 0 and len(open(out).readlines()) == 400, '400 images, 3 repeats, 2 threads, 400 lines')
    rc, single = max_rss_kb(exe, sample)
    check(max(one, two) < single + 40 * 1024,
          'bounded memory: %d / %d MB for 400 images, %d MB for one (120 MB to hold them all)'
          % (one // 1024, two // 1024, single // 1024))
    with open(lst, 'w') as f:
        f.write('\n'.join([sample, half_jpg, sample, big, os.path.join(tmp, 'missing.png'), scene, sample]) + '\n')
    r = run(exe, '--list', lst, '--out', out, '--threads', '2', '--repeat', '2')
    lines = [json.loads(l) for l in open(out)]
    check([l['image'] for l in lines] == [sample, half_jpg, sample, big, os.path.join(tmp, 'missing.png'), scene, sample]
          and ['error' in l for l in lines] == [False, True, False, True, True, False, False],
          'two threads: errors and detections in list order')
    annotated = os.path.join(tmp, 'annotated')
    r = run(exe, sample, scene, '--annotate', annotated)
    check(r.returncode == 0 and sorted(os.listdir(annotated)) == ['markers-36h12.png', 'scene.png'],
          '--annotate with several images writes each')


def max_rss_kb_stdin(exe, megabytes):
    """The peak resident memory of frappe-detect reading `megabytes` MiB of
    zeros from standard input (a pipe, so its length is not known)."""
    code = ('import resource, subprocess, sys\n'
            'p = subprocess.Popen(sys.argv[2:], stdin=subprocess.PIPE, stdout=subprocess.DEVNULL,\n'
            '                     stderr=subprocess.DEVNULL)\n'
            'chunk = bytes(1 << 20)\n'
            'for _ in range(int(sys.argv[1])):\n'
            '    p.stdin.write(chunk)\n'
            'p.stdin.close()\n'
            'print(p.wait(), resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)\n')
    env = dict(os.environ)
    env['ASAN_OPTIONS'] = ':'.join(o for o in (env.get('ASAN_OPTIONS', ''), 'quarantine_size_mb=0') if o)
    rc, kb = subprocess.run([sys.executable, '-c', code, str(megabytes), exe, '-'], capture_output=True,
                            text=True, env=env).stdout.split()
    return int(rc), int(kb)


def format_bombs(exe, tmp):
    """Issue 34: a 10 KB WebP decoded to 1.1 GB and a 1.8 MB TIFF to 0.94 GB
    before the pixel limit applied, and 528 MiB of standard input took
    1.1 GB. Now every format's size is read before decoding, what has none
    to read is not decoded, and standard input grows in place."""
    bombs = {
        'bomb.webp': (b'RIFF' + struct.pack('<I', 22) + b'WEBPVP8X' + struct.pack('<I', 10) + b'\0' * 4
                      + (16383 - 1).to_bytes(3, 'little') * 2 + b'\0' * 2, '16383 x 16383 WebP'),
        'bomb.tif': (b'II*\0' + struct.pack('<IH', 8, 2) + struct.pack('<HHII', 256, 4, 1, 40000)
                     + struct.pack('<HHII', 257, 3, 1, 30000), '40000 x 30000 TIFF'),
        'bomb.pam': (b'P7\nWIDTH 20000\nHEIGHT 20000\nDEPTH 1\nMAXVAL 255\nENDHDR\n', '20000 x 20000 PAM'),
    }
    for name, (data, what) in bombs.items():
        path = os.path.join(tmp, name)
        with open(path, 'wb') as f:
            f.write(data)
        r = run(exe, path)
        check(r.returncode == 1 and (what + ', more than the limit of 67108864 pixels') in r.stderr
              and 'not decoded' in r.stderr, '%s: refused from its header (%s)' % (name, r.stderr.strip()))
    gif = os.path.join(tmp, 'image.gif')
    with open(gif, 'wb') as f:
        f.write(b'GIF89a' + b'\0' * 100)
    r = run(exe, gif)
    check(r.returncode == 1 and 'not an image of a format whose size frappe-detect reads before decoding'
          in r.stderr, 'a format whose size is not read is not decoded')
    rc, kb = max_rss_kb_stdin(exe, 300)
    check(rc == 1 and kb < 450 * 1024, '300 MiB on standard input: %d MB at most (815 MB before)' % (kb // 1024))


def render_arguments(render, tmp):
    out = os.path.join(tmp, 'marker.png')
    r = run(render, '--id', '7', '--cell', '10', out)
    check(r.returncode == 0 and os.path.getsize(out) > 100, 'frappe-render draws a marker')
    for args in (['--id', 'x'], ['--id', '-1'], ['--id', '99999999999'], ['--cell', '0'], ['--cell', '1e3'],
                 ['--quiet', ''], ['--seed', '12abc'], ['--count', '1000', '--scene'], ['--cell']):
        r = run(render, *args, out)
        check(r.returncode == 2 and 'usage:' in r.stderr and 'terminate' not in r.stderr
              and (args[0] in r.stderr), 'frappe-render %s: exit 2 with usage' % ' '.join(args))
    r = run(render, '--id', '100000', out)
    check(r.returncode == 2 and 'id must be in 0..' in r.stderr, 'frappe-render: an id beyond the dictionary')
    r = run(render, out, out + '2.png')
    check(r.returncode == 2 and 'one output file' in r.stderr, 'frappe-render: two output files')
    r = run(render, os.path.join(tmp, 'marker.nope'))
    check(r.returncode == 1 and 'cannot write' in r.stderr and 'terminate' not in r.stderr,
          'frappe-render: an unknown extension is an error, not an abort')
    r = run(render, '--scene', os.path.join(tmp, 'no-such-dir', 'scene.png'))
    check(r.returncode == 1 and 'cannot write' in r.stderr, 'frappe-render: an unwritable scene')


def main():
    exe = sys.argv[1]
    render = sys.argv[2]
    sample = os.path.join(SAMPLES, 'markers-36h12.png')
    expected = json.load(open(os.path.join(SAMPLES, 'markers-36h12.json')))
    with tempfile.TemporaryDirectory() as tmp:
        # Contract mode, with a missing and an unreadable file in the list.
        bad = os.path.join(tmp, 'not-an-image.png')
        with open(bad, 'w') as f:
            f.write('hello')
        lst = os.path.join(tmp, 'list.txt')
        with open(lst, 'w') as f:
            f.write('# a comment\n\n%s\n%s\n%s\n' % (sample, os.path.join(tmp, 'missing.png'), bad))
        out = os.path.join(tmp, 'dets.jsonl')
        r = run(exe, '--dictionary', 'aruco_mip_36h12', '--list', lst, '--out', out, '--repeat', '3',
                '--threads', '1')
        check(r.returncode == 1, 'contract mode: every line written, then exit 1 for the bad images')
        lines = [json.loads(l) for l in open(out)]
        check(len(lines) == 3, 'one JSON line per listed image')
        check(lines[0]['image'] == sample, 'image path exactly as listed')
        ids = sorted(m['id'] for m in lines[0]['markers'])
        check(ids == sorted(m['id'] for m in expected['markers']), 'sample ids %s' % ids)
        for m in lines[0]['markers']:
            truth = next(t for t in expected['markers'] if t['id'] == m['id'])
            err = max(abs(a - b) for p, q in zip(m['corners'], truth['corners']) for a, b in zip(p, q))
            check(err < 0.5, 'id %d corners within 0.5 px of the rendered truth (%.3f)' % (m['id'], err))
        check(lines[0]['time_ms'] > 0, 'time_ms reported')
        check('error' in lines[1] and lines[1]['markers'] == [], 'missing file is an error entry')
        check('error' in lines[2], 'undecodable file is an error entry')
        check('missing.png' in r.stderr and 'not-an-image.png' in r.stderr, 'errors on stderr')

        # Human mode.
        png = os.path.join(tmp, 'annotated.png')
        r = run(exe, sample, '--annotate', png)
        check(r.returncode == 0, 'human mode exits 0')
        check(('%d markers' % len(expected['markers'])) in r.stdout, 'prints the marker count')
        check(os.path.getsize(png) > 1000, 'writes the annotated image')
        r = run(exe, os.path.join(tmp, 'missing.png'))
        check(r.returncode == 1 and 'cannot open' in r.stderr, 'unreadable file in human mode: exit 1')

        # Bad options.
        r = run(exe, '--dictionary', 'nope', sample)
        check(r.returncode == 2 and "unknown dictionary 'nope'" in r.stderr, 'unknown dictionary named')
        r = run(exe, '--repeat', 'x', sample)
        check(r.returncode == 2, 'non-numeric --repeat rejected')
        r = run(exe, '--dictionaries')
        check(r.returncode == 0 and 'apriltag_36h11' in r.stdout, '--dictionaries lists them')
        r = run(exe, '--list', os.path.join(tmp, 'nolist.txt'), '--out', out)
        check(r.returncode == 2, 'missing list file is an error')
        r = run(exe, '--backend', 'gpu', sample)
        check(r.returncode == 2 and 'vc4-emu' in r.stderr, 'unknown backend: the known ones named')

        # The QPU front end on the emulator gives exactly the CPU's markers.
        if os.environ.get('FRAPPE_HAVE_VC4') == '1':
            outs = {}
            for backend in ('cpu', 'vc4-emu'):
                r = run(exe, '--backend', backend, '--json', sample)
                check(r.returncode == 0, '--backend %s exits 0' % backend)
                outs[backend] = json.loads(r.stdout)['markers']
            check(len(outs['cpu']) == len(expected['markers']), 'cpu finds every sample marker')
            # The margin comes from the warp's samples, which the QPUs compute
            # in their own float arithmetic: equal to a few thousandths.
            def strip(markers):
                return [{k: v for k, v in m.items() if k != 'margin'} for m in markers]
            check(strip(outs['vc4-emu']) == strip(outs['cpu']), '--backend vc4-emu: the same ids and corners as cpu')
            check(all('margin' in m and 0.0 <= m['margin'] <= 1.0 for m in outs['cpu']), 'margin reported, in [0, 1]')
            check(all(abs(a['margin'] - b['margin']) < 0.02 for a, b in zip(outs['vc4-emu'], outs['cpu'])),
                  '--backend vc4-emu: the same margins as cpu, to 0.02')
            r = run(exe, '--backend', 'vc4', sample)
            if r.returncode == 0:
                print('ok: --backend vc4 runs (the QPUs are usable here)')
            else:
                check(r.returncode == 2 and 'cannot' in r.stderr.lower() and len(r.stderr) > 40,
                      '--backend vc4 without a usable GPU: exit 2 with the reason (%s)' % r.stderr.strip())

        hostile_input(exe, render, sample, tmp)
        format_bombs(exe, tmp)
        render_arguments(render, tmp)
    return 0


if __name__ == '__main__':
    sys.exit(main())
