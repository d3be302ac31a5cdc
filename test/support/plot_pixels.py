"""Whether a picture of plot_topics.py (its window or its PNG) shows a curve, or its status
note (PAUSED), from its pixels.

A curve in the first line colour (matplotlib's tab:blue, the first argument's) shows as
pixels of that colour in most of the picture's columns (it runs across the time axis) and
in many of its rows (autoscale stretches a moving value over the axes' height). A flat line
covers columns but few rows; an empty plot has only the legend's short swatch; both fail.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: matplotlib's first colour (tab:blue), the first argument's line.
LINE_RGB = (31, 119, 180)
#: A pixel within this distance (RGB, 0..255) is the line's; anti-aliased edges blend with
#: the white background and are left out.
COLOUR_TOLERANCE = 40
#: A curve: line pixels in at least this share of the picture's columns (the axes span
#: about 90 % of the width; the legend's swatch is under 5 %) and of its rows (a sine
#: autoscaled fills most of the axes' height, about 60 % of the window's; a flat line and
#: the swatch are a few rows).
MIN_COLUMNS_FRACTION = 0.6
MIN_ROWS_FRACTION = 0.25
#: The status note's colour (tab:red: PAUSED, autoscale off; nothing else is drawn in it),
#: and the pixels of it that make a note: PAUSED at the window's size has about 110, none
#: without it.
STATUS_RGB = (214, 39, 40)
MIN_STATUS_PIXELS = 40


@dataclass(frozen=True)
class CurveExtent:
    """Shares of the picture's columns and rows holding pixels of the line's colour."""

    columns_fraction: float
    rows_fraction: float

    def shows_a_curve(self) -> bool:
        return (self.columns_fraction >= MIN_COLUMNS_FRACTION
                and self.rows_fraction >= MIN_ROWS_FRACTION)


def _of_colour(pixels: np.ndarray, rgb: tuple[int, int, int]) -> np.ndarray:
    """Which of `pixels` ((height, width, 3) uint8 RGB) are within COLOUR_TOLERANCE of `rgb`."""
    distance = np.linalg.norm(pixels[..., :3].astype(float) - np.asarray(rgb, float), axis=2)
    return distance <= COLOUR_TOLERANCE


def curve_extent(pixels: np.ndarray, rgb: tuple[int, int, int] = LINE_RGB) -> CurveExtent:
    """The extent of `rgb` in `pixels` ((height, width, 3) uint8 RGB)."""
    line = _of_colour(pixels, rgb)
    height, width = line.shape
    return CurveExtent(float(line.any(axis=0).sum()) / width,
                       float(line.any(axis=1).sum()) / height)


def shows_status_note(pixels: np.ndarray) -> bool:
    """Whether the window shows its status note (PAUSED, or autoscale off)."""
    return int(np.count_nonzero(_of_colour(pixels, STATUS_RGB))) >= MIN_STATUS_PIXELS
