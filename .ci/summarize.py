#!/usr/bin/env python3
"""Counts meson's test results over one or more testlog.json files: skipped
tests are reported as skipped, not passed. Prints a line per build (its
directory, and the counts), then the total 'N passed, N failed, N skipped'
as the last line; exits 1 on any failure (a missing log counts as one)."""
import json
import os
import sys

total = [0, 0, 0]  # passed, failed, skipped
for path in sys.argv[1:]:
    build = os.path.basename(os.path.dirname(os.path.dirname(path))) or path
    counts = [0, 0, 0]
    try:
        f = open(path)
    except OSError:
        counts[1] += 1
        print('%s: no test log (the build failed)' % build)
    else:
        with f:
            for line in f:
                if not line.strip():
                    continue
                result = json.loads(line)['result']
                if result in ('OK', 'EXPECTEDFAIL'):
                    counts[0] += 1
                elif result == 'SKIP':
                    counts[2] += 1
                else:
                    counts[1] += 1
        print('%s: %d ok / %d failed / %d skipped' % (build, *counts))
    total = [t + c for t, c in zip(total, counts)]
print('%d passed, %d failed, %d skipped' % tuple(total))
sys.exit(1 if total[1] or total[0] == 0 else 0)
