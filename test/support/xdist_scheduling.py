"""make test's xdist scheduling: one test module per worker, as `--dist loadscope` does, and a
few modules together where they share a session fixture.

A module- or session-scoped fixture (a launch, the demo's live run) is set up once per worker
that runs a test needing it: under plain `--dist load` a module's tests spread over both
workers and its launch started twice. `--dist loadgroup` and its `xdist_group` mark would
group them, but pytest-xdist 3.8 names a group by rewriting `item._nodeid`, which pytest 9.2
no longer reads (Node.nodeid comes from `_id`): its groups are silently ignored.
"""

from __future__ import annotations

from xdist.scheduler import LoadScopeScheduling

#: Modules run on one worker, by the group they share: the demo_run session fixture
#: (test/integration/conftest.py) is one live `run_demo.py` run that each uses.
SHARED_FIXTURE_GROUPS = {
    'test/integration/test_recorded_run.py': 'demo_run',
    'test/integration/test_replay_live.py': 'demo_run',
    'test/integration/test_offline_vs_live.py': 'demo_run',
}


def scope_of(nodeid: str) -> str:
    """The unit of work a test belongs to: its module, or its module's shared group."""
    module = nodeid.split('::', 1)[0]
    return SHARED_FIXTURE_GROUPS.get(module, module)


class ModuleScheduling(LoadScopeScheduling):
    """LoadScopeScheduling by scope_of: whole modules (or groups) to a worker, in turn."""

    def _split_scope(self, nodeid: str) -> str:
        return scope_of(nodeid)
