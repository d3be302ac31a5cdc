"""Wall time of the search that found Stepping.yaml's step_and_stand, run again.

The arguments are the ones Stepping.yaml's header gives; search.py runs on its default local
cluster (one worker per core) and the wall time includes starting it, as a user's run does.
A whole run also says whether it found the same step and gains again (the runs are
deterministic on one machine; another CPU may round differently and find another).
"""

from __future__ import annotations

import json
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

from harness import REPO_DIR

from tutorial_atlas_control.search.cmaes import runs_per_candidate

SEARCH = REPO_DIR / 'scripts' / 'search.py'
STEPPING = REPO_DIR / 'trajectories' / 'Stepping.yaml'
STEPPING_GAINS = REPO_DIR / 'config' / 'stepping_gains.yaml'
#: The search's own generations (Stepping.yaml): what a whole run plays. The default bench
#: plays a few of them (run_bench.BUDGETS): the speed, not the step found.
GENERATIONS = 25
ARGUMENTS = (
    str(REPO_DIR / 'trajectories' / 'QuickStep.yaml'), 'quick_step',
    '--gains', str(REPO_DIR / 'config' / 'quickstep_gains.yaml'),
    '--objective', 'step_forward:dx=0.2,stand=5,z=0.8',
    '--vary', '0+1:l_leg_lax+r_leg_lax-l_leg_mhx-r_leg_mhx', '--vary', '2:r_leg_mhx',
    '--vary', '2:r_leg_lhy', '--vary', '2:r_leg_kny', '--vary', '3:r_leg_lhy',
    '--vary', '3:r_leg_kny', '--vary', '4:r_leg_lhy', '--vary', '2+3+4:l_leg_uay',
    '--vary-duration', '2', '--vary-duration', '3', '--vary-duration', '4',
    '--vary-gain', 'l_leg_mhx+r_leg_mhx', '--vary-gain', 'l_leg_lax+r_leg_lax',
    '--robust', '0.9:1', '1.1:1', '1:0.9', '1:1.1', '--latency-ms', '0:20',
    '--latency-draws', '4', '--popsize', '8', '--seed', '0', '--as', 'step_and_stand')


@dataclass(frozen=True)
class SearchTime:
    wall_s: float
    runs: int
    generations: int
    #: Whole runs only: the written step and gains are the committed ones (None: not judged).
    reproduced: bool | None


def _data_lines(path: Path) -> list[str]:
    """A YAML file's lines without comments: what a run plays."""
    return [line for line in path.read_text().splitlines() if not line.lstrip().startswith('#')]


def _smoke_arguments(arguments: list[str], popsize: int) -> list[str]:
    """ARGUMENTS for a smoke test: population `popsize`, one robustness variant and one
    late-command draw (3 runs a candidate instead of 9; each option is still used)."""
    arguments = list(arguments)
    arguments[arguments.index('--popsize') + 1] = str(popsize)
    arguments[arguments.index('--latency-draws') + 1] = '1'
    robust = arguments.index('--robust')
    end = robust + 1
    while end < len(arguments) and not arguments[end].startswith('--'):
        end += 1
    return arguments[:robust + 2] + arguments[end:]


def search_time(out_dir: Path, generations: int | None,
                popsize: int | None = None) -> SearchTime:
    """Run the search for `generations` (None: the whole search, GENERATIONS, which is
    then judged on the step it writes) and time it; `popsize` (a smoke test's) replaces
    the search's own population of 8 in a partial run, which then also tries one
    robustness variant and one late-command draw a candidate."""
    whole = generations is None
    arguments = list(ARGUMENTS)
    if popsize is not None and not whole:
        arguments = _smoke_arguments(arguments, popsize)
    if generations is None:
        generations = GENERATIONS
    log, found, gains = out_dir / 'search.jsonl', out_dir / 'found.yaml', out_dir / 'gains.yaml'
    for path in (log, found, gains):
        path.unlink(missing_ok=True)
    command = [sys.executable, str(SEARCH), *arguments, '--generations', str(generations),
               '--log', str(log), '--yaml', str(found), '--gains-out', str(gains)]
    started = time.perf_counter()
    result = subprocess.run(command, capture_output=True, text=True, check=False)
    wall_s = time.perf_counter() - started
    if result.returncode != 0:
        raise RuntimeError(f'search.py exited {result.returncode}: {result.stderr.strip()}')
    records = [json.loads(line) for line in log.read_text().splitlines()]
    header = next(r for r in records if r['kind'] == 'search')
    candidates = 1 + sum(len(r['x']) for r in records if r['kind'] == 'generation')
    done = sum(r['kind'] == 'generation' for r in records)
    reproduced = None
    if whole:
        stepping = _data_lines(STEPPING)
        start = stepping.index('step_and_stand:')
        reproduced = (_data_lines(found) == stepping[start:start + len(_data_lines(found))]
                      and _data_lines(gains) == _data_lines(STEPPING_GAINS))
    return SearchTime(wall_s, candidates * runs_per_candidate(header['config']), done,
                      reproduced)
