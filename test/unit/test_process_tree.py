"""demo.descendants/alive: how a stopped launch's leftovers are found (roslaunch setsid()s its nodes)."""

from __future__ import annotations

import subprocess
import time
from pathlib import Path

from tutorial_atlas_control.demo import alive, descendants


def session(pid: int) -> int:
    return int((Path('/proc') / str(pid) / 'stat').read_text().rsplit(')', 1)[1].split()[3])


def test_descendants_follow_parents_across_sessions_and_alive_drops_the_dead() -> None:
    # A child that moves to its own session, as roslaunch's nodes do, and an ordinary one.
    parent = subprocess.Popen(['bash', '-c', 'setsid sleep 30 & sleep 30 & wait'])
    try:
        deadline = time.monotonic() + 5.0
        while time.monotonic() < deadline:  # until both started, one of them setsid()ed
            found = descendants(parent.pid)
            if len(found) == 2 and len({session(pid) for pid in found}) == 2:
                break
            time.sleep(0.05)
        assert len(found) == 2, found
        assert len({session(pid) for pid in found}) == 2, 'one runs in a session of its own'
        assert alive(found) == found
    finally:
        for pid in [parent.pid, *descendants(parent.pid)]:
            subprocess.run(['kill', '-9', str(pid)], check=False)
        parent.wait()
    deadline = time.monotonic() + 5.0
    while alive(found) and time.monotonic() < deadline:
        time.sleep(0.05)  # init reaps the orphans
    assert alive(found) == []
