"""`make bench`'s code runs: the quick bench's sections that start no launch give every figure.

`run_bench.py --quick --runs 1` measures nothing worth judging on a loaded host (its windows
are a smoke test's), so the test asserts what makes a bench broken, not slow: it exits 0,
its JSON line names no missing or NaN figure, and every key those sections must produce is
there, finite, with each controller cost's ratio to bare physics beside it. The sections
with launches run in `make bench-quick` and `make bench` only (their real-time windows
starve on a loaded host); the arithmetic is test/unit/test_bench_figures.py's.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import pytest
import run_bench

#: Offline (no ROS, no claim about time): `make test` runs it at the lowest priority.
pytestmark = pytest.mark.offline

RUN_BENCH = Path(run_bench.__file__)
SECTIONS = ('physics', 'offline', 'analysis', 'walking')
#: About 15 CPU s beside two offline walks (physics 6 with the Python reference's runs, walking 6).
TIMEOUT_S = 1200.0


def test_the_quick_bench_gives_every_figure_of_its_offline_sections() -> None:
    result = subprocess.run(
        [sys.executable, str(RUN_BENCH), '--quick', '--runs', '1', '--only', ','.join(SECTIONS)],
        capture_output=True, text=True, timeout=TIMEOUT_S, check=False)
    assert result.returncode == 0, result.stderr[-3000:]
    figures = json.loads(result.stdout.strip().splitlines()[-1])
    assert figures['invalid'] == [] and figures['quick'] is True
    expected = {key for section in SECTIONS for key in run_bench.EXPECTED[section]}
    missing = sorted(key for key in expected
                     if not isinstance(figures.get(key), (int, float))
                     or not math.isfinite(figures[key]))
    assert missing == []
    for cost in ('stand', 'stand_python', 'walk', 'walk_python'):
        assert figures[f'{cost}_bare_ratio'] == pytest.approx(
            figures[f'{cost}_us_per_step'] * figures['bare_physics_steps_per_s'] / 1e6,
            rel=1e-3)
