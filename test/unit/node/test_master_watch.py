"""master_watch.py: one line when the master goes, registering again when a new one answers."""

from __future__ import annotations

import pytest

master_watch = pytest.importorskip('tutorial_atlas_control.node.master_watch',
                                   reason='needs the catkin workspace: source ./env.sh')
URI = 'http://localhost:11311'


class Log:
    def __init__(self) -> None:
        self.lines: list[tuple[str, str]] = []

    def warn(self, text: str) -> None:
        self.lines.append(('warn', text))

    def info(self, text: str) -> None:
        self.lines.append(('info', text))


def test_gone_once_then_registered_again_with_a_new_master() -> None:
    log, calls = Log(), []
    watch = master_watch.MasterWatch(URI, 100, log.warn, log.info)

    def reregister() -> tuple[int, int, int, int]:
        calls.append(1)
        return (16, 11, 8, 6)

    watch.update(100, reregister)
    assert log.lines == [] and calls == []
    watch.update(None, reregister)
    assert log.lines == [], 'one slow answer is not a master gone'
    watch.update(None, reregister)
    watch.update(None, reregister)
    assert log.lines == [('warn', master_watch.gone_line(URI))], 'said once'
    watch.update(200, reregister)
    assert calls == [1]
    assert log.lines[-1] == ('info', f'a ROS master is back at {URI}: registered again 16 '
                             'publications, 11 subscriptions and 8 services, and set again 6 '
                             'parameters')
    watch.update(200, reregister)
    assert calls == [1] and len(log.lines) == 2


def test_a_quick_restart_unseen_down_is_still_a_new_master() -> None:
    log, calls = Log(), []
    watch = master_watch.MasterWatch(URI, 100, log.warn, log.info)
    watch.update(101, lambda: calls.append(1) or (1, 1, 1, 0))
    assert calls == [1] and log.lines[0][0] == 'info'


def test_the_same_master_answering_again_registers_nothing() -> None:
    log = Log()
    watch = master_watch.MasterWatch(URI, 100, log.warn, log.info)
    watch.update(None, lambda: pytest.fail('no new master'))
    watch.update(None, lambda: pytest.fail('no new master'))
    watch.update(100, lambda: pytest.fail('no new master'))
    assert log.lines[-1] == ('info', f'the ROS master at {URI} answers again')


def test_a_failed_registration_is_tried_again_at_the_next_poll() -> None:
    log = Log()
    watch = master_watch.MasterWatch(URI, 100, log.warn, log.info)

    def fails() -> tuple[int, int, int, int]:
        raise OSError('connection refused')

    with pytest.raises(OSError):
        watch.update(200, fails)
    watch.update(200, lambda: (1, 2, 3, 4))
    assert watch.pid == 200 and log.lines[-1][0] == 'info'
