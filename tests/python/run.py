#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
# tests/python/run.py: what `meson test --suite python` runs: pytest over
# this folder, or skip (exit code 77) when pytest or numpy is missing.
import os
import sys

try:
    import numpy  # noqa: F401
    import pytest
except ImportError as e:
    print(f"skipped: {e}")
    sys.exit(77)

here = os.path.dirname(os.path.abspath(__file__))
# No cache folder in the source tree; -ra lists what was skipped and why.
sys.exit(pytest.main(["-q", "-ra", "-p", "no:cacheprovider", here] + sys.argv[1:]))
