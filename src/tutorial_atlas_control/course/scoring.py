"""DRCSim's VRC Task 2 scoring (VRCScoringPlugin, 2.7.0), fed once per physics step.

The rules are the plugin's code, step for step, so that a run here scores as it did there:
- the gates are taken in order; only the next one counts. The pelvis's position in the
  gate's frame is inside when |y| <= width / 2, its side the sign of x (0 outside). Going
  from side -1 to +1 passes the gate ("Successfully passed through gate k+1. " for
  gate_k), and the side then resets to 0; otherwise the side is remembered. The first
  gate's side starts at -1, as the plugin's does.
- gate_0 starts the clock ("Starting clock. ") and scores nothing; gates 1-4 add a point
  each; the last stops the clock ("Stopping clock. ").
- a fall is the head's z velocity changing by more than fall_accel_threshold (m/s²) over one
  step; none is counted within 15 s of the previous one (nor over the first 15 s: the
  previous fall is taken at time 0), nor 5 s or more after the clock stopped.
- a row goes out at every event (a gate, a fall) and otherwise once 1 s of sim time has
  passed since the previous row (the first at 1 s).

Times are integers of ns, as Gazebo's common::Time, so that the 1 s cadence and the
lockouts are exact. The plugin ran at the start of each update with the sim time already
advanced by one step and the state of the step before; the simulator's caller matches that
by giving, after each step, the new sim time with the body poses MuJoCo computed at the
step's start. Only the pelvis's position enters (the plugin rotates it into the gate's frame;
the robot's own orientation never counts).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from tutorial_atlas_control.course.errors import CourseError
from tutorial_atlas_control.course.vrc_task_2 import GATES, Gate

__all__ = [
    'FALL_ACCEL_THRESHOLD', 'FALL_LOCKOUT_NS', 'POST_COMPLETION_QUIET_NS', 'ROW_PERIOD_NS',
    'TASK_WALKING', 'Scorer', 'ScoreRow', 'gate_side', 'seconds',
]

#: The plugin's default fall threshold (m/s², the head's z acceleration over one step).
FALL_ACCEL_THRESHOLD = 1000.0
NS_PER_S = 1_000_000_000
#: No fall counts within 15 s of the previous one (the first 15 s included).
FALL_LOCKOUT_NS = 15 * NS_PER_S
#: Falls stop counting 5 s after the clock stopped (no diving across the finish line).
POST_COMPLETION_QUIET_NS = 5 * NS_PER_S
#: A row at least every 1 s of sim time.
ROW_PERIOD_NS = NS_PER_S
#: atlas_msgs/VRCScore's task_type of VRC Task 2.
TASK_WALKING = 2


def seconds(ns: int) -> float:
    """common::Time::Double() of a time of `ns`: whole seconds plus nanoseconds · 1e-9."""
    whole, rest = divmod(ns, NS_PER_S)
    return whole + rest * 1e-9


@dataclass(frozen=True)
class ScoreRow:
    """One row of score.log and one /vrc_score message (VRCScoringPlugin::WriteScore).

    Attributes:
        wall_elapsed_ns: wall time since the run (the scorer) started; the message's
            wall_time (the plugin's, despite the field's comment).
        sim_time_ns: the sim time.
        wall_since_gate0_ns, sim_since_gate0_ns: since gate_0 (to the last gate once
            passed); 0 before gate_0.
        completion: gates 1-4 passed.
        falls: falls counted.
        message: the events of this step, as the plugin wrote them ('' for a periodic row).
        task_type: atlas_msgs/VRCScore's TASK_WALKING.
    """

    wall_elapsed_ns: int
    sim_time_ns: int
    wall_since_gate0_ns: int
    sim_since_gate0_ns: int
    completion: int
    falls: int
    message: str
    task_type: int = TASK_WALKING

    def log_line(self) -> str:
        """The row as score.log has it: `%.3f` times, counts, the message in quotes."""
        times = (self.wall_elapsed_ns, self.sim_time_ns, self.wall_since_gate0_ns,
                 self.sim_since_gate0_ns)
        fields = [f'{seconds(ns):.3f}' for ns in times]
        return f'{",".join(fields)},{self.completion},{self.falls},"{self.message}"\n'


def gate_side(gate: Gate, x_m: float, y_m: float) -> int:
    """IsPoseInGate: 0 outside the gate's width, else -1 before it and +1 after (x >= 0)."""
    dx, dy = x_m - gate.x_m, y_m - gate.y_m
    cos_yaw, sin_yaw = math.cos(gate.yaw_rad), math.sin(gate.yaw_rad)
    local_x = cos_yaw * dx + sin_yaw * dy
    local_y = -sin_yaw * dx + cos_yaw * dy
    if abs(local_y) <= gate.width_m / 2.0:
        return 1 if local_x >= 0.0 else -1
    return 0


