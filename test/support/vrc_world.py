"""tools/make_vrc_world.py as a module: the VRC Task 2 world's generator and its figures."""

from __future__ import annotations

from pathlib import Path
from types import ModuleType

from support.model_table import load_script, load_table

GENERATOR = Path(__file__).resolve().parents[2] / 'tools' / 'make_vrc_world.py'
WORLD_PATH = GENERATOR.parents[1] / 'sim' / 'vrc_task_2.xml'


def load_generator() -> ModuleType:
    """Import the generator once (a script, not a package module), on the tests' copy of
    tools/make_atlas_mjcf.py."""
    load_table()
    return load_script(GENERATOR)
