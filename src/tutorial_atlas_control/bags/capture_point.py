"""The capture point against the support polygon over a recorded run (the walk's third plot).

A robot can come to rest without a step exactly while its capture point (the linear
inverted pendulum's, balance/lipm.py) is inside its support polygon; walking, it leaves the
stance foot's polygon every step and is caught by the next. The margin, the capture point's
signed distance inside the hull of the touching soles, shows how near each moment came to
needing a step, and a fall as a margin that no step brought back.

From the bag's recorded pose placed on the model (bags/feet.RecordedKinematics), at
CAPTURE_RATE_HZ: the centre of mass, its velocity by central differences, and the soles
touching where their lowest corner is within the estimator's CONTACT_HEIGHT_M of the ground
(the flat world's, at z = 0).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from tutorial_atlas_control.bags.reader import BagData
from tutorial_atlas_control.balance import (
    capture_point,
    convex_hull,
    natural_frequency,
    signed_distance,
)

#: How often the recorded pose is sampled (Hz): /ground_truth_odom's rate.
CAPTURE_RATE_HZ = 100.0


@dataclass(frozen=True)
class CaptureTrace:
    """The capture point over a run: times (s from the bag's start), the centre of mass
    and the capture point on the ground (n, 2), the support polygon at each time, how many
    soles touched (n,) and the margin (m: positive inside, negative outside; NaN while no
    sole touches)."""

    t_s: np.ndarray
    com_xy: np.ndarray
    capture_xy: np.ndarray
    polygons: list[np.ndarray]
    soles_down: np.ndarray
    margin_m: np.ndarray

    @property
    def outside_fraction(self) -> float:
        """The share of the times a sole touched with the capture point outside."""
        touching = ~np.isnan(self.margin_m)
        return float(np.mean(self.margin_m[touching] < 0.0)) if touching.any() else 0.0


def capture_points(com_m: np.ndarray, dt_s: float) -> np.ndarray:
    """The capture points (n, 2) of a centre-of-mass path `com_m` (n, 3) sampled every
    `dt_s`: xi = c + c' / omega, c' by central differences (one-sided at the ends)."""
    if len(com_m) < 2:
        return com_m[:, :2].copy()
    from tutorial_atlas_control.balance import MIN_COM_HEIGHT_M  # noqa: PLC0415 - mujoco

    velocity = np.gradient(com_m[:, :2], dt_s, axis=0)
    omega = np.array([natural_frequency(max(float(z), MIN_COM_HEIGHT_M)) for z in com_m[:, 2]])
    return capture_point(com_m[:, :2], velocity, omega[:, None])


def support_polygon(corners_m: np.ndarray, touching: list[int]) -> np.ndarray:
    """The hull (k, 2) of the bottom corners (2, 4, 3) of the `touching` soles
    (touching_soles); (0, 2) if none does."""
    if not touching:
        return np.zeros((0, 2))
    return convex_hull(corners_m[touching, :, :2].reshape(-1, 2))


def touching_soles(corners_m: np.ndarray, contact_height_m: float) -> list[int]:
    """The soles (0 left, 1 right) whose lowest bottom corner (of (2, 4, 3)) is within
    `contact_height_m` of the ground."""
    return [foot for foot in (0, 1) if float(corners_m[foot, :, 2].min()) < contact_height_m]


def margins(capture_xy: np.ndarray, polygons: list[np.ndarray]) -> np.ndarray:
    """Each capture point's signed distance inside its polygon (m); NaN without one."""
    return np.array([signed_distance(polygon, point) if len(polygon) >= 3 else np.nan
                     for point, polygon in zip(capture_xy, polygons)], dtype=np.float64)


def capture_trace(data: BagData, since_s: float = 0.0, until_s: float = np.inf
                  ) -> CaptureTrace | None:
    """The capture point over the bag between `since_s` and `until_s` (s from its start);
    None without a recorded pose and joint states to place the model with."""
    pelvis, states = data.pelvis, data.joint_states
    if pelvis is None or states is None or not len(pelvis.t_s) or not len(states.t_s):
        return None
    from tutorial_atlas_control.bags.feet import RecordedKinematics  # noqa: PLC0415 - mujoco

    kinematics = RecordedKinematics(data)
    import mujoco  # noqa: PLC0415 - after RecordedKinematics has prepared GL

    from tutorial_atlas_control.balance import (  # noqa: PLC0415 - they import mujoco
        CONTACT_HEIGHT_M,
        SOLE_GEOMS,
        sole_corners,
    )

    model = kinematics.atlas.model
    start_s = max(since_s, float(pelvis.t_s[0]), float(states.t_s[0]))
    end_s = min(until_s, float(pelvis.t_s[-1]), float(states.t_s[-1]))
    dt_s = 1.0 / CAPTURE_RATE_HZ
    t_s = np.arange(start_s, end_s, dt_s)
    com = np.empty((len(t_s), 3))
    soles_down = np.zeros(len(t_s), dtype=np.int64)
    polygons = []
    for row, at_s in enumerate(t_s):
        placed = kinematics.place(float(at_s))
        mujoco.mj_comPos(model, placed)
        com[row] = placed.subtree_com[0]
        corners = np.array([sole_corners(model, placed, name) for name in SOLE_GEOMS])
        touching = touching_soles(corners, CONTACT_HEIGHT_M)
        polygons.append(support_polygon(corners, touching))
        soles_down[row] = len(touching)
    capture = capture_points(com, dt_s)
    return CaptureTrace(t_s, com[:, :2].copy(), capture, polygons, soles_down,
                        margins(capture, polygons))


def plot_capture(trace: CaptureTrace, path: Path) -> Path:
    """The capture point's margin in the support polygon over time (below zero: outside,
    a step needed), with when one foot or both touched; written to `path` (PNG)."""
    import matplotlib  # noqa: PLC0415 - only the plot needs it
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt  # noqa: PLC0415

    margin_cm = trace.margin_m * 100.0
    figure, ax = plt.subplots(figsize=(10.0, 4.0))
    single = trace.soles_down == 1
    if single.any():  # underneath what is drawn over it
        ax.fill_between(trace.t_s, 0.0, 1.0, where=single, transform=ax.get_xaxis_transform(),
                        color='0.88', lw=0, zorder=0, label='one foot down')
    ax.axhline(0.0, color='black', lw=0.8)
    outside = np.nan_to_num(margin_cm, nan=0.0) < 0.0
    ax.fill_between(trace.t_s, margin_cm, 0.0, where=outside, color='tab:red', alpha=0.35,
                    lw=0, label='outside: a step must catch it')
    ax.plot(trace.t_s, margin_cm, color='tab:blue', lw=1,
            label='capture point inside the support polygon (cm)')
    ax.set_xlabel('time from the bag\'s start (s)')
    ax.set_ylabel('margin (cm)')
    ax.set_title(f'the capture point against the support polygon: outside '
                 f'{trace.outside_fraction:.0%} of the time a foot was down')
    figure.legend(loc='lower center', fontsize='small', ncol=3)
    figure.tight_layout(rect=(0.0, 0.08, 1.0, 1.0))
    figure.savefig(path, dpi=100)
    plt.close(figure)
    return path
