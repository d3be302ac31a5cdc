"""A recorded walk in numbers: the footsteps asked for, where the feet landed, how far the
robot went and whether it fell.

The steps asked for are the WALK commands' `walk_params.step_queue` on
/atlas/atlas_sim_interface_command (a streaming client sends each step many times: the
last pose sent for a step index is its target). Where the feet landed comes from the
recorded pose (/ground_truth_odom and /atlas/joint_states) by the model's forward
kinematics, as bags/feet.py does: a foot is down while its link is within PLANTED_HEIGHT_M
of its height standing flat (on the VRC course, above the terrain under it:
bags/course_terrain.py); each time it comes down again after the first is a step, and its
landing pose is taken LANDING_SETTLE_S later. The n-th landing of a foot is matched with
the n-th step asked of that foot, by step index. Step targets and landings are foot link
poses in the world frame (the AtlasSimInterface's pos_est frame here).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from tutorial_atlas_control import topics
from tutorial_atlas_control.bags.behaviours import BehaviourChange, walk_windows
from tutorial_atlas_control.bags.course_terrain import (
    above_ground,
    is_course_run,
    terrain_heights,
)
from tutorial_atlas_control.bags.feet import RecordedKinematics
from tutorial_atlas_control.bags.reader import BagData
from tutorial_atlas_control.bags.records import open_bag
from tutorial_atlas_control.bags.typestore import load_typestore
from tutorial_atlas_control.errors import BagAnalysisError
from tutorial_atlas_control.sim import fallen

if TYPE_CHECKING:
    from tutorial_atlas_control.balance import SoleBox

__all__ = ['FOOT_BODIES', 'Landing', 'StepTarget', 'WalkSummary', 'foot_poses', 'landings',
           'match_landings', 'plot_footprints', 'read_step_targets', 'sole_patch',
           'summarise_walk', 'titled_walks', 'walk_lines']

#: The AtlasSimInterface's WALK behaviour number.
WALK_BEHAVIOR = 4
#: The foot links, by foot_index (0 left, 1 right).
FOOT_BODIES = ('l_foot', 'r_foot')
#: A foot is down while its link is at most this far (m) above the lowest it went.
PLANTED_HEIGHT_M = 0.01
#: A landing's pose is read this long (s) after the foot came down (the sole settled).
LANDING_SETTLE_S = 0.05
#: A foot must stay down at least this long (s) to count: a stance, not a scuff or a swing
#: passing low (a walking stance lasts a step's duration, 0.63 s by default, or more).
MIN_PLANTED_S = 0.2
#: How many of a foot's next landings a step may be matched with.
MATCH_WINDOW = 5
#: The rate (Hz) at which the recorded pose is turned into foot poses.
KINEMATICS_RATE_HZ = 200.0
_COMMAND_TYPE = 'atlas_msgs/msg/AtlasSimInterfaceCommand'


@dataclass(frozen=True)
class StepTarget:
    """A step asked for: its index, foot (0 left, 1 right) and the foot link's pose (m, rad)."""

    step_index: int
    foot_index: int
    x_m: float
    y_m: float
    yaw_rad: float


@dataclass(frozen=True)
class Landing:
    """Where a foot came down (the foot link's pose, m and rad) and when (s from the bag's
    start)."""

    foot_index: int
    t_s: float
    x_m: float
    y_m: float
    yaw_rad: float


