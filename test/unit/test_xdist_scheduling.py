"""make test's scheduling (support/xdist_scheduling.py): whole modules per worker, and the
modules sharing a session fixture as one unit, each named module real and using it."""

from __future__ import annotations

from pathlib import Path

from support.xdist_scheduling import SHARED_FIXTURE_GROUPS, scope_of, work_order

REPO = Path(__file__).resolve().parents[2]


def test_a_test_s_scope_is_its_module() -> None:
    assert scope_of('test/unit/sim/test_model.py::test_mass[back]') == 'test/unit/sim/test_model.py'
    assert scope_of('test/unit/a.py::Class::test_x') == 'test/unit/a.py'


def test_the_demo_s_users_share_one_scope() -> None:
    assert {scope_of(f'{module}::test_x') for module in SHARED_FIXTURE_GROUPS} == {'demo_run'}


def test_every_grouped_module_exists_and_uses_its_fixture() -> None:
    """A renamed module would silently leave its group (and run the demo once more)."""
    for module, fixture in SHARED_FIXTURE_GROUPS.items():
        assert fixture in (REPO / module).read_text(), module


def test_the_offline_runs_modules_go_out_before_the_unit_tests() -> None:
    """Few tests but long ones first; xdist's order (most tests first) within each part. By
    test count alone test_walk_circle_seeds (1 test, about 30 CPU s) went out last."""
    scopes = {'test/unit/sim/test_model.py': 300, 'test/integration/test_walk_seeds.py': 5,
              'test/unit/test_docs.py': 40, 'test/integration/test_search.py': 15,
              'test/integration/test_walk_circle_seeds.py': 1}
    assert work_order(scopes) == [
        'test/integration/test_search.py', 'test/integration/test_walk_seeds.py',
        'test/integration/test_walk_circle_seeds.py', 'test/unit/sim/test_model.py',
        'test/unit/test_docs.py']