class Scorer:
    """VRCScoringPlugin's state for VRC Task 2, one `step` per physics step.

    Args:
        wall_start_ns: the run's start in wall time (the plugin's Load): rows' wall_elapsed.
        gates: the gates in scoring order (the course's).
        fall_accel_threshold: m/s² (the plugin's `fall_accel_threshold`, default 1000).
    """

    def __init__(self, wall_start_ns: int, gates: Sequence[Gate] = GATES,
                 fall_accel_threshold: float = FALL_ACCEL_THRESHOLD) -> None:
        if not gates:
            raise CourseError('scoring needs at least one gate (found no gates)')
        if not fall_accel_threshold > 0.0:
            raise CourseError(f'fall_accel_threshold must be > 0 m/s^2, '
                              f'got {fall_accel_threshold!r}')
        self.wall_start_ns = wall_start_ns
        self.gates = tuple(gates)
        self.fall_accel_threshold = float(fall_accel_threshold)
        self.next_gate = 0
        self.next_gate_side = -1
        self.completion = 0
        self.falls = 0
        # Zero means unset, as common::Time::Zero in the plugin.
        self.start_sim_ns = self.start_wall_ns = 0
        self.stop_sim_ns = self.stop_wall_ns = 0
        self.prev_row_ns = 0
        self.prev_fall_ns = 0
        self.prev_vel_ns = 0
        self.prev_head_vz = 0.0

    def step(self, sim_ns: int, wall_ns: int, pelvis_x_m: float, pelvis_y_m: float,
             head_vz_mps: float) -> ScoreRow | None:
        """One update (OnUpdate): the gates, the falls, and the row due now, if any."""
        previous = (self.completion, self.falls)
        message = ''
        force = False
        first_gate = self.next_gate == 0
        passed = self._check_next_gate(pelvis_x_m, pelvis_y_m)
        if passed:
            message += f'Successfully passed through gate {passed}. '
            if first_gate:
                force = True  # gate_0 scores nothing but is logged
                self.start_sim_ns, self.start_wall_ns = sim_ns, wall_ns
                message += 'Starting clock. '
            else:
                self.completion += 1
                if self.next_gate == len(self.gates):
                    self.stop_sim_ns, self.stop_wall_ns = sim_ns, wall_ns
                    message += 'Stopping clock. '
        accel = self._check_fall(sim_ns, head_vz_mps)
        if accel is not None:
            self.falls += 1
            message += f'Damaging fall detected, acceleration of: {accel:g} m/s^2. '
        if (self.completion, self.falls) != previous:
            force = True
        return self._row(sim_ns, wall_ns, message, force)

    @property
    def finished(self) -> bool:
        """Every gate passed (the clock stopped)."""
        return self.next_gate == len(self.gates)

    def _check_next_gate(self, x_m: float, y_m: float) -> int:
        """CheckNextGate: the passed gate's number in the log (k+1 for gate_k), else 0."""
        if self.next_gate >= len(self.gates):
            return 0
        side = gate_side(self.gates[self.next_gate], x_m, y_m)
        if self.next_gate_side < 0 < side:
            self.next_gate += 1
            self.next_gate_side = 0
            return self.next_gate
        # Going backwards (+1 to -1) is only logged by the plugin; the side is remembered.
        self.next_gate_side = side
        return 0

    def _check_fall(self, sim_ns: int, head_vz_mps: float) -> float | None:
        """CheckFall: the acceleration (m/s²) of a fall counted now, else None."""
        if self.stop_sim_ns and sim_ns - self.stop_sim_ns >= POST_COMPLETION_QUIET_NS:
            return None
        if sim_ns - self.prev_fall_ns < FALL_LOCKOUT_NS:
            self.prev_vel_ns, self.prev_head_vz = sim_ns, head_vz_mps
            return None
        dt_ns = sim_ns - self.prev_vel_ns
        change = head_vz_mps - self.prev_head_vz
        self.prev_vel_ns, self.prev_head_vz = sim_ns, head_vz_mps
        if dt_ns <= 0:
            return None  # the same instant twice: no rate (the plugin would divide by 0)
        accel = change / seconds(dt_ns)
        if abs(accel) > self.fall_accel_threshold:
            self.prev_fall_ns = sim_ns
            return accel
        return None

    def _row(self, sim_ns: int, wall_ns: int, message: str, force: bool) -> ScoreRow | None:
        """WriteScore: the row due now (every event; else 1 s of sim time after the last)."""
        if not force and sim_ns - self.prev_row_ns < ROW_PERIOD_NS:
            return None
        if self.stop_sim_ns:
            sim_elapsed = self.stop_sim_ns - self.start_sim_ns
        elif self.start_sim_ns:
            sim_elapsed = sim_ns - self.start_sim_ns
        else:
            sim_elapsed = 0
        if self.stop_wall_ns:
            wall_elapsed = self.stop_wall_ns - self.start_wall_ns
        elif self.start_wall_ns:
            wall_elapsed = wall_ns - self.start_wall_ns
        else:
            wall_elapsed = 0
        self.prev_row_ns = sim_ns
        return ScoreRow(wall_ns - self.wall_start_ns, sim_ns, wall_elapsed, sim_elapsed,
                        self.completion, self.falls, message)
