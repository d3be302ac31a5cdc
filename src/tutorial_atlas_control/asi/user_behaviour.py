"""A user's own behaviour: a Python class named by a launch argument, loaded into the library.

The argument is `module:Class` (a module on the Python path) or `path/to/file.py:Class`. The
class is called with the AtlasModel and must give a library behaviour (library.py's
contract; `BehaviourBase` has its quiet defaults) answering one of USER_BEHAVIORS, in that
behaviour's control mode. It then runs in the simulator's tick like the library's own, so
offline runs play it in lockstep and replays of its runs are exact (they replay the recorded
torques). Anything wrong with the argument or the class is one line, a UserBehaviourError.
"""

from __future__ import annotations

import importlib
import importlib.util
import sys
from pathlib import Path

from tutorial_atlas_control.asi.behaviors import MODE_OF_BEHAVIOR, Behavior
from tutorial_atlas_control.asi.library import LibraryBehaviour
from tutorial_atlas_control.control_modes import ControlMode
from tutorial_atlas_control.errors import AtlasControlError
from tutorial_atlas_control.sim import AtlasModel

__all__ = ['USER_BEHAVIORS', 'UserBehaviourError', 'load_user_behaviour']

#: The behaviours a user's own can answer, each in its control mode: Stand (then Manipulate,
#: the library's Stand with its pelvis servoed, is not served), Walk and Step.
USER_BEHAVIORS: dict[Behavior, ControlMode] = {
    Behavior.STAND: MODE_OF_BEHAVIOR[Behavior.STAND],
    Behavior.WALK: ControlMode.WALK,
    Behavior.STEP: ControlMode.STEP,
}
_MEMBERS = ('start', 'torque', 'refusal', 'prepare', 'take', 'stop', 'handover', 'feedback')


class UserBehaviourError(AtlasControlError, ValueError):
    """The behaviour argument names no loadable class, or the class breaks the contract."""


def _module_of(source: str, spec: str) -> object:
    """The module `source` names: a .py file or an importable module."""
    if source.endswith('.py'):
        path = Path(source).expanduser()
        if not path.is_file():
            raise UserBehaviourError(f'behaviour {spec!r}: no file {path}')
        name = f'tac_user_behaviour_{path.stem}'
        loader_spec = importlib.util.spec_from_file_location(name, path)
        if loader_spec is None or loader_spec.loader is None:
            raise UserBehaviourError(f'behaviour {spec!r}: {path} is not a Python module')
        module = importlib.util.module_from_spec(loader_spec)
        sys.modules[name] = module
        try:
            loader_spec.loader.exec_module(module)
        except Exception as err:  # the user's code: one line, whatever it raised
            raise UserBehaviourError(f'behaviour {spec!r}: {path} failed to load: '
                                     f'{type(err).__name__}: {err}') from err
        return module
    try:
        return importlib.import_module(source)
    except ImportError as err:
        raise UserBehaviourError(f'behaviour {spec!r}: {err}') from err


def load_user_behaviour(spec: str, atlas: AtlasModel) -> LibraryBehaviour:
    """The behaviour `spec` (`module:Class` or `file.py:Class`) names, made for `atlas`."""
    source, colon, class_name = spec.rpartition(':')
    if not colon or not source or not class_name.isidentifier():
        raise UserBehaviourError(f'behaviour {spec!r}: expected module:Class or '
                                 'path/to/file.py:Class')
    module = _module_of(source, spec)
    cls = getattr(module, class_name, None)
    if not isinstance(cls, type):
        raise UserBehaviourError(f'behaviour {spec!r}: {source} has no class {class_name}')
    try:
        behaviour = cls(atlas)
    except Exception as err:  # the user's constructor
        raise UserBehaviourError(f'behaviour {spec!r}: {class_name}(atlas) failed: '
                                 f'{type(err).__name__}: {err}') from err
    missing = [name for name in ('behavior', 'mode', *_MEMBERS)
               if not hasattr(behaviour, name)]
    if missing:
        raise UserBehaviourError(f'behaviour {spec!r}: {class_name} lacks '
                                 f'{", ".join(missing)} (see asi.BehaviourBase)')
    try:
        behavior = Behavior(behaviour.behavior)
    except ValueError:
        behavior = None
    if behavior not in USER_BEHAVIORS:
        names = ', '.join(b.name for b in USER_BEHAVIORS)
        raise UserBehaviourError(f'behaviour {spec!r}: {class_name}.behavior is '
                                 f'{behaviour.behavior!r}, not one of {names}')
    if behaviour.mode is not USER_BEHAVIORS[behavior]:
        raise UserBehaviourError(f'behaviour {spec!r}: {class_name}.mode must be '
                                 f'{USER_BEHAVIORS[behavior]!r} for {behavior.name}')
    return behaviour
