"""Many offline runs on Dask distributed: a local cluster of processes, or an existing one.

Why Dask: it is pure pip (no daemon to install), a LocalCluster of processes is one call,
and the same Client code talks to a remote scheduler (`dask scheduler` / `dask worker`).
Each run is one task; its row comes back to the client, which sorts the rows by input
order, so the table does not depend on the number of workers or on which finished first.
"""

from __future__ import annotations

import contextlib
import csv
import io
import itertools
import json
import logging
import math
import os
import signal
import sys
import threading
from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from tqdm import tqdm

from tutorial_atlas_control.search.runs import (
    TABLE_COLUMNS,
    Push,
    RunSpec,
    SweepError,
    run_one,
    spec_gains,
    spec_waypoints,
)
from tutorial_atlas_control.sim import GainsError, load_gains_yaml
from tutorial_atlas_control.trajectories import (
    TrajectoryError,
    load_trajectory,
    locate_trajectory_file,
)

__all__ = ['SweepEngine', 'SweepInputs', 'SweepOutcome', 'build_specs', 'parse_latency',
           'run_sweep', 'write_table']

#: Seconds the client waits for a given scheduler before refusing it.
CONNECT_TIMEOUT_S = 5


@dataclass(frozen=True)
class SweepInputs:
    """The grid: every trajectory x gains x gain scale x time scale x push (or none) x
    repeat. Repeats differ only in their seed, which draws the command latency (if any)."""

    trajectories: Sequence[tuple[str, str]]  # (file, name)
    gains_files: Sequence[str]
    gain_scales: Sequence[float] = (1.0,)
    time_scales: Sequence[float] = (1.0,)
    pushes: Sequence[Push | None] = (None,)
    settle_s: float = 3.0
    seed: int = 0
    latency_steps: tuple[int, int] = (0, 0)
    repeats: int = 1


def parse_latency(text: str) -> tuple[int, int]:
    """`LO:HI` whole milliseconds (1 ms steps), 0 <= LO <= HI, or `MS` for MS:MS."""
    parts = text.split(':')
    try:
        if len(parts) not in (1, 2):
            raise ValueError
        lo, hi = int(parts[0]), int(parts[-1])
        if not 0 <= lo <= hi:
            raise ValueError
    except ValueError:
        raise SweepError(f'latency {text!r} is not LO:HI whole milliseconds, 0 <= LO <= HI '
                         '(e.g. 1:3)') from None
    return lo, hi


def parse_push(text: str) -> Push:
    """`AT_S:FX,FY,FZ:DURATION_S` (s after the first command, N, s)."""
    parts = text.split(':')
    try:
        if len(parts) != 3:
            raise ValueError
        force = tuple(float(x) for x in parts[1].split(','))
        at_s, duration_s = float(parts[0]), float(parts[2])
        if len(force) != 3 or not all(math.isfinite(v) for v in (*force, at_s, duration_s)) \
                or at_s < 0 or duration_s <= 0:
            raise ValueError
    except ValueError:
        raise SweepError(f'push {text!r} is not AT_S:FX,FY,FZ:DURATION_S (e.g. 2:0,150,0:0.1)'
                         ) from None
    return Push(at_s, (force[0], force[1], force[2]), duration_s)


def build_specs(inputs: SweepInputs) -> list[RunSpec]:
    """All runs, in input order; every file and name is checked here, before any run.

    Raises:
        SweepError: a trajectory file or gains file is missing or malformed, a name unknown.
    """
    loaded: list[tuple[str, str, Any]] = []
    for file, name in inputs.trajectories:
        try:
            path = locate_trajectory_file(file)
            loaded.append((str(file), name, spec_waypoints(load_trajectory(path, name))))
        except TrajectoryError as err:
            raise SweepError(str(err)) from None
    gains = []
    for file in inputs.gains_files:
        if not Path(file).is_file():
            raise SweepError(f'gains file {file} does not exist')
        try:
            gains.append((str(file), spec_gains(load_gains_yaml(file))))
        except GainsError as err:
            raise SweepError(str(err)) from None
    specs = []
    grid = itertools.product(loaded, gains, inputs.gain_scales, inputs.time_scales,
                             inputs.pushes, range(inputs.repeats))
    for index, ((file, name, waypoints), (gains_file, table), g, t, push, _) in enumerate(grid):
        specs.append(RunSpec(index, file, name, gains_file, waypoints, table, g, t, push,
                             inputs.seed + index, inputs.settle_s, inputs.latency_steps))
    return specs


@dataclass
class SweepOutcome:
    rows: list[dict[str, Any]]
    total: int
    interrupted: bool = False


def _client(scheduler: str | None, workers: int) -> Any:
    """A Dask client: on `scheduler`, or on a new local cluster of `workers` processes."""
    # distributed imported here: half a second (matplotlib among it) --help need not pay.
    from distributed import Client, LocalCluster  # noqa: PLC0415

    if scheduler is not None:
        try:
            return Client(scheduler, timeout=CONNECT_TIMEOUT_S)
        except (OSError, TimeoutError, ValueError) as err:
            raise SweepError(f'cannot reach the Dask scheduler at {scheduler}: '
                             f'{str(err).splitlines()[0] if str(err) else type(err).__name__}'
                             ) from None
    # Workers log at CRITICAL only: a run's error reaches the client through its future, and
    # a worker whose heartbeat meets the scheduler closing first (Ctrl-C, or any close)
    # would print an ERROR traceback of distributed's that says nothing to the user.
    with _sigint_ignored():  # the workers inherit it: Ctrl-C is the client's alone
        cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                               dashboard_address=':0', silence_logs=logging.CRITICAL)
    return Client(cluster)


