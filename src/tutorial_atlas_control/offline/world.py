"""The world an offline run simulates: its model file and where the robot starts.

`run_offline.py --world NAME` names one of DRCSim's VRC Task 2 worlds (the course's model,
that world's start); a replay or a played session takes the world its recorded run's
/atlas/sim_config names (the model file, when the package has it, and the start), so that a
run on the course is re-created on the course, where the live one stood.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from tutorial_atlas_control.course import (
    MUD_DAMPING,
    WORLD_MODEL_FILE,
    CourseError,
    Start,
    parse_start,
    world_start,
)
from tutorial_atlas_control.resources import package_path
from tutorial_atlas_control.sim import MODEL_PATH, SimConfig

__all__ = ['OfflineWorld', 'named_world', 'recorded_world']


@dataclass(frozen=True)
class OfflineWorld:
    """A model file, the start the simulator resets to (None: the model's spawn pose), and
    the mud's damping (N s/m) if the model has mud (sim.mud)."""

    model_path: Path = MODEL_PATH
    start: Start | None = None
    mud_damping: float = MUD_DAMPING


def named_world(name: str) -> OfflineWorld:
    """The VRC Task 2 world `name` (a key of course.STARTS): the course's model, its start.

    Raises:
        CourseError: an unknown world, or the course's model missing from the package.
    """
    start = world_start(name)
    model_path = package_path('sim', WORLD_MODEL_FILE)
    if not model_path.is_file():
        raise CourseError(f'world {name}: the course model {model_path} is missing from '
                          'the package')
    return OfflineWorld(model_path, start)


def recorded_world(config: SimConfig) -> OfflineWorld:
    """The world a recorded run's config names: its model file when the package's sim/
    holds one of that name (else the default model: replay's checksum check then says
    so), its start and its mud's damping.

    Raises:
        CourseError: the config's start is not a start.
    """
    model_path = MODEL_PATH
    if config.model_file and Path(config.model_file).name == config.model_file:
        candidate = package_path('sim', config.model_file)
        if candidate.suffix == '.xml' and candidate.is_file():
            model_path = candidate
    try:
        start = parse_start(config.start)
    except CourseError as err:
        raise CourseError(f'the recorded /atlas/sim_config: {err}') from None
    return OfflineWorld(model_path, start, MUD_DAMPING if config.mud_damping is None
                        else config.mud_damping)
