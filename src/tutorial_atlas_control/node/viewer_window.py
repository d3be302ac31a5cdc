"""The simulator node's viewer window: opened beside the stepping loop, refreshed and
paced by a thread of its own, its Reset and pause keys turned into the loop's.

(viewer.py holds the window itself: a shadow of the physics data, never the data.)
"""

from __future__ import annotations

import os
import threading
import time

import rospy

from tutorial_atlas_control.node.viewer import ViewerLink, ViewerRequest, display_problem
from tutorial_atlas_control.sim import (
    AtlasSimulator,
    configure_viewer_camera,
    configure_viewer_scene,
)
from tutorial_atlas_control.stepping import SteppingLoop

__all__ = ['VIEWER_FRAME_PERIOD_S', 'open_viewer']

#: The viewer draws at most one frame per VIEWER_FRAME_PERIOD_S (s, wall): left alone, its
#: render thread draws as fast as it can, and with software OpenGL (no GPU, Xvfb) that took
#: the CPU the simulation needs. The pause is VIEWER_HOLD_S of it; the rest is its turn.
VIEWER_FRAME_PERIOD_S = 1.0 / 30.0
VIEWER_TURN_S = 0.005
VIEWER_HOLD_S = VIEWER_FRAME_PERIOD_S - VIEWER_TURN_S


def open_viewer(sim: AtlasSimulator, loop: SteppingLoop) -> ViewerLink | None:
    """The viewer window, framing the whole robot and following the pelvis, kept up to
    date by a thread of its own; None (and one warning) when it cannot open."""
    problem = display_problem(os.environ.get('DISPLAY'))
    if problem is not None:
        rospy.logwarn(f'cannot open the MuJoCo viewer: {problem}; running headless, '
                      'recording on (gui:=false starts without trying)')
        return None
    try:
        link = ViewerLink(sim.model)
    except Exception as err:  # noqa: BLE001 - no display, no GL: run headless
        rospy.logwarn(f'cannot open the MuJoCo viewer ({err}); running headless')
        return None
    with loop.lock:
        link.copy_in(sim.data)
    with link.handle.lock():
        configure_viewer_camera(link.handle.cam, sim.model, link.shadow)
        configure_viewer_scene(link.handle.user_scn)
    threading.Thread(target=_viewer_loop, args=(link, sim, loop), name='viewer',
                     daemon=True).start()
    return link


def _viewer_loop(viewer: ViewerLink, sim: AtlasSimulator, loop: SteppingLoop) -> None:
    """Refresh the window and pace its drawing, outside the stepping loop."""
    while not rospy.is_shutdown() and _update_viewer(viewer, sim, loop):
        viewer.hold(VIEWER_HOLD_S)  # its render thread waits at the top of its next frame
        time.sleep(VIEWER_TURN_S)


def _update_viewer(viewer: ViewerLink, sim: AtlasSimulator, loop: SteppingLoop) -> bool:
    """Refresh the window and carry out what was asked in it; False once it is closed.

    The lock is held only to copy the state in and the mouse forces out: the sync
    itself waits for the viewer's thread, which must not stall services and commands.
    """
    if not viewer.is_running():
        rospy.signal_shutdown('viewer closed')
        return False
    with loop.lock:
        viewer.copy_in(sim.data)
    viewer.sync()
    with loop.lock:
        viewer.copy_out(sim.data)
    for request in viewer.take_requests():
        if request is ViewerRequest.RESET_WORLD:
            loop.reset_world(by=' (viewer)')
        elif loop.paused:  # ViewerRequest.TOGGLE_PAUSE
            loop.unpause()
        else:
            loop.pause()
    viewer.show_paused(loop.paused)
    return True
