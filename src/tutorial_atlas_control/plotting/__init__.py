"""Live plots of topic fields (plot_topics.py, rqt_plot's arguments).

fields: rqt_plot's argument syntax, field paths checked against a message class, reading
the numbers out of a message; series: the rolling window of samples and the clock watch
that notices a reset; live: the plot's state fed with raw messages; figure: the matplotlib
drawing shared by the window and the PNG. No ROS, except the rospy side, plot_topics_node.py
(import it by its module).
"""

from tutorial_atlas_control.exports import lazy_exports

__all__, __getattr__, __dir__ = lazy_exports(__name__, {
    'fields': ['FieldReader', 'FieldStep', 'PlotError', 'expand_arguments', 'parse_field_path',
               'split_topic'],
    'figure': ['PlotFigure'],
    'live': ['LivePlot', 'PlotField'],
    'series': ['ClockWatch', 'RollingSeries'],
})
