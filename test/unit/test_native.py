"""The loader of the compiled library refuses one whose structs differ from the mirrors."""

from __future__ import annotations

import ctypes
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from tutorial_atlas_control import native
from tutorial_atlas_control.sim import model as atlas_model
from tutorial_atlas_control.sim.controller import load_gains_yaml
from tutorial_atlas_control.sim.copy_plan import CopyPlan
from tutorial_atlas_control.sim.simulator import AtlasSimulator

REPO = Path(__file__).resolve().parents[2]
C_SOURCES = (REPO / 'src' / 'atlas_law.c', REPO / 'src' / 'atlas_gather.c',
             REPO / 'src' / 'atlas_estimator.c', REPO / 'src' / 'atlas_statics.h',
             REPO / 'src' / 'atlas_statics.c', REPO / 'src' / 'atlas_swing.h',
             REPO / 'src' / 'atlas_swing.c', REPO / 'src' / 'atlas_whole_body.h',
             REPO / 'src' / 'atlas_whole_body.c', REPO / 'src' / 'atlas_legs.h',
             REPO / 'src' / 'atlas_legs.c', REPO / 'src' / 'atlas_walk_swing.c',
             REPO / 'src' / 'atlas_heightfield.c')
CONFIG = REPO / 'config' / 'atlas_controller.yaml'
#: A C struct Python may lay out: `typedef struct { ... } Name;`.
C_TYPEDEF_STRUCT = re.compile(r'typedef struct \{.*?\} (\w+);', re.S)


@pytest.fixture()
def fresh_loader(monkeypatch: pytest.MonkeyPatch) -> None:
    """The loader as in a new process: nothing loaded, nothing warned yet."""
    monkeypatch.setattr(native, '_library', None)
    monkeypatch.setattr(native, '_warned', False)


def test_every_struct_of_the_c_sources_is_mirrored() -> None:
    c_structs = {name for source in C_SOURCES
                 for name in C_TYPEDEF_STRUCT.findall(source.read_text())}
    assert c_structs == set(native.MIRRORED_STRUCTS) == {'AtlasLawStep', 'AtlasCopy',
                                                         'AtlasEstimator', 'AtlasStatics',
                                                         'AtlasSwing', 'AtlasWholeBody',
                                                         'AtlasLegs', 'AtlasLegsSupport',
                                                         'AtlasWalkSwing', 'AtlasHeightfield'}
    for name, mirror in native.MIRRORED_STRUCTS.items():
        assert mirror.__name__ == name


def test_the_library_reports_the_mirrored_sizes() -> None:
    library = native.load_library()
    assert library is not None, f'{native.LIBRARY_NAME} not built: run `make setup`'
    for name, mirror in native.MIRRORED_STRUCTS.items():
        sizeof = getattr(library, f'tac_sizeof_{name}')
        sizeof.restype = ctypes.c_size_t
        assert sizeof() == ctypes.sizeof(mirror), name
    assert native.size_mismatches(library) == []


class _LongerCopy(ctypes.Structure):
    """AtlasCopy with one field too many: a mirror that no longer matches the C struct."""

    _fields_ = [*native.AtlasCopy._fields_, ('extra', ctypes.c_long)]


def test_a_library_whose_sizes_differ_is_refused_with_one_warning(
        monkeypatch: pytest.MonkeyPatch, fresh_loader: None) -> None:
    path = native.find_library()
    assert path is not None, f'{native.LIBRARY_NAME} not built: run `make setup`'
    monkeypatch.setitem(native.MIRRORED_STRUCTS, 'AtlasCopy', _LongerCopy)
    expected = (rf'^{re.escape(str(path))} does not match this code \(sizeof\(AtlasCopy\) is '
                rf'{ctypes.sizeof(native.AtlasCopy)} bytes there, {ctypes.sizeof(_LongerCopy)}'
                r' in tutorial_atlas_control.native\); rebuild it \(`make setup`\); '
                r"using the numpy controller law \(same torques, slower\), the laser's "
                r'numpy heightfield march, the Python swing-foot servo and the Python '
                r'balance estimator, statics and whole-body tick$')
    with pytest.warns(RuntimeWarning, match=expected) as caught:
        assert native.load_library() is None
        sim = AtlasSimulator(atlas_model.load_model(), load_gains_yaml(CONFIG))
        plan = CopyPlan([(np.zeros(2), [0, 1], np.ones(2), [1, 0])])
    assert len(caught) == 1
    assert not sim.uses_compiled_law and plan._call is None
    sim.step()
    assert np.isfinite(sim.torque_nm).all()


@pytest.mark.skipif(shutil.which('cc') is None, reason='needs a C compiler')
def test_a_library_without_size_functions_is_refused(
        monkeypatch: pytest.MonkeyPatch, tmp_path: Path, fresh_loader: None) -> None:
    """A library built from sources older than the size check (here: the law alone)."""
    old = tmp_path / 'libold.so'
    subprocess.run(['cc', '-shared', '-fPIC', '-o', str(old), str(C_SOURCES[0]), '-lm'],
                   check=True)
    monkeypatch.setenv(native.LIBRARY_ENV, str(old))
    with pytest.warns(RuntimeWarning, match=rf'^{re.escape(str(old))} does not match this '
                                            r'code \(no tac_sizeof_AtlasCopy\(\); no '
                                            r'tac_sizeof_AtlasEstimator\(\); no '
                                            r'tac_sizeof_AtlasStatics\(\); no '
                                            r'tac_sizeof_AtlasSwing\(\); no '
                                            r'tac_sizeof_AtlasWholeBody\(\); no '
                                            r'tac_sizeof_AtlasLegs\(\); no '
                                            r'tac_sizeof_AtlasLegsSupport\(\); no '
                                            r'tac_sizeof_AtlasWalkSwing\(\); no '
                                            r'tac_sizeof_AtlasHeightfield\(\)\); rebuild'):
        assert native.load_library() is None


def test_address_refuses_arrays_the_library_would_misread() -> None:
    array = np.zeros(3)
    assert native.address(array, np.float64) == array.ctypes.data
    with pytest.raises(ValueError, match='C-contiguous float64 arrays, got float32'):
        native.address(np.zeros(3, dtype=np.float32), np.float64)
    with pytest.raises(ValueError, match=r'got float64 \(contiguous: False\)'):
        native.address(np.zeros(6)[::2], np.float64)
