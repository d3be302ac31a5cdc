"""keyboard_teleop.py draws with curses: rospy's terminal output is taken off the screen
(a log line from actionlib once broke a screen line in two), its log file output kept."""

from __future__ import annotations

import logging
from pathlib import Path

import pytest

pytest.importorskip('atlas_msgs.msg', reason='needs the catkin workspace: source ./env.sh')
from rosgraph.roslogging import RosStreamHandler

from tutorial_atlas_control.cli.keyboard_teleop import keep_logs_off_the_screen


def test_the_terminal_handler_goes_and_the_file_stays(tmp_path: Path) -> None:
    logger = logging.getLogger('rosout.test_teleop_logging')
    to_file = logging.FileHandler(tmp_path / 'node.log')
    to_terminal = RosStreamHandler(colorize=False)
    logger.addHandler(to_file)
    logger.addHandler(to_terminal)
    try:
        assert keep_logs_off_the_screen(logger) == 1
        assert logger.handlers == [to_file]
        assert keep_logs_off_the_screen(logger) == 0
    finally:
        for handler in list(logger.handlers):
            logger.removeHandler(handler)
        to_file.close()
