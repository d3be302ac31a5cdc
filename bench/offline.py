"""The benchmark's measurements that need no ROS master: physics ceiling and bag reading."""

from __future__ import annotations

import contextlib
import hashlib
import os
import sys
import time
from collections.abc import Iterator
from pathlib import Path
from typing import TYPE_CHECKING

from harness import REPO_DIR, log

from tutorial_atlas_control import topics

if TYPE_CHECKING:
    from tutorial_atlas_control.sim.simulator import AtlasSimulator

# The synthetic run bag is a test fixture: test/support, imported as `support` (as the tests
# and node_loop.py do).
sys.path.insert(0, str(REPO_DIR / 'test'))

GAINS_YAML = REPO_DIR / 'config' / 'atlas_controller.yaml'
#: The topics bags.reader.read_bag deserializes (the baseline reads the same ones).
ANALYSIS_TOPICS = (topics.JOINT_STATES, topics.JOINT_COMMANDS, topics.GROUND_TRUTH_ODOM,
                   topics.CONTROL_MODE)


# ---------------------------------------------------------------------------- physics
def make_simulator(compiled_law: bool = True) -> 'AtlasSimulator':
    """AtlasSimulator with the DRCSim gains from config/, as the node builds it."""
    from tutorial_atlas_control.sim import controller, model
    from tutorial_atlas_control.sim.simulator import AtlasSimulator

    return AtlasSimulator(model.load_model(), controller.load_gains_yaml(GAINS_YAML),
                          compiled_law=compiled_law)


def physics_run(warmup_steps: int = 1500, steps: int = 5000, compiled_law: bool = True) -> float:
    """Steps per wall second of AtlasSimulator.step() (law + mj_step) in a plain loop.

    A fresh simulator each run; the warm-up passes the 1 s torso pin so the timed
    steps are the standing robot with its feet in contact, as in a real run.
    """
    sim = make_simulator(compiled_law)
    step = sim.step
    for _ in range(warmup_steps):
        step()
    start = time.perf_counter()
    for _ in range(steps):
        step()
    return steps / (time.perf_counter() - start)


def python_reference_switches() -> tuple[str, ...]:
    """The environment variables that switch each compiled part of the controller to its
    pure Python reference: the bench's "before" of the compiled core."""
    from tutorial_atlas_control.balance import ESTIMATOR_ENV, STATICS_ENV, WHOLE_BODY_ENV
    from tutorial_atlas_control.walking import LEGS_ENV, SWING_ENV, WALK_SWING_ENV

    return ESTIMATOR_ENV, STATICS_ENV, SWING_ENV, WHOLE_BODY_ENV, LEGS_ENV, WALK_SWING_ENV


def own_passes_switches() -> tuple[str, ...]:
    """The environment variables that make a simulator step a behaviour with mj_step whole,
    its estimate computing MuJoCo's passes of its own (sim.shared_passes): the Python
    reference's way, and the "before" of the shared passes (`python` or `own`)."""
    from tutorial_atlas_control.sim import SHARED_PASSES_ENV

    return (SHARED_PASSES_ENV,)


@contextlib.contextmanager
def python_reference() -> Iterator[None]:
    """Controllers built inside run their pure Python reference: every compiled part
    switched off (each part reads its variable when it is built), the estimate's passes
    its own, restored after."""
    switches = python_reference_switches() + own_passes_switches()
    saved = {name: os.environ.get(name) for name in switches}
    os.environ.update({name: 'python' for name in switches})
    try:
        yield
    finally:
        for name, value in saved.items():
            if value is None:
                os.environ.pop(name, None)
            else:
                os.environ[name] = value


def stand_run(warmup_steps: int = 2500, steps: int = 5000) -> float:
    """Wall µs per step the balancing Stand spends (its estimate and controller, f_out).

    A fresh simulator with the Stand behaviour installed (atlas.launch stand:=balance), as
    the node steps it; the warm-up passes the 1 s torso pin and the 1 s take-over to the
    Stand pose, so the timed steps are the robot balancing on both feet.
    """
    from tutorial_atlas_control.balance import TimedStand

    sim = make_simulator()
    stand = TimedStand(sim.atlas, clock=time.perf_counter)
    sim.install_stand(stand)
    for _ in range(warmup_steps):
        sim.step()
    stand.spent_s = 0.0
    for _ in range(steps):
        sim.step()
    return stand.spent_s / steps * 1e6