@dataclass(frozen=True)
class WalkSummary:
    """A walk's figures. `placements` pairs each step asked for with its landing (None: the
    foot never came down for it)."""

    placements: list[tuple[StepTarget, Landing | None]]
    distance_m: float | None
    fell: bool
    lowest_pelvis_m: float | None
    pelvis_xy: np.ndarray  # (n, 2), for the plot
    #: How far the feet went, landing to landing, the two feet's mean (m): the path walked
    #: (a circle walked round is long; its distance from the start is short).
    path_m: float | None = None
    #: The model's sole box, the footprint drawn (None: the plot reads it from the model).
    sole: SoleBox | None = None

    @property
    def steps_taken(self) -> int:
        return sum(landing is not None for _, landing in self.placements)

    @property
    def worst_placement(self) -> tuple[float, float] | None:
        """The largest position (m) and yaw (rad) errors of the landings, or None."""
        errors = [(float(np.hypot(landing.x_m - target.x_m, landing.y_m - target.y_m)),
                   abs(_wrap(landing.yaw_rad - target.yaw_rad)))
                  for target, landing in self.placements if landing is not None]
        if not errors:
            return None
        return max(e[0] for e in errors), max(e[1] for e in errors)


    def placement_errors(self) -> np.ndarray:
        """Each landing's position error in its step's frame (m, (n, 2)): ahead of the
        step asked for along its heading, and to its left."""
        rows = []
        for target, landing in self.placements:
            if landing is None:
                continue
            dx, dy = landing.x_m - target.x_m, landing.y_m - target.y_m
            c, s = np.cos(target.yaw_rad), np.sin(target.yaw_rad)
            rows.append((c * dx + s * dy, -s * dx + c * dy))
        return np.array(rows).reshape(-1, 2)

    @property
    def placement_bias_m(self) -> tuple[float, float] | None:
        """The landings' mean error ahead and to the left of the steps asked for (m)."""
        errors = self.placement_errors()
        return None if not len(errors) else (float(errors[:, 0].mean()),
                                              float(errors[:, 1].mean()))

    @property
    def placement_scatter_m(self) -> float | None:
        """The landings' RMS distance from the steps asked for plus the bias (m)."""
        errors = self.placement_errors()
        if not len(errors):
            return None
        return float(np.sqrt(np.mean(np.sum((errors - errors.mean(axis=0)) ** 2, axis=1))))


def _wrap(angle_rad: float) -> float:
    return float((angle_rad + np.pi) % (2.0 * np.pi) - np.pi)


def _yaw_of_xyzw(x: float, y: float, z: float, w: float) -> float:
    return float(np.arctan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z)))


def read_step_targets(data: BagData, window_s: tuple[float, float] | None = None
                      ) -> tuple[list[StepTarget], float | None]:
    """The steps the WALK commands in `data`'s bag asked for, by step index (the last pose
    sent for each index), and when the first WALK came (s from the bag's start; None: no
    WALK did); with `window_s` (from, to), only the commands sent in it (one walk of
    several: their step indices start again at 1)."""
    records = open_bag(data.path)
    try:
        connections = [c for c in records.connections if c.topic == topics.ASI_COMMAND]
        if not connections:
            return [], None
        typestore = load_typestore(records.connections)
        bag_ns, raws = records.raw_messages(connections)
        targets: dict[int, StepTarget] = {}
        first_walk_s = None
        for t_ns, raw in zip(bag_ns.tolist(), raws):
            command = typestore.deserialize_ros1(raw, _COMMAND_TYPE)
            sent_s = t_ns / 1e9 - data.start_time_s
            if command.behavior != WALK_BEHAVIOR or (
                    window_s is not None and not window_s[0] <= sent_s <= window_s[1]):
                continue
            if first_walk_s is None:
                first_walk_s = sent_s
            for step in command.walk_params.step_queue:
                if step.step_index == 0:  # a padding entry
                    continue
                q = step.pose.orientation
                targets[int(step.step_index)] = StepTarget(
                    int(step.step_index), int(step.foot_index), float(step.pose.position.x),
                    float(step.pose.position.y), _yaw_of_xyzw(q.x, q.y, q.z, q.w))
    except (KeyError, ValueError, AttributeError) as err:
        raise BagAnalysisError(f'Could not read the WALK commands of {data.path}: {err}') \
            from err
    finally:
        records.close()
    return [targets[index] for index in sorted(targets)], first_walk_s


