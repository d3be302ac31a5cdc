"""A user's behaviour named by `module:Class` or `file.py:Class`: loaded and checked against
the library's contract, every mistake one line naming the argument and what is wrong."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from tutorial_atlas_control.asi import Behavior, UserBehaviourError, load_user_behaviour
from tutorial_atlas_control.control_modes import ControlMode
from tutorial_atlas_control.sim import load_model

EXAMPLE = Path(__file__).resolve().parents[3] / 'examples' / 'arm_wave.py'


@pytest.fixture(scope='module')
def atlas():
    return load_model()


def _write(tmp_path: Path, body: str) -> str:
    path = tmp_path / 'mine.py'
    path.write_text('from tutorial_atlas_control.asi import Behavior, BehaviourBase\n'
                    'from tutorial_atlas_control.control_modes import ControlMode\n' + body)
    return str(path)


def test_the_example_loads_by_file_as_the_users_stand(atlas) -> None:
    behaviour = load_user_behaviour(f'{EXAMPLE}:ArmWave', atlas)
    assert (behaviour.behavior, behaviour.mode) == (Behavior.STAND, ControlMode.STAND)


def test_a_module_on_the_path_is_found_by_name(atlas) -> None:
    """Found by import (BehaviourBase itself takes no model: its call is refused)."""
    with pytest.raises(UserBehaviourError, match=re.escape(
            "behaviour 'tutorial_atlas_control.asi.library:BehaviourBase': "
            'BehaviourBase(atlas) failed: TypeError')):
        load_user_behaviour('tutorial_atlas_control.asi.library:BehaviourBase', atlas)


@pytest.mark.parametrize(('body', 'message'), [
    ('', '{path} has no class Mine'),
    ('class Mine:\n    def __init__(self, atlas): pass\n',
     'Mine lacks behavior, mode, start, torque, refusal, prepare, take, stop, handover, '
     'feedback (see asi.BehaviourBase)'),
    ('class Mine(BehaviourBase):\n    behavior = Behavior.FREEZE\n    mode = ControlMode.FREEZE\n'
     '    def __init__(self, atlas): pass\n',
     'Mine.behavior is <Behavior.FREEZE: 2>, not one of STAND, WALK, STEP'),
    ('class Mine(BehaviourBase):\n    behavior = Behavior.WALK\n    mode = ControlMode.STAND\n'
     '    def __init__(self, atlas): pass\n',
     "Mine.mode must be <ControlMode.WALK: 'Walk'> for WALK"),
    ('class Mine(BehaviourBase):\n    def __init__(self, atlas): raise RuntimeError("no")\n',
     'Mine(atlas) failed: RuntimeError: no'),
    ('raise ImportError("broken")\n', '{path} failed to load: ImportError: broken'),
])
def test_a_bad_class_is_one_line_naming_what_is_wrong(atlas, tmp_path: Path, body: str,
                                                      message: str) -> None:
    path = _write(tmp_path, body)
    spec = f'{path}:Mine'
    with pytest.raises(UserBehaviourError) as raised:
        load_user_behaviour(spec, atlas)
    assert str(raised.value) == f'behaviour {spec!r}: {message.format(path=path)}'


@pytest.mark.parametrize(('spec', 'message'), [
    ('arm_wave.py', 'expected module:Class or path/to/file.py:Class'),
    ('/no/such/file.py:ArmWave', 'no file /no/such/file.py'),
    ('no_such_module_here:ArmWave', "No module named 'no_such_module_here'"),
])
def test_a_bad_argument_is_one_line(atlas, spec: str, message: str) -> None:
    with pytest.raises(UserBehaviourError) as raised:
        load_user_behaviour(spec, atlas)
    assert str(raised.value) == f'behaviour {spec!r}: {message}'
