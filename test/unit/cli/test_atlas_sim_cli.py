"""sim/atlas_sim_node.py's command line: --help, and a refused set-up (exit 1, one fatal line)."""

from __future__ import annotations

import pytest

pytest.importorskip('rospy', reason='needs ROS 1 (source ./env.sh)')

from tutorial_atlas_control import topics
from tutorial_atlas_control.cli import atlas_sim
from tutorial_atlas_control.errors import AtlasControlError
from tutorial_atlas_control.node.transport import WireBatch


@pytest.fixture(autouse=True)
def no_other_simulator(monkeypatch: pytest.MonkeyPatch) -> None:
    """No master to ask: the single-instance check passes (test_single_instance.py's)."""
    monkeypatch.setattr(atlas_sim, 'refuse_if_running', lambda *_: False)


def test_help_prints_the_parameters_and_starts_no_node(
        capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(atlas_sim.rospy, 'init_node', lambda *_: pytest.fail('node started'))
    assert atlas_sim.main(['atlas_sim_node.py', '--help']) == 0
    out = capsys.readouterr().out
    assert '~real_time_factor' in out and 'atlas_controller/gains' in out


def test_a_refused_set_up_exits_1_with_one_fatal_line(monkeypatch: pytest.MonkeyPatch) -> None:
    fatal: list[str] = []
    monkeypatch.setattr(atlas_sim.rospy, 'init_node', lambda *_: None)
    monkeypatch.setattr(atlas_sim.rospy, 'logfatal', fatal.append)

    def refuse() -> None:
        raise AtlasControlError('gain atlas_controller/gains/back_lbz/p is missing')

    monkeypatch.setattr(atlas_sim, 'build_node', refuse)
    assert atlas_sim.main(['atlas_sim_node.py']) == 1
    assert fatal == ['atlas_sim: gain atlas_controller/gains/back_lbz/p is missing']


class FakeNode:
    """spin() ends as rospy does when the master hands our name to a newer node."""

    def __init__(self, hooks: list, reason: str) -> None:
        self.hooks = hooks
        self.reason = reason
        self.sim = type('Sim', (), {'dt_s': 0.001, 'time_to_unpin_s': 1.0, 'start': None})()
        self.loop = type('Loop', (), {'real_time_factor': 1.0, 'paused': False,
                                      'outbox': WireBatch()})()
        self.publishers = {topics.CLOCK: 'clock'}

    def spin(self) -> int:
        for hook in self.hooks:
            hook(self.reason)
        return 0


@pytest.mark.parametrize(('reason', 'line'), [
    ('external shutdown request from [/master]: [/atlas_sim] Reason: new node registered '
     'with same name',
     'atlas_sim: another atlas_sim took over: a second simulator registered as /atlas_sim on '
     'http://localhost:11311, so this one stops (its launch and recording end); run one '
     'atlas.launch per master, or give the second its own (roslaunch -p PORT)\n'),
    ('signal-caught', ''),  # Ctrl-C: nothing to explain
])
def test_a_simulator_another_one_replaced_exits_0_with_one_line(
        reason: str, line: str, capsys: pytest.CaptureFixture[str],
        monkeypatch: pytest.MonkeyPatch) -> None:
    hooks: list = []
    monkeypatch.setattr(atlas_sim.rospy, 'init_node', lambda *_: None)
    monkeypatch.setattr(atlas_sim.rospy, 'loginfo', lambda _text: None)
    monkeypatch.setattr(atlas_sim.rospy, 'get_name', lambda: '/atlas_sim')
    monkeypatch.setattr(atlas_sim.rospy.core, 'add_preshutdown_hook', hooks.append)
    monkeypatch.setattr(atlas_sim.rosgraph, 'get_master_uri', lambda: 'http://localhost:11311')
    monkeypatch.setattr(atlas_sim, 'build_node', lambda: FakeNode(hooks, reason))
    assert atlas_sim.main(['atlas_sim_node.py']) == 0
    assert capsys.readouterr().err == line