def landings(foot_index: int, t_s: np.ndarray, position_m: np.ndarray, yaw_rad: np.ndarray,
             standing_m: float) -> list[Landing]:
    """The times a foot came down again after its first stance, and its pose then: `t_s`
    (n,), the foot link's world `position_m` (n, 3) and `yaw_rad` (n,) over a run; the link
    is down within PLANTED_HEIGHT_M of `standing_m`, its height with the sole flat on the
    ground (or below it: a foot on its edge after a fall is down too)."""
    if len(t_s) == 0:
        return []
    down = position_m[:, 2] <= standing_m + PLANTED_HEIGHT_M
    edges = np.flatnonzero(np.diff(down.astype(np.int8)))
    starts = ([0] if down[0] else []) + [int(i) + 1 for i in edges if not down[i]]
    found = []
    for number, start in enumerate(starts):
        ups = np.flatnonzero(~down[start:])
        end = start + int(ups[0]) if len(ups) else len(t_s)
        if t_s[end - 1] - t_s[start] < MIN_PLANTED_S and end < len(t_s):
            continue  # a scuff, not a stance
        if number == 0 and start == 0:
            continue  # standing there before the walk
        at = min(int(np.searchsorted(t_s, t_s[start] + LANDING_SETTLE_S)), end - 1)
        found.append(Landing(foot_index, float(t_s[start]), float(position_m[at, 0]),
                             float(position_m[at, 1]), float(yaw_rad[at])))
    return found


def match_landings(targets: list[StepTarget],
                   by_foot: list[list[Landing]]) -> list[tuple[StepTarget, Landing | None]]:
    """Each step asked for (in step order) with its foot's landing, in time order: the
    nearest to its target of the foot's next MATCH_WINDOW landings not yet matched (a step
    whose command the recorder missed, or an extra landing after a stumble, then shifts
    nothing); None once the foot has no landing left."""
    placements: list[tuple[StepTarget, Landing | None]] = []
    taken = [0, 0]
    for target in targets:
        foot = target.foot_index if target.foot_index in (0, 1) else 0
        candidates = by_foot[foot][taken[foot]:taken[foot] + MATCH_WINDOW]
        if not candidates:
            placements.append((target, None))
            continue
        nearest = min(range(len(candidates)), key=lambda k: np.hypot(
            candidates[k].x_m - target.x_m, candidates[k].y_m - target.y_m))
        placements.append((target, candidates[nearest]))
        taken[foot] += nearest + 1
    return placements


def foot_poses(data: BagData, since_s: float, until_s: float = np.inf
                ) -> tuple[np.ndarray, list[np.ndarray], list[np.ndarray], float, SoleBox]:
    """Times (n,) at KINEMATICS_RATE_HZ from `since_s`, per foot its link's world positions
    (n, 3) and yaws (n,) from the recorded pose, the links' height (m) with the soles
    flat on the ground (the Stand pose placed on it), and the model's sole box."""
    pelvis, states = data.pelvis, data.joint_states
    assert pelvis is not None and states is not None
    kinematics = RecordedKinematics(data)
    from tutorial_atlas_control.balance import (  # noqa: PLC0415 - they import mujoco
        SoleBox,
        place_in_stand_pose,
    )

    bodies = [kinematics.body_id(name) for name in FOOT_BODIES]
    place_in_stand_pose(kinematics.atlas, kinematics.data)  # the soles flat on the ground
    standing_m = float(kinematics.data.xpos[bodies[0]][2])
    end_s = min(float(pelvis.t_s[-1]), float(states.t_s[-1]), until_s)
    t_s = np.arange(max(since_s, float(pelvis.t_s[0]), float(states.t_s[0])), end_s,
                    1.0 / KINEMATICS_RATE_HZ)
    positions = [np.empty((len(t_s), 3)) for _ in bodies]
    yaws = [np.empty(len(t_s)) for _ in bodies]
    for row, at_s in enumerate(t_s):
        placed = kinematics.place(float(at_s))
        for foot, body in enumerate(bodies):
            positions[foot][row] = placed.xpos[body]
            xmat = placed.xmat[body]
            yaws[foot][row] = np.arctan2(xmat[3], xmat[0])
    return t_s, positions, yaws, standing_m, SoleBox.of(kinematics.atlas.model)


