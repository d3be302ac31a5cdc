"""make test's xdist scheduling: one test module per worker, as `--dist loadscope` does, and a
few modules together where they share a session fixture.

A module- or session-scoped fixture (a launch, the demo's live run) is set up once per worker
that runs a test needing it: under plain `--dist load` a module's tests spread over both
workers and its launch started twice. `--dist loadgroup` and its `xdist_group` mark would
group them, but pytest-xdist 3.8 names a group by rewriting `item._nodeid`, which pytest 9.2
no longer reads (Node.nodeid comes from `_id`): its groups are silently ignored.
"""

from __future__ import annotations

from collections import OrderedDict
from typing import Any

from xdist.scheduler import LoadScopeScheduling
from xdist.workermanage import WorkerController

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


def work_order(scopes: dict[str, int]) -> list[str]:
    """The order the scopes (name: number of tests) are handed out: the integration and
    reliability modules first, then the unit tests', each part by number of tests, most first
    (xdist's own order). The few-test modules of offline runs are the longest units of
    `make test`'s offline part (a minute of CPU or more, in one or a few tests); by test count
    alone they came last, and one worker ran the last of them alone while the other had
    nothing left. The unit tests' many short modules now fill that end instead."""
    return sorted(scopes, key=lambda scope: (scope.startswith('test/unit/'), -scopes[scope]))


class ModuleScheduling(LoadScopeScheduling):
    """LoadScopeScheduling by scope_of: whole modules (or groups) to a worker, in
    work_order."""

    def __init__(self, config: Any, log: Any = None) -> None:
        super().__init__(config, log)
        self._ordered = False

    def _split_scope(self, nodeid: str) -> str:
        return scope_of(nodeid)

    def _assign_work_unit(self, node: WorkerController) -> None:
        """The first assignment finds the whole queue (schedule() fills it first): put it in
        work_order once."""
        if not self._ordered:
            self._ordered = True
            units = {scope: len(tests) for scope, tests in self.workqueue.items()}
            self.workqueue = OrderedDict((scope, self.workqueue[scope])
                                         for scope in work_order(units))
        super()._assign_work_unit(node)
