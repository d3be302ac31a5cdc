"""The load run's memory baseline waits for its floods to report their start (bench/load.py).

Stand-in floods (small Python processes writing what flood_commands.py writes) replace the
real ones, so no ROS master is needed.
"""

from __future__ import annotations

import subprocess
import sys

import load
import pytest
from harness import BenchError


class RunningLaunch:
    """A launch that is still running (load.py only asks that)."""

    def check_running(self) -> None:
        pass


def stand_in_flood(script: str) -> load.Flood:
    return load.Flood(subprocess.Popen([sys.executable, '-c', script], stdout=subprocess.PIPE,
                                       stderr=subprocess.PIPE, text=True))


def starting_flood(sent: int) -> str:
    """Waits, says it started (as flood_commands.py does), waits, prints its figures."""
    return ('import sys, time\n'
            'print("waiting for /clock", file=sys.stderr, flush=True)\n'
            'time.sleep(0.3)\n'
            'print("flood_commands.py: started at sim 2.001 s", file=sys.stderr, flush=True)\n'
            'time.sleep(0.3)\n'
            f'print(\'{{"sent": {sent}}}\')\n')


def test_floods_are_waited_for_until_each_reports_its_start() -> None:
    floods = [stand_in_flood(starting_flood(sent)) for sent in (10, 20)]
    load._wait_floods_started(RunningLaunch(), floods)
    assert all(flood.started.is_set() for flood in floods)
    assert all('started at sim' in flood.stderr_lines[-1] for flood in floods)
    assert load._flood_figures(floods, duration_s=5.0) == [{'sent': 10}, {'sent': 20}]


def test_a_flood_that_never_starts_fails_the_run_with_its_error() -> None:
    failing = stand_in_flood('import sys\n'
                             'sys.exit("flood_commands.py: no /clock, or fewer than 2 '
                             'subscribers to /atlas/joint_commands")\n')
    floods = [stand_in_flood(starting_flood(10)), failing]
    with pytest.raises(BenchError) as raised:
        load._wait_floods_started(RunningLaunch(), floods)
    assert str(raised.value) == ('flood_commands.py exited (1) before its flood began: '
                                 'flood_commands.py: no /clock, or fewer than 2 subscribers '
                                 'to /atlas/joint_commands')
    floods[0].process.wait(timeout=10)
