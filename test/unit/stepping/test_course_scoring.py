"""The VRC course's scoring in the tick: Atlas teleported through gate_0 and gate_1 on the
simulator scores 1, in score.log and on /vrc_score, the same on every run."""

from __future__ import annotations

from pathlib import Path

import pytest

from tutorial_atlas_control import topics
from tutorial_atlas_control.course import ScoreRow
from tutorial_atlas_control.sim import model as atlas_model
from tutorial_atlas_control.sim.controller import load_gains_yaml
from tutorial_atlas_control.sim.controller_statistics import CommandAgeStatistics
from tutorial_atlas_control.sim.simulator import AtlasSimulator
from tutorial_atlas_control.sim.vrc import pose_input
from tutorial_atlas_control.stepping.loop import LoopSettings, SteppingLoop
from tutorial_atlas_control.stepping.outputs import LoopOutputs

REPO = Path(__file__).resolve().parents[3]
CONFIG = REPO / 'config' / 'atlas_controller.yaml'
#: (step, pelvis x, y): before and after gate_0 (x 1, y -38, yaw 0), then gate_1 (0, -22,
#: yaw 90°), each a Pose() with the all-zero quaternion, as DRCSim's checks sent them.
TELEPORTS = {500: (0.7, -38.0), 600: (1.3, -38.0), 800: (0.0, -22.3), 900: (0.0, -21.7)}
STEPS = 2000


class NoOutbox:
    def wanted(self, _outlet: object) -> bool:
        return False

    def add(self, _outlet: object, _data: bytes) -> None: ...

    def replace(self, _outlet: object, _data: bytes) -> None: ...

    def flush(self) -> None: ...


class QuietLog:
    def __getattr__(self, _name: str) -> object:
        return lambda *_args: None


def scored_run(score_dir: Path, teleports: dict[int, tuple[float, ...]] = TELEPORTS,
               steps: int = STEPS) -> list[ScoreRow]:
    """The loop's ticks with the scoring on, the teleports (x, y, and z or 1 m) applied
    between steps."""
    sim = AtlasSimulator(atlas_model.load_model(), load_gains_yaml(CONFIG))
    rows: list[ScoreRow] = []
    outlets = {topic.name: topic.name for topic in topics.INTERFACE if topic.delivery.loop}
    outputs = LoopOutputs(NoOutbox(), outlets, QuietLog(), lambda _json: None,
                          publish_score=rows.append)
    loop = SteppingLoop(sim, outputs, LoopSettings(score_dir=score_dir),
                        CommandAgeStatistics(sim.dt_s))
    for step in range(steps):
        if step in teleports:
            x_m, y_m, *z_m = teleports[step]
            sim.apply_input(pose_input((x_m, y_m, *(z_m or [1.0])), (0.0, 0.0, 0.0, 0.0)))
        assert loop.tick()
    loop.scoring.close()
    return rows


def test_teleports_through_gate_0_and_gate_1_score_1(tmp_path: Path) -> None:
    rows = scored_run(tmp_path / 'vrc_task_2')
    events = [(row.sim_time_ns, row.message) for row in rows if row.message]
    # The step after each teleport sees the new pose (poses at the step's start).
    assert events == [(601_000_000, 'Successfully passed through gate 1. Starting clock. '),
                      (901_000_000, 'Successfully passed through gate 2. ')]
    last = rows[-1]
    assert (last.completion, last.falls, last.sim_time_ns) == (1, 0, 1_901_000_000)
    assert last.sim_since_gate0_ns == 1_300_000_000  # the clock runs on to gate_4
    log = (tmp_path / 'vrc_task_2' / 'score.log').read_text().splitlines()
    assert log[0] == '# Score data for world vrc_task_2'
    assert [line.split(',', 1)[1] for line in log[4:]] == [
        row.log_line().rstrip('\n').split(',', 1)[1] for row in rows]


def test_a_dropped_robot_counts_one_fall(tmp_path: Path) -> None:
    """Dropped from 5 m (pelvis) once the first 15 s are over: the head's landing exceeds
    1000 m/s² over a step (2300 here), once; the steps after it are within the lockout."""
    rows = scored_run(tmp_path, {16_000: (0.0, 0.0, 5.0)}, 19_500)
    falls = [row for row in rows if 'fall' in row.message]
    assert len(falls) == 1 and rows[-1].falls == 1
    accel = float(falls[0].message.split(': ')[1].split(' ')[0])
    assert accel > 1000.0 and falls[0].message.endswith(' m/s^2. ')
    assert 17 * 10**9 < falls[0].sim_time_ns < 19 * 10**9  # on landing, not at the teleport


def test_two_runs_score_the_same(tmp_path: Path) -> None:
    def scores(rows: list[ScoreRow]) -> list[tuple[int, int, int, int, str]]:
        return [(r.sim_time_ns, r.sim_since_gate0_ns, r.completion, r.falls, r.message)
                for r in rows]

    assert scores(scored_run(tmp_path / 'a')) == scores(scored_run(tmp_path / 'b'))


def test_the_scored_node_publishes_vrc_score_latched(tmp_path: Path) -> None:
    pytest.importorskip('tutorial_atlas_control.node.sim_node',
                        reason='needs the catkin workspace: source ./env.sh')
    from support.fake_rospy import fake_ros_node

    sim = AtlasSimulator(atlas_model.load_model(), load_gains_yaml(CONFIG))
    with fake_ros_node(sim, 0, score_dir=tmp_path) as node:
        for _ in range(1000):
            assert node.loop.tick()
        publisher = node.fake_publishers[topics.VRC_SCORE]
    assert publisher.advertised == ('atlas_msgs/VRCScore', True)
    (message,) = publisher.published
    assert (message.sim_time.secs, message.sim_time.nsecs) == (1, 0)
    assert (message.completion_score, message.falls, message.message,
            message.task_type) == (0, 0, '', message.TASK_WALKING)
    assert (tmp_path / 'score.log').read_text().count('\n') == 5
