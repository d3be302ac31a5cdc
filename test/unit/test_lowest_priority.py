"""tools/lowest_priority.py: the command runs at nice 19 in a session of its own whose
autogroup is niced to 19 too, so that it takes only the CPU make test's other tests leave
idle, even while the caller waits (docs/TESTING.md)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

WRAPPER = Path(__file__).resolve().parents[2] / 'tools' / 'lowest_priority.py'
AUTOGROUP = Path('/proc/self/autogroup')
#: What the command prints: its session, its nice value, and its autogroup's nice once that
#: reads 19 (the wrapper sets it within its 0.5 s poll), or after 10 s whatever it reads.
PROBE = '''
import os, time
from pathlib import Path
deadline = time.monotonic() + 10.0
while True:
    nice = Path('/proc/self/autogroup').read_text().split()[-1]
    if nice == '19' or time.monotonic() > deadline:
        break
    time.sleep(0.05)
print(os.getsid(0), os.nice(0), nice)
'''


@pytest.mark.skipif(not AUTOGROUP.exists(), reason='no autogroups in this kernel')
def test_the_command_runs_niced_in_a_niced_session_of_its_own() -> None:
    done = subprocess.run([sys.executable, str(WRAPPER), sys.executable, '-c', PROBE],
                          capture_output=True, text=True, timeout=60, check=False)
    assert done.returncode == 0, done.stderr
    session, nice, autogroup_nice = (int(field) for field in done.stdout.split())
    assert session != os.getsid(0)
    assert nice == 19
    assert autogroup_nice == 19


def test_the_command_s_exit_status_is_passed_on() -> None:
    done = subprocess.run([sys.executable, str(WRAPPER), sys.executable, '-c',
                           'raise SystemExit(3)'],
                          capture_output=True, text=True, timeout=60, check=False)
    assert done.returncode == 3
