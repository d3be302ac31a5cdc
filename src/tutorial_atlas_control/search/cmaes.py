"""CMA-ES (the `cma` package) over a trajectory's waypoints and gains, evaluated through sweep.

The search vector x starts at 0 (the starting trajectory, unchanged) and holds:
  * joint offsets (rad): `W:EXPR`, EXPR a signed sum of joints such as
    `l_leg_lax+r_leg_lax-l_leg_mhx-r_leg_mhx` (a term may carry a factor: `2*r_leg_kny`),
    added to waypoint W's positions (W a 0-based index, or `all`);
  * duration factors, exp(x), on waypoint W's duration;
  * gain factors, exp(x), on the p and d of a sum of joints (signs ignored).
Candidates are rounded as the written files hold them (POSITION_DECIMALS, DURATION_STEP_S,
GAIN_DIGITS), so the YAML written plays exactly what was evaluated.

The log is JSON lines: a header with the whole problem, then one line per generation
(candidates and costs). Resuming re-creates the strategy from the same seed and replays
the logged generations through ask/tell, so a resumed search continues exactly as the
uninterrupted one would have.
"""

from __future__ import annotations

import dataclasses
import json
import math
import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from tutorial_atlas_control.joints import JOINT_INDEX, JOINT_NAMES
from tutorial_atlas_control.search.objectives import Objective
from tutorial_atlas_control.search.runs import RunSpec, SweepError
from tutorial_atlas_control.search.sweep import SweepOutcome, atomic_write

if TYPE_CHECKING:
    import cma

__all__ = ['Parameter', 'SearchProblem', 'SearchResult', 'parse_parameter', 'run_search',
           'runs_per_candidate']

#: Written (and evaluated) precision: positions to 1e-4 rad, durations to 10 ms (at least
#: one 20 ms command period), gains to 4 significant digits.
POSITION_DECIMALS = 4
DURATION_STEP_S = 0.01
MIN_DURATION_S = 0.02
GAIN_DIGITS = 4
#: Initial step of each kind of coordinate: rad for joints, log-factor for durations and gains.
DEFAULT_STEP = {'joint': 0.05, 'duration': 0.2, 'gain': 0.3}
#: Seed of a candidate's first latency draw: every candidate meets the same draws (common
#: random numbers), so a difference in cost is the candidate's, not the draw's.
LATENCY_SEED = 1_000_000
_TERM = re.compile(r'([+-]?)(?:(\d+(?:\.\d*)?)\*)?([a-z_]+)')


@dataclass(frozen=True)
class Parameter:
    """One search coordinate: its kind, waypoints and joint weights."""

    kind: str                       # 'joint', 'duration' or 'gain'
    waypoints: tuple[int, ...]      # for joint and duration; () for gain
    weights: tuple[tuple[int, float], ...]  # (joint index, factor); () for duration
    text: str


def _joint_sum(expr: str, text: str) -> tuple[tuple[int, float], ...]:
    pos, terms = 0, []
    while pos < len(expr):
        match = _TERM.match(expr, pos)
        if match is None or (pos and not match.group(1)):
            raise SweepError(f'parameter {text!r}: {expr[pos:]!r} is not +JOINT, -JOINT or '
                             '+FACTOR*JOINT')
        sign, factor, joint = match.groups()
        if joint not in JOINT_INDEX:
            raise SweepError(f'parameter {text!r}: unknown joint {joint!r}')
        terms.append((JOINT_INDEX[joint], (-1.0 if sign == '-' else 1.0) * float(factor or 1)))
        pos = match.end()
    if not terms:
        raise SweepError(f'parameter {text!r}: no joint')
    return tuple(terms)


def _waypoints(spec: str, count: int, text: str) -> tuple[int, ...]:
    if spec == 'all':
        return tuple(range(count))
    try:
        indices = tuple(int(part) for part in spec.split('+'))
    except ValueError:
        raise SweepError(f'parameter {text!r}: waypoint {spec!r} is not an index or "all"'
                         ) from None
    for index in indices:
        if not 0 <= index < count:
            raise SweepError(f'parameter {text!r}: waypoint {index} does not exist '
                             f'(the trajectory has {count})')
    return indices


