"""The VRC Task 2 course map of a recorded run: which bags are course runs, the terrain under
a point, landings found on the terrain, and analyze_bag.py's PNG (its size, the gates and
the pelvis's path drawn where the course's figures put them)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from support.scored_runs import GATE_TELEPORTS, record_teleported_run
from support.synthetic_bags import Record, odometry, sim_config, write_bag, write_run_bag
from tutorial_atlas_control import topics
from tutorial_atlas_control.bags import analyze_bag, course_map, format_summary, read_bag
from tutorial_atlas_control.bags.course_map import (
    GATE_COLOUR,
    MAP_SIZE_PX,
    PATH_COLOUR,
    map_pixel,
    plot_course_map,
)
from tutorial_atlas_control.bags.course_run import read_course_run, terrain_landings
from tutorial_atlas_control.bags.course_terrain import (
    ground_under,
    is_course_run,
    terrain_heights,
)
from tutorial_atlas_control.bags.overview_plot import draw_overview
from tutorial_atlas_control.cli.analyze_bag import main
from tutorial_atlas_control.course import GATES
from tutorial_atlas_control.offline.world import named_world
from tutorial_atlas_control.sim import model as atlas_model
from tutorial_atlas_control.sim.controller import load_gains_yaml
from tutorial_atlas_control.sim.simulator import AtlasSimulator

CONFIG = Path(__file__).resolve().parents[3] / 'config' / 'atlas_controller.yaml'
#: (sim time s, pelvis x, y): from the pen through gate_0, then through gate_1.
TELEPORTS = GATE_TELEPORTS
#: A point on each gate's line, away from the posts, the labels and the path (m).
GATE_POINTS = ((1.0, -39.5), (1.6, -22.0), (-1.4, -10.5), (5.0, 6.5), (7.0, 18.0))
#: A colour channel may differ this much (0-255) from the colour drawn (antialiasing,
#: the PNG's rounding): drawn, 0 away; without the gates the terrain there is 138 away.
TOLERANCE = 40


@pytest.fixture(scope='module')
def course_bag(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """3 s of sim time in the course (its model, the pen's start, scored), the robot
    teleported through gate_0 and gate_1 (about 3 s of wall time), with the laser's scans."""
    directory = tmp_path_factory.mktemp('course')
    world = named_world('vrc_task_2')
    sim = AtlasSimulator(atlas_model.load_model(world.model_path), load_gains_yaml(CONFIG),
                         start=world.start)
    return record_teleported_run(sim, directory / 'course.bag', directory / 'vrc_task_2', 3.0,
                                 scans=True)


def _pixels(path: Path) -> np.ndarray:
    import matplotlib.image

    return np.rint(matplotlib.image.imread(path)[..., :3] * 255.0).astype(int)


def _colour(name: str) -> np.ndarray:
    from matplotlib.colors import to_rgb

    return np.rint(np.array(to_rgb(name)) * 255.0).astype(int)


def assert_gates_drawn(path: Path) -> None:
    """Each gate's line shows in the gates' colour at a point of it."""
    image = _pixels(path)
    for gate, (x_m, y_m) in zip(GATES, GATE_POINTS):
        column, row = map_pixel(x_m, y_m)
        found = image[row, column]
        assert np.abs(found - _colour(GATE_COLOUR)).max() <= TOLERANCE, (
            f'{gate.name} at ({x_m}, {y_m}): pixel ({column}, {row}) is {found.tolist()}')


def test_a_course_run_is_told_from_its_config_or_its_score(course_bag: Path,
                                                           tmp_path: Path) -> None:
    assert is_course_run(read_bag(course_bag))
    flat = write_run_bag(tmp_path / 'flat.bag', duration_s=0.5)
    assert not is_course_run(read_bag(flat))
    config = sim_config(0.0, 0.0)
    text = json.loads(config.message.data)
    text['model_file'] = 'vrc_task_2.xml'  # what the course's simulator names
    named = Record(topics.SIM_CONFIG, 'std_msgs/String', 0.0,
                   type(config.message)(data=json.dumps(text)))
    in_course = write_bag(tmp_path / 'named.bag', [named])
    assert is_course_run(read_bag(in_course))


def test_the_ground_under_a_point_is_the_heightmaps() -> None:
    heights = terrain_heights()
    pen, pit = ground_under(heights, np.array([-3.0, 0.5]), np.array([-38.0, -16.6]))
    assert pen == pytest.approx(0.03, abs=0.01)  # the course's flat ground
    assert pit == pytest.approx(-0.6, abs=0.005)  # the pit's floor


def test_a_foot_landing_in_the_pit_is_found_on_the_terrain() -> None:
    """A foot standing 1 s, then 0.4 s up, then down again 0.3 m on in the pit: one landing
    on its height above the terrain; none on its height above z 0."""
    standing_m, rate_hz = 0.08, 200.0
    t_s = np.arange(0.0, 3.0, 1 / rate_hz)
    x_m = np.where(t_s < 1.0, 0.2, np.where(t_s < 1.4, 0.2 + 0.3 * (t_s - 1.0) / 0.4, 0.5))
    lift = np.where((t_s >= 1.0) & (t_s < 1.4), 0.05, 0.0)
    position = np.column_stack([x_m, np.full_like(t_s, -16.6), -0.6 + standing_m + lift])
    yaw = np.zeros_like(t_s)
    found = terrain_landings(0, t_s, position, yaw, standing_m, terrain_heights())
    assert [(round(each.t_s, 2), round(each.x_m, 2)) for each in found] == [(1.4, 0.5)]
    from tutorial_atlas_control.bags.footprints import landings

    # Above z 0 the foot in the pit never leaves the ground: one stance, no landing.
    assert landings(0, t_s, position, yaw, standing_m) == []


def test_the_map_has_its_size_the_gates_and_the_path(course_bag: Path, tmp_path: Path,
                                                      capsys: pytest.CaptureFixture[str]
                                                      ) -> None:
    png = tmp_path / 'map.png'
    assert main([str(course_bag), '--course-map', str(png)]) == 0
    assert f'wrote {png}' in capsys.readouterr().err
    image = _pixels(png)
    assert (image.shape[1], image.shape[0]) == MAP_SIZE_PX
    assert_gates_drawn(png)
    column, row = map_pixel(-1.5, -38.0)  # the path from the start to the first teleport
    assert np.abs(image[row, column] - _colour(PATH_COLOUR)).max() <= TOLERANCE
    column, row = map_pixel(-6.0, 0.0)  # terrain only, away from everything drawn
    assert np.abs(image[row, column] - _colour(GATE_COLOUR)).max() > 3 * TOLERANCE
    # The robot, teleported onto the pit's ramp, falls there: within 0.5 m of the terrain.
    falls = read_course_run(read_bag(course_bag), None).falls
    assert [(fall.text, round(fall.y_m)) for fall in falls] == [('fell (pelvis low)', -21)]
    column, row = map_pixel(falls[0].x_m, falls[0].y_m)
    assert np.abs(image[row, column] - _colour('red')).max() <= TOLERANCE


def test_the_gates_check_fails_on_a_map_without_gates(course_bag: Path, tmp_path: Path,
                                                      monkeypatch: pytest.MonkeyPatch) -> None:
    run = read_course_run(read_bag(course_bag), None, [])
    monkeypatch.setattr(course_map, 'draw_gates', lambda ax: None)
    bad = plot_course_map(run, tmp_path / 'no_gates.png')
    with pytest.raises(AssertionError, match='gate_0'):
        assert_gates_drawn(bad)


def test_plot_writes_the_course_map_beside_and_refuses_it_off_the_course(
        course_bag: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main([str(course_bag), '--plot', str(tmp_path / 'run.png')]) == 0
    assert (tmp_path / 'run.course.png').is_file()
    flat = write_run_bag(tmp_path / 'flat.bag', duration_s=0.5)
    capsys.readouterr()
    assert main([str(flat), '--course-map', str(tmp_path / 'flat.png')]) == 1
    out, err = capsys.readouterr()
    assert out == '' and len(err.strip().splitlines()) == 1, (out, err)  # before the summary
    assert 'is not a VRC Task 2 run' in err
    assert not (tmp_path / 'flat.png').exists()


def _course_config(t_s: float) -> Record:
    config = sim_config(t_s, 0.0)
    text = json.loads(config.message.data)
    text['model_file'] = 'vrc_task_2.xml'
    return Record(topics.SIM_CONFIG, 'std_msgs/String', t_s,
                  type(config.message)(data=json.dumps(text)))


def test_standing_in_the_pit_is_no_fall_on_the_course_and_one_on_the_plane(
        tmp_path: Path) -> None:
    """The pelvis 0.85 m over the pit's floor (z 0.25) for 2 s, then 0.3 m over it: on the
    course the fall is found at the drop, its lowest over the terrain; the same path in a
    bag naming no course is fallen from the first sample (over z 0)."""
    path = [odometry(t_s, (0.85 if t_s < 2.0 else 0.3) - 0.6, x_m=0.5, y_m=-16.6)
            for t_s in np.arange(0.0, 3.0, 0.01)]
    course = analyze_bag(write_bag(tmp_path / 'pit.bag', [_course_config(0.0), *path]))
    assert course.over_terrain
    assert course.fell and course.fall_time_s == pytest.approx(2.0, abs=0.011)
    assert course.min_pelvis_height_m == pytest.approx(0.3, abs=0.005)
    assert 'pelvis below 0.5 m over the terrain' in format_summary(course)
    page = draw_overview(course, set())
    line = next(each for each in page.axes[0].lines
                if each.get_label() == 'pelvis over the terrain')
    assert line.get_ydata().min() == pytest.approx(0.3, abs=0.005)
    plane = analyze_bag(write_bag(tmp_path / 'plane.bag', [sim_config(0.0, 0.0), *path]))
    assert not plane.over_terrain
    assert plane.fell and plane.fall_time_s == pytest.approx(0.0, abs=0.011)


def test_scan_cloud_needs_the_course_map_and_scans(course_bag: Path, tmp_path: Path,
                                                   capsys: pytest.CaptureFixture[str]) -> None:
    """--scan-cloud draws on --course-map's map (the course run's scans, as recorded); a
    course bag without scans is one line before the summary, and no map."""
    with pytest.raises(SystemExit) as exit_info:
        main([str(course_bag), '--scan-cloud'])
    assert exit_info.value.code == 2
    png = tmp_path / 'cloud.png'
    assert main([str(course_bag), '--course-map', str(png), '--scan-cloud']) == 0
    assert png.is_file()
    bare = write_bag(tmp_path / 'no_scans.bag', [_course_config(0.0)] + [
        odometry(t_s, 0.3, x_m=-3.0, y_m=-38.0) for t_s in np.arange(0.0, 1.0, 0.01)])
    capsys.readouterr()
    assert main([str(bare), '--course-map', str(tmp_path / 'none.png'), '--scan-cloud']) == 1
    out, err = capsys.readouterr()
    assert out == '' and f'has no {topics.LASER_SCAN}' in err
    assert not (tmp_path / 'none.png').exists()


def test_laser_map_option_maps_the_scans_and_needs_them(course_bag: Path, tmp_path: Path,
                                                        capsys: pytest.CaptureFixture[str]
                                                        ) -> None:
    """--laser-map prints the run's scans as a height map at its WALK footsteps (this run
    teleports: none asked for); a bag without scans is one line, no summary."""
    capsys.readouterr()
    assert main([str(course_bag), '--laser-map']) == 0
    out, _ = capsys.readouterr()
    assert 'laser map: ' in out and '0 of 0 footsteps asked for on seen ground' in out
    bare = write_bag(tmp_path / 'no_scans.bag', [_course_config(0.0)] + [
        odometry(t_s, 0.3, x_m=-3.0, y_m=-38.0) for t_s in np.arange(0.0, 1.0, 0.01)])
    assert main([str(bare), '--laser-map']) == 1
    out, err = capsys.readouterr()
    assert out == '' and f'has no {topics.LASER_SCAN}' in err
