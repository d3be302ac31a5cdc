"""A walk on the VRC Task 2 course, analysed: an offline session from the pen's start (the
course's model, a one-shot WALK of four 0.25 m steps) read by analyze_bag.py, whose walk
summary and course map find the steps on the course's ground (z 0.03), not above z 0."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import matplotlib.image
import numpy as np
import pytest
from matplotlib.colors import to_rgb

from tutorial_atlas_control.asi import Behavior
from tutorial_atlas_control.bags import (
    footprints,
    plot_course_map,
    read_bag,
    read_course_run,
    read_scores,
    summarise_walk,
    terrain_heights,
)
from tutorial_atlas_control.bags.course_map import FOOT_COLOURS, map_pixel
from tutorial_atlas_control.msgs.atlas_sim_interface import (
    AsiCommand,
    ManipulateParams,
    StepData,
    encode_asi_command,
)
from tutorial_atlas_control.offline.asi_playback import AsiStream, write_asi_bag
from tutorial_atlas_control.offline.world import named_world
from tutorial_atlas_control.sim import VrcMode
from tutorial_atlas_control.units import NS_PER_S
from tutorial_atlas_control.walking import straight_steps

pytestmark = pytest.mark.offline

ANALYZE = Path(__file__).resolve().parents[2] / 'scripts' / 'analyze_bag.py'
WORLD = named_world('vrc_task_2')
#: The WALK is sent at 3 s of sim time (the Stand balances from 2 s); the session's end.
WALK_AT_S = 3.0
SESSION_S = 8.0


def _walk_bytes(stamp_ns: int, behavior: int) -> bytes:
    """Four 0.25 m steps east from the start, on the course's ground."""
    start = WORLD.start
    assert start is not None
    queue = tuple(StepData(s.step_index, s.foot_index, s.duration_s,
                           (s.x_m + start.x_m, s.y_m + start.y_m, 0.03), (0.0, 0.0, 0.0, 1.0),
                           0.0) for s in straight_steps(4, 0.25, width_m=0.24))
    return encode_asi_command(AsiCommand(stamp_ns, behavior, queue, False, StepData(), False,
                                         ManipulateParams(), None, 0))


@pytest.fixture(scope='module')
def course_walk(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The session's bag (about 18 s of wall time at load 5)."""
    bag = tmp_path_factory.mktemp('course_walk') / 'walk.bag'
    at_ns = int(WALK_AT_S * NS_PER_S)
    commands = [(at_ns, _walk_bytes(at_ns, Behavior.STAND)),
                (at_ns, _walk_bytes(at_ns, Behavior.WALK))]
    stream = AsiStream(Path('recorded.bag'), VrcMode.BDI_STAND, commands,
                       int(SESSION_S * NS_PER_S), WORLD)
    assert write_asi_bag(stream, bag, settle_s=0.0).commands == 1
    return bag


def test_the_walk_s_steps_are_found_on_the_course_s_ground(course_walk: Path,
                                                           tmp_path: Path) -> None:
    plot = tmp_path / 'walk.png'
    result = subprocess.run([sys.executable, str(ANALYZE), str(course_walk), '--plot',
                             str(plot)], capture_output=True, text=True, timeout=300,
                            check=False)
    assert result.returncode == 0, result.stderr
    lines = result.stdout.splitlines()
    assert any(line.startswith('walk: 4 of 4 steps taken; walked ') for line in lines), lines
    assert any(line.startswith('walk: no fall') for line in lines), lines
    assert f'wrote {tmp_path / "walk.course.png"}' in result.stderr


def test_the_course_map_draws_the_landings(course_walk: Path, tmp_path: Path) -> None:
    """The walk's landings (after WALK_AT_S; the earlier ones are the release's) lie on the
    steps asked for, and each foot's colour shows at the last landing's place."""
    data = read_bag(course_walk)
    run = read_course_run(data, read_scores(data), None)
    assert run is not None and run.falls == []
    walked = [landing for landing in run.landings if landing.t_s > WALK_AT_S]
    start = WORLD.start
    assert start is not None
    ahead = sorted(landing.x_m - start.x_m for landing in walked)
    assert len(walked) == 4, walked
    # The last two steps asked for put both feet 0.75 m ahead (the landings' worst is 5 cm).
    assert ahead[-2:] == pytest.approx([0.75, 0.75], abs=0.06), ahead
    image = matplotlib.image.imread(plot_course_map(run, tmp_path / 'map.png'))[..., :3] * 255
    for foot in (0, 1):
        last = [landing for landing in walked if landing.foot_index == foot][-1]
        sole_centre = (last.x_m + 0.05 * np.cos(last.yaw_rad), last.y_m)
        column, row = map_pixel(*sole_centre)
        drawn = np.array(to_rgb(FOOT_COLOURS[foot])) * 255.0
        assert np.abs(image[row, column] - drawn).max() <= 40, (foot, image[row, column])


def test_the_walk_summary_takes_the_pelvis_over_the_course_s_ground(
        course_walk: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The lowest pelvis (and so a fall) is taken over the terrain under it: in the mud pit,
    0.6 m down, a walking pelvis at z 0.26 m is no fall (a live course demo's summary said
    FELL there). The same walk over ground raised 0.5 m has fallen."""
    data = read_bag(course_walk)
    walked = summarise_walk(data)
    assert walked is not None and not walked.fell
    assert 0.75 < walked.lowest_pelvis_m < 0.95
    raised = terrain_heights() + 0.5
    monkeypatch.setattr(footprints, 'terrain_heights', lambda: raised)
    sunk = summarise_walk(data)
    assert sunk is not None and sunk.fell
    assert sunk.lowest_pelvis_m == pytest.approx(walked.lowest_pelvis_m - 0.5, abs=1e-9)