def summarise_walk(data: BagData, window_s: tuple[float, float] | None = None
                   ) -> WalkSummary | None:
    """The walk in `data`'s bag (with `window_s`, the one in that window, s from the bag's
    start); None when it holds no WALK command or no recorded pose."""
    targets, first_walk_s = read_step_targets(data, window_s)
    pelvis = data.pelvis
    if first_walk_s is None or pelvis is None or data.joint_states is None \
            or not len(pelvis.t_s) or not len(data.joint_states.t_s):
        return None
    until_s = np.inf if window_s is None else window_s[1]
    t_s, positions, yaws, standing_m, sole = foot_poses(data, first_walk_s, until_s)
    heights = terrain_heights() if is_course_run(data) else None  # the course's ground
    by_foot = [landings(foot, t_s, above_ground(positions[foot], heights), yaws[foot],
                        standing_m) for foot in (0, 1)]
    placements = match_landings(targets, by_foot)
    walking = (pelvis.t_s >= first_walk_s) & (pelvis.t_s <= until_s)
    path = pelvis.position_m[walking]
    distance = float(np.hypot(*(path[-1, :2] - path[0, :2]))) if len(path) else None
    # Over the ground under it: walking in the course's mud pit, 0.6 m down, is no fall.
    lowest = float(above_ground(path, heights)[:, 2].min()) if len(path) else None
    travel = [_travel(positions[foot][0, :2] if len(t_s) else None, by_foot[foot])
              for foot in (0, 1)]
    return WalkSummary(placements, distance, lowest is not None and fallen(lowest),
                       lowest, path[:, :2].copy(), path_m=float(np.mean(travel)), sole=sole)


def _travel(start_xy: np.ndarray | None, landed: list[Landing]) -> float:
    """How far a foot went from `start_xy` through its landings (m)."""
    points = ([start_xy] if start_xy is not None else []) + [
        np.array([landing.x_m, landing.y_m]) for landing in landed]
    return float(sum(np.hypot(*(b - a)) for a, b in zip(points, points[1:])))


def titled_walks(data: BagData, changes: list[BehaviourChange] | None
                 ) -> list[tuple[str, WalkSummary]]:
    """Each walk of `data`'s run, titled: by the recorded behaviours' walk windows
    (`changes`, read_behaviours's; a client's step indices start at 1 again each walk), else
    the bag's WALK commands as one."""
    if changes is not None:
        found = []
        for number, window in enumerate(walk_windows(changes), 1):
            each = summarise_walk(data, window)
            if each is not None:
                end = 'the end' if window[1] == float('inf') else f'{window[1]:.1f} s'
                found.append((f'Walk {number} (from {window[0]:.1f} s to {end}):', each))
        return found
    walk = summarise_walk(data)
    return [] if walk is None else [('Walk (the bag\'s WALK commands):', walk)]


def walk_lines(summary: WalkSummary) -> list[str]:
    """The lines on a walk: steps and how far, placement as bias and scatter, falls."""
    asked = len(summary.placements)
    went = []
    if summary.path_m is not None:
        went.append(f'walked {summary.path_m:.2f} m')
    if summary.distance_m is not None:
        went.append(f'ended {summary.distance_m:.2f} m from where the walk began')
    lines = [f'walk: {summary.steps_taken} of {asked} steps taken'
             + (f'; {", ".join(went)}' if went else '')]
    bias, scatter, worst = (summary.placement_bias_m, summary.placement_scatter_m,
                            summary.worst_placement)
    if bias is not None and scatter is not None and worst is not None:
        ahead, left = bias
        lines.append(f'walk: landings {_signed_cm(ahead, "ahead", "behind")} and '
                     f'{_signed_cm(left, "left", "right")} of the steps asked for on average, '
                     f'scatter {scatter * 100:.1f} cm; worst placement {worst[0] * 100:.1f} cm '
                     f'and {worst[1]:.3f} rad from the step asked for')
    lowest = '' if summary.lowest_pelvis_m is None else \
        f' (lowest pelvis {summary.lowest_pelvis_m:.3f} m)'
    lines.append(f'walk: {"FELL" if summary.fell else "no fall"}{lowest}')
    return lines


