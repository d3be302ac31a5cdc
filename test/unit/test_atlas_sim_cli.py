"""sim/atlas_sim_node.py's command line: --help, and a refused set-up (exit 1, one fatal line)."""

from __future__ import annotations

import pytest

pytest.importorskip('rospy', reason='needs ROS 1 (source ./env.sh)')

from tutorial_atlas_control.cli import atlas_sim
from tutorial_atlas_control.errors import AtlasControlError


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
