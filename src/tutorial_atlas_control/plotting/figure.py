"""The drawing of a live plot on a matplotlib Figure: the window's and the PNG's alike.

plot_topics_node.py hands it a pyplot figure on the Tk backend (the window) or a plain
Figure on Agg (--png); `update` sets the lines, the time axis (the last `window_s` seconds
of ROS time), the y range and the legend, and the caller draws or saves.
"""

from __future__ import annotations

import math

import numpy as np

from tutorial_atlas_control.plotting.live import LivePlot

__all__ = ['PlotFigure', 'y_range']

#: Room (fraction of the data's span) left above and below the data when autoscaling.
Y_MARGIN = 0.05
#: A flat line's y range: its value +- this much, or +- this fraction of it if larger.
FLAT_HALF_SPAN = 0.5
FLAT_RELATIVE_HALF_SPAN = 0.1
LINE_WIDTH = 1.5
#: Legend entries per row, above the axes, and a row's height (fraction of the figure).
LEGEND_COLUMNS = 2
LEGEND_ROW_HEIGHT = 0.05
LAYOUT_TOP = 0.99


def y_range(values: list[np.ndarray]) -> tuple[float, float] | None:
    """The y limits that show every finite value in `values` (None: there is none)."""
    finite = [v[np.isfinite(v)] for v in values]
    finite = [v for v in finite if len(v)]
    if not finite:
        return None
    low = min(float(v.min()) for v in finite)
    high = max(float(v.max()) for v in finite)
    if high - low <= 0.0:
        half = max(FLAT_HALF_SPAN, abs(low) * FLAT_RELATIVE_HALF_SPAN)
        return low - half, high + half
    margin = (high - low) * Y_MARGIN
    return low - margin, high + margin


class PlotFigure:
    """One axes with a line and a legend entry per plotted argument."""

    def __init__(self, figure: object, plot: LivePlot, time_label: str) -> None:
        self.figure = figure
        self.plot = plot
        self.axes = figure.add_subplot(1, 1, 1)
        # A fixed layout (constrained layout costs a third of each frame): the legend's rows
        # above the axes, the time label and the status line below.
        rows = math.ceil(len(plot.fields) / LEGEND_COLUMNS)
        figure.subplots_adjust(left=0.08, right=0.98, bottom=0.16,
                               top=LAYOUT_TOP - LEGEND_ROW_HEIGHT * rows)
        self.axes.set_xlabel(time_label)
        self.axes.grid(True, alpha=0.3)
        self.lines = {}
        for plot_field in plot.fields:
            (line,) = self.axes.plot([], [], label=plot_field.argument, linewidth=LINE_WIDTH)
            self.lines[plot_field.argument] = line
        self.status = self.axes.text(1.0, -0.12, '', transform=self.axes.transAxes,
                                     ha='right', va='top', color='tab:red')
        self._legend_for: tuple[tuple[str, str, bool], ...] = ()
        self._refresh_legend()

    def update(self, *, autoscale: bool = True, paused: bool = False) -> None:
        """Show the plot's samples as they are now."""
        plot = self.plot
        now_s = plot.now_s
        start_s = now_s - plot.window_s
        shown = []
        for plot_field in plot.fields:
            line = self.lines[plot_field.argument]
            if not plot_field.plotted:
                line.set_data([], [])
                line.set_visible(False)
                continue
            times, values = plot_field.series.times_s, plot_field.series.values
            line.set_data(times, values)
            shown.append(values[times >= start_s])
        self._refresh_legend()
        # The axis starts at 0 (sim time's start, or the plotter's) until a window has passed.
        left_s = max(start_s, 0.0)
        self.axes.set_xlim(left_s, left_s + plot.window_s)
        if autoscale:
            limits = y_range(shown)
            if limits is not None and all(math.isfinite(x) for x in limits):
                self.axes.set_ylim(*limits)
        notes = [note for note, on in (('PAUSED', paused), ('autoscale off', not autoscale))
                 if on]
        self.status.set_text('  '.join(notes))

    def _refresh_legend(self) -> None:
        """The legend above the axes (it never hides data): one entry per plotted argument,
        `(no data yet)` after those without a sample."""
        entries = tuple((f.argument, f.label, f.samples > 0) for f in self.plot.fields
                        if f.plotted)
        if entries == self._legend_for:
            return
        self._legend_for = entries
        units = sorted({f.unit for f in self.plot.fields if f.plotted and f.unit})
        self.axes.set_ylabel(', '.join(units))
        legend = self.axes.get_legend()
        if legend is not None:
            legend.remove()
        if entries:
            self.axes.legend(
                handles=[self.lines[argument] for argument, _, _ in entries],
                labels=[label if has_data else f'{label} (no data yet)'
                        for _, label, has_data in entries],
                loc='lower left', bbox_to_anchor=(0.0, 1.01), ncols=LEGEND_COLUMNS,
                fontsize='small', frameon=False, borderaxespad=0.0)
