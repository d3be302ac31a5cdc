"""Live plots of topic fields (plot_topics.py, rqt_plot's arguments): no ROS.

fields: rqt_plot's argument syntax, field paths checked against a message class, reading
the numbers out of a message; series: the rolling window of samples and the clock watch
that notices a reset; live: the plot's state fed with raw messages; figure: the matplotlib
drawing shared by the window and the PNG. The rospy side is node/plot_topics.py.
"""
