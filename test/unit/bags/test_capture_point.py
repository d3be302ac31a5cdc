"""bags/capture_point.py's arithmetic: the capture point of a sampled path, the support
polygon of the soles that touch, the margin, and its plot."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from tutorial_atlas_control.bags.capture_point import (
    CaptureTrace,
    capture_points,
    margins,
    plot_capture,
    support_polygon,
    touching_soles,
)

#: A sole box's 4 bottom corners: 0.26 x 0.125 m, 0.05 m thick, its centre at (x, y, z).
HALF = np.array([0.13, 0.0625, 0.025])
SIGNS = np.array([[1, 1, -1], [1, -1, -1], [-1, -1, -1], [-1, 1, -1]], dtype=np.float64)
CONTACT_M = 0.01


def sole(x_m: float, y_m: float, lifted_m: float = 0.0) -> np.ndarray:
    return np.array([x_m, y_m, HALF[2] + lifted_m]) + SIGNS * HALF


def test_a_com_moving_at_constant_speed_has_its_capture_point_ahead_by_v_over_omega() -> None:
    dt_s, speed = 0.01, 0.3
    t_s = np.arange(0.0, 1.0, dt_s)
    com = np.column_stack([speed * t_s, np.zeros_like(t_s), np.full_like(t_s, 0.981)])
    ahead = capture_points(com, dt_s)[:, 0] - com[:, 0]
    assert ahead == pytest.approx(np.full_like(t_s, speed / math.sqrt(10.0)), rel=1e-9)
    still = capture_points(com[:, :] * [0.0, 1.0, 1.0], dt_s)
    assert still == pytest.approx(np.zeros((len(t_s), 2)))


def polygon(*soles: np.ndarray) -> np.ndarray:
    corners = np.array(soles)
    return support_polygon(corners, touching_soles(corners, CONTACT_M))


def test_the_polygon_holds_the_soles_that_touch() -> None:
    both = polygon(sole(0.0, 0.12), sole(0.0, -0.12))
    assert np.ptp(both, axis=0) == pytest.approx([0.26, 0.365])
    left_only = polygon(sole(0.0, 0.12), sole(0.2, -0.12, 0.05))
    assert np.ptp(left_only, axis=0) == pytest.approx([0.26, 0.125])
    assert touching_soles(np.array([sole(0.0, 0.12), sole(0.2, -0.12, 0.05)]), CONTACT_M) == [0]
    assert len(polygon(sole(0.0, 0.12, 0.3), sole(0.0, -0.12, 0.3))) == 0


def test_the_margin_is_signed_and_nan_in_the_air() -> None:
    both = polygon(sole(0.0, 0.12), sole(0.0, -0.12))
    found = margins(np.array([[0.0, 0.0], [0.23, 0.0], [0.0, 0.0]]),
                    [both, both, np.zeros((0, 2))])
    assert found[0] == pytest.approx(0.13)  # the heels and toes are nearer than the sides
    assert found[1] == pytest.approx(-0.10)
    assert math.isnan(found[2])


def test_the_margin_is_plotted(tmp_path: Path) -> None:
    t_s = np.linspace(0.0, 4.0, 401)
    margin = 0.05 * np.cos(2.0 * t_s)
    trace = CaptureTrace(t_s, np.zeros((401, 2)), np.zeros((401, 2)), [np.zeros((0, 2))] * 401,
                         np.where(t_s > 2.0, 1, 2), margin)
    assert trace.outside_fraction == pytest.approx(np.mean(margin < 0.0))
    path = plot_capture(trace, tmp_path / 'run.capture.png')
    assert path.read_bytes()[:8] == b'\x89PNG\r\n\x1a\n'
    assert path.stat().st_size > 10_000