def parse_parameter(kind: str, text: str, waypoint_count: int) -> Parameter:
    """`W:EXPR` (joint), `W` (duration) or `EXPR` (gain).

    Raises:
        SweepError: the text names no existing waypoint or joint.
    """
    if kind == 'joint':
        where, sep, expr = text.partition(':')
        if not sep:
            raise SweepError(f'parameter {text!r} is not WAYPOINT:JOINTS')
        return Parameter(kind, _waypoints(where, waypoint_count, text), _joint_sum(expr, text),
                         text)
    if kind == 'duration':
        return Parameter(kind, _waypoints(text, waypoint_count, text), (), text)
    return Parameter(kind, (), _joint_sum(text, text), text)


def _round_gain(value: float) -> float:
    return float(f'{value:.{GAIN_DIGITS}g}')


def runs_per_candidate(config: dict[str, Any]) -> int:
    """Runs each candidate costs, from a search log's header config (SearchProblem.config):
    the nominal run, one per (gains, timing) variant, one per late-command draw."""
    return 1 + len(config['variants']) + config.get('latency', (0, 0, 0))[2]


@dataclass
class SearchProblem:
    """What is searched: the starting trajectory and gains, the coordinates, the objective."""

    base: RunSpec
    parameters: Sequence[Parameter]
    objective: Objective
    seed: int = 0
    popsize: int = 6
    generations: int = 10
    step_scale: float = 1.0
    #: (gain scale, time scale) each candidate is also played at; its cost is the mean over
    #: the nominal run and these (a search for a step that survives them).
    variants: Sequence[tuple[float, float]] = ()
    #: (lo ms, hi ms, draws): each candidate is also played `draws` times with each command
    #: delayed lo..hi ms (CommandLatency), as live delivery on a busy machine; (0, 0, 0) none.
    latency: tuple[int, int, int] = (0, 0, 0)

    def config(self) -> dict[str, Any]:
        """The problem as the log's header holds it (a resume must match it exactly)."""
        return {'trajectory': self.base.trajectory, 'name': self.base.name,
                'gains': self.base.gains_label,
                'waypoints': [[d, list(p)] for d, p in self.base.waypoints],
                'gain_table': [list(row) for row in self.base.gains],
                'parameters': [[p.kind, p.text] for p in self.parameters],
                'objective': self.objective.text(), 'seed': self.seed, 'popsize': self.popsize,
                'step_scale': self.step_scale, 'settle_s': self.base.settle_s,
                'variants': [list(v) for v in self.variants],
                **({'latency': list(self.latency)} if self.latency[2] else {})}

    def candidate(self, x: Sequence[float], index: int = 0) -> RunSpec:
        """The run of vector `x`, rounded as its files will hold it."""
        durations = [d for d, _ in self.base.waypoints]
        positions = [list(p) for _, p in self.base.waypoints]
        p, i, d, clamp = (list(row) for row in self.base.gains)
        for value, param in zip(x, self.parameters):
            if param.kind == 'joint':
                for w in param.waypoints:
                    for joint, factor in param.weights:
                        positions[w][joint] += factor * value
            elif param.kind == 'duration':
                for w in param.waypoints:
                    durations[w] *= math.exp(value)
            else:
                for joint, _ in param.weights:
                    p[joint] *= math.exp(value)
                    d[joint] *= math.exp(value)
        waypoints = tuple(
            (max(MIN_DURATION_S, round(round(dur / DURATION_STEP_S) * DURATION_STEP_S, 2)),
             tuple(float(f'{v:.{POSITION_DECIMALS}f}') + 0.0 for v in pos))
            for dur, pos in zip(durations, positions))
        gains = self.base.gains
        if any(param.kind == 'gain' for param in self.parameters):
            gains = (tuple(_round_gain(v) for v in p), tuple(i), tuple(_round_gain(v) for v in d),
                     tuple(clamp))
        base = self.base
        return RunSpec(index, base.trajectory, base.name, base.gains_label, waypoints, gains,
                       base.gain_scale, base.time_scale, base.push, self.seed + index,
                       base.settle_s)

    def runs(self, x: Sequence[float], index: int) -> list[RunSpec]:
        """Candidate `index`'s runs: nominal first, then each variant."""
        nominal = self.candidate(x, index)
        count = self.runs_per_candidate()
        specs = [dataclasses.replace(nominal, index=index * count)]
        for j, (gain_scale, time_scale) in enumerate(self.variants, start=1):
            specs.append(dataclasses.replace(nominal, index=index * count + j,
                                             gain_scale=gain_scale, time_scale=time_scale))
        lo, hi, draws = self.latency
        for j in range(draws):
            specs.append(dataclasses.replace(nominal, index=index * count + len(specs),
                                             latency_steps=(lo, hi), seed=LATENCY_SEED + j))
        return specs

    def runs_per_candidate(self) -> int:
        return runs_per_candidate(self.config())

    def costs(self, rows: Sequence[dict[str, Any]]) -> tuple[list[float], list[dict[str, Any]]]:
        """Each candidate's cost (the mean over its runs) and its nominal row."""
        count = self.runs_per_candidate()
        costs, nominal = [], []
        for k in range(0, len(rows), count):
            group = rows[k:k + count]
            costs.append(float(np.mean([self.objective.cost(row) for row in group])))
            nominal.append(group[0])
        return costs, nominal

    def evaluate(self, evaluate: Evaluate, xs: Sequence[Sequence[float]]
                 ) -> tuple[list[float], list[dict[str, Any]]] | None:
        """Costs and nominal rows of candidates `xs`; None if the sweep was interrupted."""
        outcome = evaluate([spec for k, x in enumerate(xs) for spec in self.runs(x, k)])
        if outcome.interrupted:
            return None
        return self.costs(outcome.rows)

    def steps(self) -> list[float]:
        return [DEFAULT_STEP[p.kind] * self.step_scale for p in self.parameters]

    def strategy(self) -> cma.CMAEvolutionStrategy:
        # cma takes seed 0 as "from the clock": the user's seed is shifted by one.
        options = {'seed': self.seed + 1, 'popsize': self.popsize, 'CMA_stds': self.steps(),
                   'verbose': -9, 'verb_log': 0, 'verb_disp': 0}
        import cma  # noqa: PLC0415 - scipy.stats behind it: --help and bad input skip it

        return cma.CMAEvolutionStrategy(np.zeros(len(self.parameters)), 1.0, options)