def walk_run(steps: int = 6) -> tuple[float, float]:
    """(controller CPU µs per step, offline real-time factor) of a walking trial: Stand
    1 s, `steps` straight steps of 0.25 m at 0.63 s, the catch, Stand again (walk_trial:
    the robot placed standing, the controller in lockstep with the physics, no bag)."""
    from tutorial_atlas_control.walking import straight_steps
    from tutorial_atlas_control.walking.walk_trial import SETTLE_S, walk_trial

    sim_s = SETTLE_S + 0.6 + steps * 0.63 + 0.8
    start = time.perf_counter()
    trial = walk_trial(straight_steps(steps, 0.25), sim_s)
    wall_s = time.perf_counter() - start
    if trial.fell or trial.steps != steps:
        raise RuntimeError(f'the bench\'s walk fell or took {trial.steps} of {steps} steps')
    return trial.cost_per_step_us, sim_s / wall_s


def steps_per_sim_second() -> float:
    from tutorial_atlas_control.sim import model

    return 1.0 / float(model.load_model().model.opt.timestep)


# ---------------------------------------------------------------------------- bags
def run_bag(cache_dir: Path, duration_s: float = 60.0) -> Path:
    """The 60 s synthetic run bag (synthetic_bags.write_run_bag), cached in /tmp.

    Cached under a name that hashes synthetic_bags.py, so a changed generator makes a new
    bag; written to a temporary name and renamed, so an interrupted run leaves no half bag.
    """
    from support import synthetic_bags

    source = Path(synthetic_bags.__file__).read_bytes()
    key = hashlib.sha1(source + str(duration_s).encode()).hexdigest()[:12]
    path = cache_dir / f'run{duration_s:.0f}s_{key}.bag'
    if path.is_file():
        return path
    cache_dir.mkdir(parents=True, exist_ok=True)
    partial = path.with_name(f'{path.stem}.{os.getpid()}.partial.bag')
    log(f'writing the {duration_s:.0f} s synthetic run bag {path} (once; cached)')
    start = time.perf_counter()
    try:
        synthetic_bags.write_run_bag(partial, duration_s)
        partial.rename(path)
    finally:
        partial.unlink(missing_ok=True)
    log(f'bag written in {time.perf_counter() - start:.1f} s')
    return path


def analysis_message_count(path: Path) -> int:
    """Messages on ANALYSIS_TOPICS (what both readers deserialize)."""
    import rosbag

    with rosbag.Bag(str(path)) as bag:
        return bag.get_message_count(topic_filters=list(ANALYSIS_TOPICS))


def analysis_run(path: Path) -> float:
    """Wall seconds of bags.analysis.analyze_bag (read_bag + metrics) on `path`."""
    from tutorial_atlas_control.bags.analysis import analyze_bag

    start = time.perf_counter()
    analyze_bag(path)
    return time.perf_counter() - start


def rosbag_run(path: Path) -> tuple[float, int]:
    """Wall seconds (and message count) to deserialize ANALYSIS_TOPICS with Debian's rosbag."""
    import rosbag

    count = 0
    start = time.perf_counter()
    with rosbag.Bag(str(path)) as bag:
        for _topic, _msg, _t in bag.read_messages(topics=list(ANALYSIS_TOPICS)):
            count += 1
    return time.perf_counter() - start, count


# ---------------------------------------------------------------------------- offline runs
#: The trajectory of the offline-run figure: the longest that stays up (10.5 s of sim time).
OFFLINE_TRAJECTORY = 'touchdown'


def offline_run(work_dir: Path) -> float:
    """Real-time factor of run_offline (simulate + write the bag) on OFFLINE_TRAJECTORY."""
    from tutorial_atlas_control.offline.player import run_offline

    bag = work_dir / 'offline_bench.bag'
    run = run_offline(str(REPO_DIR / 'trajectories' / 'Traj_data2.yaml'), OFFLINE_TRAJECTORY,
                      bag, gains_file=GAINS_YAML)
    bag.unlink()
    return run.real_time_factor
