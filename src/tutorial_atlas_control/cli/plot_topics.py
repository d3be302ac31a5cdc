"""Command line of plot_topics.py: live plots of topic fields, with rqt_plot's arguments.

Debian 12 packages no rqt, so DRCSim's tutorials' `rqt_plot /atlas/joint_states/position[3]`
is "command not found"; `rosrun tutorial_atlas_control plot_topics.py` takes the same
arguments. Exit status: 0 when the window was closed (or the picture written) with every
argument plotted; 1 when refused (no master, no display, an unwritable PNG, nothing to
plot) or when an argument could not be plotted (a bad or non-numeric field, no message:
one line each, the others are plotted and the PNG written); 2 for a bad command line;
130 on Ctrl-C.
"""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Sequence
from pathlib import Path

from tutorial_atlas_control.cli.convention import (
    EXIT_INTERRUPTED,
    EXIT_REFUSED,
    argument_type,
    print_error,
)
from tutorial_atlas_control.plotting import PlotError, expand_arguments, parse_field_path
from tutorial_atlas_control.plotting import plot_topics_node as plot_topics

PROG = 'plot_topics.py'
DEFAULT_WINDOW_S = 10.0

EPILOG = '''\
examples:
  plot_topics.py /atlas/joint_states/position[19]
  plot_topics.py /atlas/controller_statistics/command_age:command_age_mean
  plot_topics.py /ground_truth_odom/pose/pose/position/x:y:z --window 30
  plot_topics.py /atlas/joint_states/position[19] --png elbow.png --duration 5

In the window: space pauses and resumes, a turns autoscale off and on; matplotlib's toolbar
zooms and saves. Time is ROS time (sim time under /use_sim_time); a reset of sim time back
to 0 clears the plot. Messages with a header are placed at their stamp, others at receipt.
'''


def _seconds(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and value > 0.0):
        raise PlotError(f'{text!r} must be a finite number of seconds > 0')
    return value


def _argument(text: str) -> str:
    """One TOPIC/FIELD word, its syntax checked (the topic/field split needs the master)."""
    for name in expand_arguments([text]):
        parse_field_path(name.strip('/'))
    return text


def parse_args(argv: Sequence[str] | None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(
        prog=PROG, description='Plot numeric fields of ROS topics live, as rqt_plot did.',
        epilog=EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('arguments', nargs='+', metavar='TOPIC/FIELD',
                        type=argument_type(_argument),
                        help='TOPIC/FIELD, TOPIC/FIELD[INDEX], TOPIC/FIELD1:FIELD2, nested '
                             'TOPIC/FIELD/SUBFIELD; all in one plot')
    parser.add_argument('--window', type=argument_type(_seconds), metavar='S',
                        help='seconds of ROS time shown (default: --duration with --png, else '
                             f'{DEFAULT_WINDOW_S:g})')
    parser.add_argument('--png', type=Path, metavar='OUT.png',
                        help='no window: write the plot to OUT.png after --duration and exit')
    parser.add_argument('--duration', type=argument_type(_seconds), metavar='S',
                        help='seconds of ROS time to plot before the picture is written (or the '
                             'window closed); default with --png: --window')
    return parser.parse_args(argv)


def window_s(args: argparse.Namespace) -> float:
    """--window, else for a picture (--png) --duration, so that it fills the time axis."""
    if args.window is not None:
        return float(args.window)
    if args.png is not None and args.duration is not None:
        return float(args.duration)
    return DEFAULT_WINDOW_S


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of scripts/plot_topics.py."""
    args = parse_args(argv)
    options = plot_topics.PlotOptions(expand_arguments(args.arguments), window_s(args),
                                      args.png, args.duration)
    try:
        plot_topics.require_master()
        not_plotted = plot_topics.run_plot(options, plot_topics.stderr_line(PROG))
    except plot_topics.PlotRefused as err:
        print_error(PROG, err)
        return EXIT_REFUSED
    except KeyboardInterrupt:
        return EXIT_INTERRUPTED
    return EXIT_REFUSED if not_plotted else 0


if __name__ == '__main__':
    sys.exit(main())
