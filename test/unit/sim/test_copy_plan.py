"""CopyPlan's compiled copies (src/atlas_gather.c) equal numpy's bit for bit."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from tutorial_atlas_control import native
from tutorial_atlas_control.sim.copy_plan import CopyPlan


def test_copy_plan_equals_numpy_copies_into_unaligned_bytes(library) -> None:
    """The compiled copies write what numpy's `dst[to] = src[from]` writes, bit for bit,
    into float blocks at odd byte offsets (as in a serialized message)."""
    rng = np.random.default_rng(7)
    src = rng.standard_normal(40)
    src[[3, 5]] = (np.nan, -0.0)
    to, source = np.array([4, 0, 2, 9]), np.array([3, 5, 39, 0])
    results = []
    for compiled in (True, False):
        buf = bytearray(3 + 8 * 10)
        dst = np.frombuffer(buf, dtype='<f8', offset=3, count=10)
        plan = CopyPlan([(dst, to, src, source), (dst[5:8], [0, 1, 2], src, [6, 7, 8])],
                        compiled=compiled)
        assert (plan._call is not None) == compiled
        plan()
        results.append(bytes(buf))
    assert results[0] == results[1]
    copied = np.frombuffer(results[0], dtype='<f8', offset=3, count=10)
    assert copied[0] == 0.0 and np.signbit(copied[0]) and np.isnan(copied[4])
    assert copied[9] == src[0] and list(copied[5:8]) == list(src[6:9])


@pytest.mark.parametrize('copy, problem', [
    ((np.zeros(3), [0, 1], np.zeros(3), [0]), 'a copy of 1 values to 2 places'),
    ((np.zeros(3), [0, 3], np.zeros(3), [0, 1]), 'dst index outside 0..2'),
    ((np.zeros(3), [0, 1], np.zeros(2), [0, -1]), 'src index outside 0..1'),
])
def test_copy_plan_refuses_bad_indices(copy, problem) -> None:
    with pytest.raises(ValueError, match=problem):
        CopyPlan([copy])


def test_copy_plan_without_the_library_copies_with_numpy(
        monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    monkeypatch.setenv(native.LIBRARY_ENV, str(tmp_path / 'missing.so'))
    monkeypatch.setattr(native, '_library', None)
    monkeypatch.setattr(native, '_warned', False)
    src, dst = np.arange(5.0), np.zeros(3)
    with pytest.warns(RuntimeWarning, match=r'missing\.so does not exist; using the numpy'):
        plan = CopyPlan([(dst, [0, 1, 2], src, [4, 0, 2])])
    assert plan._call is None
    plan()
    assert list(dst) == [4.0, 0.0, 2.0]
