#!/usr/bin/env python3
"""Run a command at the lowest CPU priority, every process it starts included.

`nice -n 19` alone does not do it on Linux with autogroups (kernel.sched_autogroup_enabled,
Debian's default): the scheduler first shares the CPU between sessions, equally, and a
process's nice value only ranks it within its own session. roslaunch starts every node in a
session of its own (setsid), so a niced bench's simulators took as much CPU as a test's
(measured: a nice-19 busy loop in its own session 64 % of a core beside a nice-0 one; 2 %
once its session's autogroup was niced too). This wrapper runs the command at nice 19 in a
session of its own and, every POLL_PERIOD_S, sets the autogroup nice of that session and of
every other session its descendants start to 19 (/proc/PID/autogroup, sched(7)); raising a
nice value needs no privilege. In the caller's session the command would share the caller's
autogroup, and whenever the caller waits (make test's pytest, waiting on a launch) take that
whole autogroup's share.

    python3 tools/lowest_priority.py COMMAND [ARG...]

Exits with the command's status; SIGINT and SIGTERM are passed on to it.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

LOWEST_NICE = 19
#: How often new descendants are looked for (s): they run at full share until found.
POLL_PERIOD_S = 0.5
USAGE = 'usage: lowest_priority.py COMMAND [ARG...]'


def parent_links() -> dict[int, int]:
    """pid -> parent pid of every process now (those that end meanwhile are skipped)."""
    links = {}
    for entry in os.scandir('/proc'):
        if not entry.name.isdigit():
            continue
        try:
            stat = Path(entry.path, 'stat').read_text()
        except OSError:
            continue
        # The command name (field 2) may hold spaces and parentheses: split after its end.
        fields = stat[stat.rindex(')') + 2:].split()
        links[int(entry.name)] = int(fields[1])
    return links


def descendants(root: int, links: dict[int, int]) -> set[int]:
    children: dict[int, list[int]] = {}
    for pid, parent in links.items():
        children.setdefault(parent, []).append(pid)
    found, frontier = set(), [root]
    while frontier:
        for child in children.get(frontier.pop(), ()):
            if child not in found:
                found.add(child)
                frontier.append(child)
    return found


def lower_autogroup(pid: int) -> bool:
    """Set the autogroup nice of `pid`'s session to LOWEST_NICE; False if it was already,
    or if that session is ours (the caller's processes keep their share)."""
    path = Path(f'/proc/{pid}/autogroup')
    try:
        if os.getsid(pid) == os.getsid(0):
            return False
        if path.read_text().split()[-1] == str(LOWEST_NICE):
            return False
        path.write_text(str(LOWEST_NICE))
    except (OSError, IndexError):  # ended meanwhile, or no autogroup support
        return False
    return True


def main(argv: list[str]) -> int:
    if not argv or argv[0] in ('-h', '--help'):
        print(USAGE, file=sys.stdout if argv else sys.stderr)
        return 0 if argv else 2
    try:
        child = subprocess.Popen(argv, preexec_fn=lambda: os.nice(LOWEST_NICE),
                                 start_new_session=True)
    except OSError as error:
        print(f'lowest_priority.py: cannot run {argv[0]}: {error.strerror}', file=sys.stderr)
        return 127
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, lambda received, _frame: child.send_signal(received))
    while child.poll() is None:
        for pid in {child.pid} | descendants(child.pid, parent_links()):
            lower_autogroup(pid)
        time.sleep(POLL_PERIOD_S)
    return child.returncode


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