@contextlib.contextmanager
def _sigint_ignored() -> Iterator[None]:
    """SIGINT ignored while local worker processes start.

    A terminal's Ctrl-C goes to the whole process group: workers that did not ignore it
    would each print a KeyboardInterrupt traceback while the client cancels the runs and
    stops them itself. An ignored signal stays ignored in a started process, and Python
    then installs no handler of its own.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


class SweepEngine:
    """A Dask client for one or more sweeps: on `scheduler`, or a local cluster of `workers`
    processes (default: one per core); one worker and no scheduler run in this process, as
    the same tasks one after another (a cluster of one would add only its start-up: a
    process importing MuJoCo, seconds). A context manager; close() stops a local cluster."""

    def __init__(self, workers: int | None = None, scheduler: str | None = None) -> None:
        self.workers = workers or os.cpu_count() or 1
        self.scheduler = scheduler
        #: None: the runs go in this process.
        self.client = (None if self.workers == 1 and scheduler is None
                       else _client(scheduler, self.workers))

    def __enter__(self) -> SweepEngine:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        if self.client is None:
            return
        cluster = self.client.cluster if self.scheduler is None else None
        self.client.close()
        if cluster is not None:
            cluster.close()

    def run(self, specs: Sequence[RunSpec], progress: bool = True,
            run: Callable[[RunSpec], dict[str, Any]] = run_one) -> SweepOutcome:
        """Run every spec as a Dask task; rows come back sorted by input order.

        Ctrl-C cancels what is left and returns the finished rows (interrupted=True).
        """
        rows: list[dict[str, Any]] = []
        interrupted = False
        client = self.client
        futures = [] if client is None else [client.submit(run, spec, pure=False)
                                             for spec in specs]
        if client is not None:
            from distributed import as_completed  # noqa: PLC0415
        finished = ((run(spec) for spec in specs) if client is None
                    else (future.result() for future in as_completed(futures)))
        bar = _bar(len(specs), progress)
        # Not on a terminal (a log): a plain line per finished run instead of the bar.
        lines = progress and bar.disable
        try:
            for row in finished:
                rows.append(row)
                bar.update(1)
                if lines:
                    print(f'sweep: {len(rows)}/{len(specs)} runs done', file=sys.stderr,
                          flush=True)
        except KeyboardInterrupt:
            interrupted = True
            if client is not None:
                client.cancel(futures)
        finally:
            bar.close()
        rows.sort(key=lambda row: row['index'])
        return SweepOutcome(rows, len(specs), interrupted)


def run_sweep(specs: Sequence[RunSpec], workers: int | None = None, scheduler: str | None = None,
              progress: bool = True) -> SweepOutcome:
    """One sweep on its own engine (see SweepEngine.run)."""
    with SweepEngine(workers, scheduler) as engine:
        return engine.run(specs, progress)


def _bar(total: int, enabled: bool) -> Any:
    # disable=None: tqdm draws only on a terminal (a log file gets no bars).
    return tqdm(total=total, unit='run', desc='sweep', disable=None if enabled else True,
                leave=False)


def _csv_value(value: Any) -> str:
    if value is None:
        return ''
    if isinstance(value, float):
        return repr(value)
    return str(value)


def _json_value(value: Any) -> Any:
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, np.generic):
        return value.item()
    return value


def table_texts(rows: Iterable[dict[str, Any]], columns: Sequence[str] = TABLE_COLUMNS
                ) -> tuple[str, str]:
    """The table as CSV and JSON text (`columns`: the trajectory sweep's by default)."""
    rows = list(rows)
    out = io.StringIO()
    writer = csv.writer(out, lineterminator='\n')
    writer.writerow(columns)
    for row in rows:
        writer.writerow([_csv_value(row.get(column)) for column in columns])
    doc = [{column: _json_value(row.get(column)) for column in columns} for row in rows]
    return out.getvalue(), json.dumps(doc, indent=1) + '\n'


def check_output(prefix: Path) -> None:
    """Refuse an output whose directory does not exist, before running anything."""
    if not prefix.parent.is_dir():
        raise SweepError(f'{prefix}: directory {prefix.parent} does not exist')


def write_table(rows: Iterable[dict[str, Any]], prefix: Path,
                columns: Sequence[str] = TABLE_COLUMNS) -> tuple[Path, Path]:
    """PREFIX.csv and PREFIX.json (`columns`), each written to a temporary file and
    renamed."""
    csv_text, json_text = table_texts(rows, columns)
    paths = (prefix.with_name(prefix.name + '.csv'), prefix.with_name(prefix.name + '.json'))
    for path, text in zip(paths, (csv_text, json_text)):
        atomic_write(path, text)
    return paths


def atomic_write(path: Path, text: str) -> None:
    partial = path.with_name(f'.{path.name}.{os.getpid()}.partial')
    try:
        partial.write_text(text)
        os.replace(partial, path)
    except OSError as err:
        raise SweepError(f'cannot write {path}: {err.strerror or err}') from err
    finally:
        partial.unlink(missing_ok=True)
