#!/usr/bin/env python3
"""frappe-detect as a user meets it: the contract mode, the human mode,
unreadable files and bad options.

usage: test_cli.py FRAPPE_DETECT
"""
import json
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
SAMPLES = os.path.join(HERE, '..', '..', 'examples', 'images')


def run(*args, cwd=None):
    return subprocess.run(list(args), capture_output=True, text=True, cwd=cwd)


def check(cond, what):
    if not cond:
        print('FAIL: ' + what)
        sys.exit(1)
    print('ok: ' + what)


def main():
    exe = sys.argv[1]
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
        check(r.returncode == 0, 'contract mode exits 0 with bad images in the list')
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
    return 0


if __name__ == '__main__':
    sys.exit(main())
