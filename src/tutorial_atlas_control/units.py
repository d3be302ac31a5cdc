"""Units and number checks used across the package."""

from __future__ import annotations

import math

#: Sim time is counted in integer nanoseconds so that stamps stay exact.
NS_PER_S = 1_000_000_000


def finite_number(value: object, allow_text: bool = False) -> float | None:
    """`value` as a finite float, or None if it is not a finite number.

    Booleans are not numbers (YAML's `yes` and rosparam's `true` must not pass as 1.0);
    text counts only with `allow_text` (the tutorial's waypoints are space-separated strings).
    """
    if isinstance(value, bool):
        return None
    if isinstance(value, (int, float)) or (allow_text and isinstance(value, str)):
        try:
            number = float(value)
        except (ValueError, OverflowError):
            return None
        return number if math.isfinite(number) else None
    return None
