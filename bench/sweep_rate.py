"""Offline runs per second through sweep.py's Dask engine, on 1 and on 2 local workers."""

from __future__ import annotations

import time

from harness import REPO_DIR

from tutorial_atlas_control.search.sweep import SweepEngine, SweepInputs, build_specs

TRAJECTORIES = REPO_DIR / 'trajectories' / 'Traj_data2.yaml'
GAINS_YAML = REPO_DIR / 'config' / 'atlas_controller.yaml'


def runs_per_s(workers: int, runs: int, settle_s: float = 0.5) -> float:
    """Offline touchdown runs (6 s of trajectory + `settle_s`) per wall second on `workers`
    local workers. The cluster is started and warmed (one run per worker) before timing."""
    specs = build_specs(SweepInputs([(str(TRAJECTORIES), 'touchdown')], [str(GAINS_YAML)],
                                    time_scales=[1.0] * runs, settle_s=settle_s))
    with SweepEngine(workers) as engine:
        engine.run(specs[:workers], progress=False)
        started = time.perf_counter()
        outcome = engine.run(specs, progress=False)
        elapsed_s = time.perf_counter() - started
    if len(outcome.rows) != runs:
        raise RuntimeError(f'sweep returned {len(outcome.rows)} of {runs} runs')
    return runs / elapsed_s
