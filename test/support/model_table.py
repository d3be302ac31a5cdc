"""tools/make_atlas_mjcf.py as a module: the table of figures the MJCF and URDF are made from."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path
from types import ModuleType

GENERATOR = Path(__file__).resolve().parents[2] / 'tools' / 'make_atlas_mjcf.py'


def load_script(path: Path) -> ModuleType:
    """Import the script at `path` once, as a module named after its file (tools/ holds
    scripts, not package modules)."""
    name = path.stem
    if name not in sys.modules:
        spec = importlib.util.spec_from_file_location(name, path)
        module = importlib.util.module_from_spec(spec)
        sys.modules[name] = module
        spec.loader.exec_module(module)
    return sys.modules[name]


def load_table() -> ModuleType:
    """Import the generator once (it is a script, not a package module)."""
    return load_script(GENERATOR)
