"""A scored offline run: the VRC course's scoring in the offline tick writes /vrc_score to
the bag as the node publishes it, and analyze_bag.py prints its timeline."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from support.scored_runs import GATE_TELEPORTS, record_teleported_run
from tutorial_atlas_control.bags import read_bag, read_scores
from tutorial_atlas_control.cli.analyze_bag import main
from tutorial_atlas_control.offline.player import OfflinePlayer, open_offline_bag
from tutorial_atlas_control.sim import model as atlas_model
from tutorial_atlas_control.sim.controller import load_gains_yaml
from tutorial_atlas_control.sim.simulator import AtlasSimulator

CONFIG = Path(__file__).resolve().parents[3] / 'config' / 'atlas_controller.yaml'
#: (sim time s, pelvis x, y): through gate_0 (x 1, y -38, yaw 0), then gate_1 (0, -22, 90°).
TELEPORTS = GATE_TELEPORTS


@pytest.fixture(scope='module')
def scored_bag(tmp_path_factory: pytest.TempPathFactory) -> Path:
    directory = tmp_path_factory.mktemp('scored')
    sim = AtlasSimulator(atlas_model.load_model(), load_gains_yaml(CONFIG))
    return record_teleported_run(sim, directory / 'scored.bag', directory / 'vrc_task_2', 2.5)


def test_the_bag_has_the_scores_rows(scored_bag: Path) -> None:
    entries = read_scores(read_bag(scored_bag))
    assert entries is not None
    events = [(round(e.sim_time_s, 3), e.completion, e.message) for e in entries if e.message]
    assert events == [(0.601, 0, 'Successfully passed through gate 1. Starting clock. '),
                      (0.901, 1, 'Successfully passed through gate 2. ')]
    assert [round(e.sim_time_s, 3) for e in entries] == [0.601, 0.901, 1.901]
    assert entries[-1].sim_elapsed_s == pytest.approx(1.3, abs=1e-9)
    log = (scored_bag.parent / 'vrc_task_2' / 'score.log').read_text().splitlines()
    assert [line.split(',')[1] for line in log[4:]] == ['0.601', '0.901', '1.901']


def test_analyze_bag_prints_the_score_timeline(scored_bag: Path,
                                               capsys: pytest.CaptureFixture[str]) -> None:
    assert main([str(scored_bag)]) == 0
    out = capsys.readouterr().out
    assert ('VRC score (/vrc_score; sim time): completion 1, falls 0, 1.300 s since gate 1'
            in out)
    assert ('      0.901 s  score 1  falls 0     0.300 s since gate 1' in out
            and 'Successfully passed through gate 2.' in out)
    assert main([str(scored_bag), '--json']) == 0
    scores = json.loads(capsys.readouterr().out)['vrc_score']
    assert [(s['completion'], round(s['sim_time_s'], 3)) for s in scores] == [
        (0, 0.601), (1, 0.901), (1, 1.901)]


def test_an_unscored_bag_prints_no_score(tmp_path: Path,
                                         capsys: pytest.CaptureFixture[str]) -> None:
    sim = AtlasSimulator(atlas_model.load_model(), load_gains_yaml(CONFIG))
    bag = tmp_path / 'plain.bag'
    sink = open_offline_bag(bag)
    try:
        player = OfflinePlayer(sim, sink)
        player.publish()
        player.advance(0.2)
        player.write_steps()
    finally:
        sink.close()
    assert read_scores(read_bag(bag)) is None
    assert main([str(bag)]) == 0
    assert 'VRC score' not in capsys.readouterr().out