@dataclass
class SearchResult:
    start_cost: float
    best_cost: float
    best_x: list[float]
    best_row: dict[str, Any]
    best_spec: RunSpec
    generations: int
    history: list[float] = field(default_factory=list)  # best cost after each generation
    interrupted: bool = False


Evaluate = Callable[[Sequence[RunSpec]], SweepOutcome]


def _header(problem: SearchProblem) -> dict[str, Any]:
    return {'kind': 'search', 'config': problem.config()}


def _read_log(path: Path, problem: SearchProblem) -> list[dict[str, Any]]:
    try:
        lines = [json.loads(line) for line in path.read_text().splitlines() if line.strip()]
    except (OSError, ValueError) as err:
        raise SweepError(f'cannot resume from {path}: {err}') from None
    if not lines or lines[0].get('kind') != 'search':
        raise SweepError(f'cannot resume from {path}: it is not a search log')
    logged = lines[0]['config']
    expected = json.loads(json.dumps(problem.config()))
    differing = sorted(k for k in set(logged) | set(expected) if logged.get(k) != expected.get(k))
    if differing:
        raise SweepError(f'cannot resume from {path}: it was written for another search '
                         f'(differs in: {", ".join(differing)})')
    return lines[1:]


def run_search(problem: SearchProblem, evaluate: Evaluate, log_path: Path, resume: bool = False,
               report: Callable[[str], None] = print,
               on_best: Callable[[SearchResult], None] | None = None) -> SearchResult:
    """Run (or resume) the search for problem.generations generations in all.

    Raises:
        SweepError: the log exists and resume is False, or it does not match the problem.
    """
    records: list[dict[str, Any]] = []
    if resume:
        records = _read_log(log_path, problem)
    elif log_path.exists():
        raise SweepError(f'{log_path} exists; give --resume to continue that search, or '
                         'another --log')
    es = problem.strategy()
    start = _start_record(problem, evaluate, log_path, records)
    result = SearchResult(start['cost'], start['cost'], [0.0] * len(problem.parameters),
                          start['row'], problem.candidate(np.zeros(len(problem.parameters))), 0)
    report(f'search: start: cost {result.start_cost:.4g}')

    def consider(xs: Sequence[Sequence[float]], costs: Sequence[float],
                 rows: Sequence[dict[str, Any]]) -> None:
        k = int(np.argmin(costs))
        if costs[k] < result.best_cost:
            result.best_cost, result.best_x = float(costs[k]), [float(v) for v in xs[k]]
            result.best_row, result.best_spec = rows[k], problem.candidate(xs[k])
            if on_best is not None:
                on_best(result)

    for record in (r for r in records if r['kind'] == 'generation'):
        xs = es.ask()
        if not np.array_equal(np.array(xs), np.array(record['x'])):
            raise SweepError(f'cannot resume from {log_path}: generation {record["gen"]} does '
                             'not replay (another cma version?)')
        es.tell(xs, record['cost'])
        consider(xs, record['cost'], record['rows'])
        result.generations += 1
        result.history.append(result.best_cost)
    if result.generations:
        report(f'search: resumed after generation {result.generations}: best cost '
               f'{result.best_cost:.4g}')
    while result.generations < problem.generations and result.best_cost > 0.0:
        xs = es.ask()
        evaluated = problem.evaluate(evaluate, xs)
        if evaluated is None:
            result.interrupted = True
            break
        costs, rows = evaluated
        es.tell(xs, costs)
        consider(xs, costs, rows)
        record = {'kind': 'generation', 'gen': result.generations + 1,
                  'x': [[float(v) for v in x] for x in xs], 'cost': costs, 'rows': rows}
        with log_path.open('a') as log:
            log.write(json.dumps(record) + '\n')
        result.generations += 1
        result.history.append(result.best_cost)
        report(f'search: generation {result.generations}: best of generation '
               f'{min(costs):.4g}, best {result.best_cost:.4g}')
    return result