def _signed_cm(value_m: float, positive: str, negative: str) -> str:
    return f'{abs(value_m) * 100:.1f} cm {positive if value_m >= 0 else negative}'


def plot_footprints(summary: WalkSummary, path: Path) -> Path:
    """The footprints seen from above: each step asked for (outline) and where the foot came
    down (filled), with the pelvis's path; written to `path` (PNG)."""
    import matplotlib  # noqa: PLC0415 - only the plot needs it
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt  # noqa: PLC0415
    from matplotlib.patches import Rectangle  # noqa: PLC0415

    colours = ('tab:blue', 'tab:red')
    points = np.vstack([summary.pelvis_xy.reshape(-1, 2),
                        [(t.x_m, t.y_m) for t, _ in summary.placements] or np.zeros((0, 2))])
    span = np.ptp(points, axis=0) + 0.6 if len(points) else np.ones(2)
    width = 9.0
    figure, ax = plt.subplots(figsize=(width, float(np.clip(width * span[1] / span[0], 1.6,
                                                                 8.0)) + 1.4))
    ax.plot(summary.pelvis_xy[:, 0], summary.pelvis_xy[:, 1], color='0.6', lw=1,
            label='pelvis')
    sole = summary.sole or _model_sole()
    for target, landing in summary.placements:
        colour = colours[target.foot_index % 2]
        ax.add_patch(sole_patch(sole, target.x_m, target.y_m, target.yaw_rad, Rectangle,
                           fill=False, edgecolor=colour, lw=1))
        if landing is not None:
            ax.add_patch(sole_patch(sole, landing.x_m, landing.y_m, landing.yaw_rad, Rectangle,
                               facecolor=colour, alpha=0.35, edgecolor='none'))
    ax.plot([], [], color=colours[0], label='left foot: asked (outline), landed (filled)')
    ax.plot([], [], color=colours[1], label='right foot')
    ax.set_aspect('equal', adjustable='datalim')
    ax.autoscale_view()
    ax.set_xlabel('x (m)')
    ax.set_ylabel('y (m)')
    worst = summary.worst_placement
    title = f'{summary.steps_taken} of {len(summary.placements)} steps'
    if worst is not None:
        title += f', worst {worst[0] * 100:.1f} cm / {worst[1]:.3f} rad'
    ax.set_title(title + (', fell' if summary.fell else ''))
    figure.legend(loc='lower center', ncol=3, fontsize='small')
    figure.tight_layout(rect=(0.0, 0.08, 1.0, 1.0))
    figure.savefig(path, dpi=100)
    plt.close(figure)
    return path


def _model_sole() -> SoleBox:
    """The sole box of the model, for a summary made without one."""
    from tutorial_atlas_control.balance import SoleBox  # noqa: PLC0415 - imports mujoco
    from tutorial_atlas_control.sim import load_model  # noqa: PLC0415 - imports mujoco

    return SoleBox.of(load_model().model)


def sole_patch(sole: SoleBox, x_m: float, y_m: float, yaw_rad: float, rectangle: Any,
          **style: Any) -> Any:
    """The sole's rectangle for a foot link at (x, y, yaw)."""
    length, width = 2.0 * sole.half_length_m, 2.0 * sole.half_width_m
    c, s = np.cos(yaw_rad), np.sin(yaw_rad)
    centre = np.array([x_m + c * sole.ahead_m, y_m + s * sole.ahead_m])
    half_diagonal = np.array([c * length / 2 - s * width / 2, s * length / 2 + c * width / 2])
    corner = centre - half_diagonal  # matplotlib turns the rectangle about this corner
    return rectangle(tuple(corner), length, width, angle=float(np.degrees(yaw_rad)), **style)
