"""The tutorial's arm tracking, judged offline: touchdown and touchdown_exhausted reach every
waypoint's arm positions by the end of its segment (one command period after its last
sample, the instant the live rostest measures at).

Deterministic, so it checks every waypoint, including touchdown_exhausted's third, whose
2.2 rad swing in 1 s ends as the robot starts to tip (the live rostest judges the waypoints
before it; see test_tutorial_run.py).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from tutorial_atlas_control.joints import JOINT_INDEX
from tutorial_atlas_control.offline.player import DEFAULT_START_AFTER_S, write_offline_bag
from tutorial_atlas_control.sim.controller import DEFAULT_GAINS_FILE, load_gains_yaml
from tutorial_atlas_control.sim.simulator import AtlasSimulator
from tutorial_atlas_control.trajectories.trajectory import load_trajectory, sample_count

#: Offline (no ROS, no claim about time): `make test` runs it at the lowest priority beside
#: the serial tests, on the CPU they leave idle.
pytestmark = pytest.mark.offline

REPO = Path(__file__).resolve().parents[2]
TRAJ_DATA2 = REPO / 'trajectories' / 'Traj_data2.yaml'
ARM_JOINTS = ('l_arm_shx', 'r_arm_shx', 'l_arm_elx', 'r_arm_elx')
#: The rostest's acceptance threshold (rad).
ARM_TOLERANCE_RAD = 0.1
#: Largest error over the four joints at each waypoint's end, as measured (rad, 3 decimals).
MEASURED_RAD = {'touchdown': (0.035, 0.015, 0.053),
                'touchdown_exhausted': (0.035, 0.015, 0.048, 0.042)}


class WaypointEnds:
    """Step hook: the arm joints' errors at each segment's end (sim time, ns)."""

    def __init__(self, ends_ns: list[int], targets: list[np.ndarray]) -> None:
        self.ends_ns = ends_ns
        self.targets = targets
        self.errors: list[np.ndarray] = []

    def __call__(self, sim: AtlasSimulator) -> None:
        k = len(self.errors)
        if k < len(self.ends_ns) and sim.sim_time_ns >= self.ends_ns[k]:
            q = sim.joint_positions()
            self.errors.append(np.array([abs(q[JOINT_INDEX[j]] - self.targets[k][JOINT_INDEX[j]])
                                         for j in ARM_JOINTS]))


@pytest.mark.parametrize('trajectory', sorted(MEASURED_RAD))
def test_arms_reach_every_waypoint(trajectory: str, tmp_path: Path) -> None:
    waypoints = load_trajectory(TRAJ_DATA2, trajectory)
    start_ns = round(DEFAULT_START_AFTER_S * 1e9)
    ends_ns, t_ns = [], start_ns
    for w in waypoints:
        t_ns += round(w.duration_s * 1e9)
        ends_ns.append(t_ns + round(w.duration_s / sample_count(w.duration_s) * 1e9))
    probe = WaypointEnds(ends_ns, [w.positions for w in waypoints])
    write_offline_bag(tmp_path / 'run.bag', str(TRAJ_DATA2), trajectory, waypoints,
                      load_gains_yaml(DEFAULT_GAINS_FILE), 0.5, DEFAULT_START_AFTER_S,
                      on_step=probe)
    worst = [round(float(e.max()), 3) for e in probe.errors]
    print(f'\n{trajectory}: largest arm error at each waypoint end {worst} rad')
    assert len(worst) == len(waypoints)
    assert max(worst) < ARM_TOLERANCE_RAD
    assert tuple(worst) == pytest.approx(MEASURED_RAD[trajectory], abs=0.0005)