def _start_record(problem: SearchProblem, evaluate: Evaluate, log_path: Path,
                  records: Sequence[dict[str, Any]]) -> dict[str, Any]:
    """The start's record (the unchanged spec, x = 0): the log's, or evaluated now and
    written with the log's header (a new log)."""
    start = next((r for r in records if r['kind'] == 'start'), None)
    if start is not None:
        return start
    evaluated = problem.evaluate(evaluate, [np.zeros(len(problem.parameters))])
    if evaluated is None:
        raise KeyboardInterrupt
    start = {'kind': 'start', 'cost': evaluated[0][0], 'row': evaluated[1][0]}
    atomic_write(log_path, json.dumps(_header(problem)) + '\n' + json.dumps(start) + '\n')
    return start


# -- the files the search writes --------------------------------------------------------

def _number(value: float, decimals: int) -> str:
    text = f'{value:.{decimals}f}'.rstrip('0').rstrip('.')
    return '0' if text in ('-0', '') else text


def trajectory_yaml(name: str, spec: RunSpec, comment: Sequence[str]) -> str:
    """`name` in the tutorial's format (traj_yaml.py plays it unchanged)."""
    lines = [f'# {line}' for line in comment]
    lines.append('#   columns: ' + ' '.join(JOINT_NAMES))
    lines.append(f'{name}:')
    for duration_s, positions in spec.waypoints:
        numbers = ' '.join(_number(v, POSITION_DECIMALS) for v in positions)
        lines.append(f'  - [{_number(duration_s, 2)}, "{numbers}"]')
    return '\n'.join(lines) + '\n'


def gains_yaml(spec: RunSpec, comment: Sequence[str]) -> str:
    """The gains in config/atlas_controller.yaml's layout (a gains_file:= for atlas.launch)."""
    p, i, d, clamp = spec.gains
    lines = [f'# {line}' for line in comment]
    lines.append('atlas_controller:')
    lines.append(f'  joints: [{", ".join(JOINT_NAMES)}]')
    lines.append('  gains:')
    for k, joint in enumerate(JOINT_NAMES):
        lines.append(f'    {joint}: {{p: {p[k]!r}, i: {i[k]!r}, d: {d[k]!r}, '
                     f'i_clamp: {clamp[k]!r}}}')
    return '\n'.join(lines) + '\n'
