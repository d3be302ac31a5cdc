"""The MuJoCo viewer window as a view of the simulator node, never a second simulator.

MuJoCo's passive viewer acts on the MjData it is given: its "Reset" button and key
(Backspace) make the next ``sync()`` call ``mj_resetData`` on it, which would put the robot
at the model's qpos0 unpinned, rewind ``data.time`` to 0 and leave the controller's memory
and ``/atlas/sim_config`` stale. So the viewer never gets the physics data: it shows a
shadow copy, refreshed before each sync, and a reset it performs on the shadow is turned
into a request for the node's own ``reset_world`` (DRCSim's "Reset Model Poses"). Keys
the node adds, as Gazebo had them:

    Backspace, or the "Reset" button   reset_world (what /gazebo/reset_world does)
    Shift+Ctrl+R                       reset_world (Gazebo's "Reset Model Poses")
    Space                              pause / unpause physics and /clock
                                       (/gazebo/pause_physics, /gazebo/unpause_physics)

The window opens with the 3-D view filling it; MuJoCo's own keys show its panels: Tab the
left one (File, Option, Simulation with "Reset", ...), Shift+Tab the right one (joints,
controls).

The viewer's own Pause/Run switch is greyed out for a passive viewer (MuJoCo's choice); a
"PAUSED" overlay shows the node's state instead. Mouse perturbations (Ctrl+drag) still push
the robot: their forces are copied back to the physics data. Joint and control sliders only
display values: the next refresh overwrites an edit (the controller owns the joints).

Closing (ViewerLink.close) ends the window's thread before the node exits: the interpreter's
exit runs glfw.terminate (an atexit hook of mujoco.viewer), and a window still being
destroyed by its thread then is a segfault.
"""

from __future__ import annotations

import atexit
import ctypes
import ctypes.util
import enum
import threading
import time
from collections.abc import Callable

import mujoco
import numpy as np

__all__ = ['KEY_R', 'KEY_SPACE', 'ViewerLink', 'ViewerRequest', 'request_for_key']


class ViewerRequest(enum.Enum):
    """What the user asked for in the window; the node's loop carries it out."""

    RESET_WORLD = 'reset_world'
    TOGGLE_PAUSE = 'toggle_pause'


#: GLFW key codes (glfw.KEY_SPACE, glfw.KEY_R), named here so that the mapping can be
#: tested without a display.
KEY_SPACE = 32
KEY_R = 82
#: Modifier sets, as _glfw_modifiers() reports them.
SHIFT = 'shift'
CONTROL = 'control'
ALT = 'alt'
RESET_MODIFIERS = frozenset({SHIFT, CONTROL})
#: Written into the shadow's qacc_warmstart before each sync: mj_resetData (the viewer's
#: reset) zeroes that field, and nothing else on the shadow writes it (the shadow is never
#: stepped; mj_forward reads it only). Unlike data.time, it also tells a reset at t = 0.
RESET_CANARY = 1.0
#: Whether MuJoCo's left and right UI panels show when the window opens. Shown, the two
#: leave the robot about a third of a 1280-pixel-wide window; Tab and Shift+Tab (MuJoCo's
#: keys) toggle them.
PANELS_SHOWN_AT_OPEN = False
#: The overlay shown while physics is paused (left and right column).
PAUSED_TEXT = ('PAUSED', 'physics and /clock stopped; Space runs')
#: mujoco.viewer.launch_passive runs the window in a thread whose target is this function
#: of mujoco.viewer; Python names such a thread 'Thread-N (_launch_internal)'.
WINDOW_THREAD_TARGET = '_launch_internal'
#: How long close() waits for the window's thread to destroy the window (s, wall): it takes
#: one frame; beyond this the thread is hung and left to the interpreter's exit.
CLOSE_TIMEOUT_S = 10.0

Modifiers = Callable[[], frozenset[str]]
Launcher = Callable[..., object]


def _glfw_modifiers() -> frozenset[str]:
    """Modifier keys held now in the viewer's window (call from the viewer's thread).

    The passive viewer's key callback receives only the key code; its thread has the
    window's GL context current, so GLFW can be asked for the modifiers' state.
    """
    # The viewer's own GLFW binding, imported late: it needs a display library.
    import glfw  # noqa: PLC0415

    window = glfw.get_current_context()
    if not window:
        return frozenset()
    held = set()
    for name, keys in ((SHIFT, (glfw.KEY_LEFT_SHIFT, glfw.KEY_RIGHT_SHIFT)),
                       (CONTROL, (glfw.KEY_LEFT_CONTROL, glfw.KEY_RIGHT_CONTROL)),
                       (ALT, (glfw.KEY_LEFT_ALT, glfw.KEY_RIGHT_ALT))):
        if any(glfw.get_key(window, key) == glfw.PRESS for key in keys):
            held.add(name)
    return frozenset(held)


def _window_threads(before: set[threading.Thread]) -> list[threading.Thread]:
    """The threads a launch started, not in `before`, that run the window."""
    suffix = f'({WINDOW_THREAD_TARGET})'
    return [thread for thread in threading.enumerate()
            if thread not in before and thread.name.endswith(suffix)]


def request_for_key(key: int, modifiers: frozenset[str]) -> ViewerRequest | None:
    """The node's action for a key pressed in the window, if any."""
    if key == KEY_SPACE and not modifiers:
        return ViewerRequest.TOGGLE_PAUSE
    if key == KEY_R and modifiers == RESET_MODIFIERS:
        return ViewerRequest.RESET_WORLD
    return None


def display_problem(display: str | None) -> str | None:
    """Why no window can open on X display `display` ($DISPLAY); None when a server answers.

    MuJoCo's viewer ends the whole process when GLFW cannot open the display ("could not
    initialize GLFW"), which took the launch down with it; so the node asks X first.
    """
    if not display:
        return '$DISPLAY is not set'
    name = ctypes.util.find_library('X11')
    if name is None:
        return 'the X11 library (libX11) is not installed'
    xlib = ctypes.CDLL(name)
    xlib.XOpenDisplay.restype = ctypes.c_void_p
    xlib.XOpenDisplay.argtypes = [ctypes.c_char_p]
    xlib.XCloseDisplay.argtypes = [ctypes.c_void_p]
    connection = xlib.XOpenDisplay(display.encode())
    if not connection:
        return (f'no X server answers at DISPLAY={display} (none running there, or a broken '
                'ssh -X forwarding)')
    xlib.XCloseDisplay(connection)
    return None


class ViewerLink:
    """A passive MuJoCo viewer on a shadow of the physics data, and the requests made in it.

    Threads: ``on_key`` runs in the viewer's thread and only queues a request; everything
    else is called by the node's loop. ``copy_in``/``copy_out`` read/write the physics data
    and belong under the node's lock; ``sync`` does not (it waits for the viewer's own
    mutex, which the viewer's thread holds while it handles window events).

    ``close`` may come from another thread (the node's main thread) while the loop is in
    ``hold``: MuJoCo's close waits for the render loop while holding the GIL, and the render
    loop ends by taking the viewer's mutex, which a hold keeps until its thread gets the
    GIL back. So a hold and the close take turns under ``_hold_lock`` (waiting for it
    releases the GIL), and a closed link holds no more.
    """

    def __init__(self, model: mujoco.MjModel, launch: Launcher | None = None,
                 modifiers: Modifiers = _glfw_modifiers) -> None:
        if launch is None:  # imported late: it needs GLFW, hence a display library
            from mujoco import viewer as mujoco_viewer  # noqa: PLC0415
            launch = mujoco_viewer.launch_passive
        self.model = model
        self.shadow = mujoco.MjData(model)
        self._modifiers = modifiers
        self._requests: list[ViewerRequest] = []
        self._requests_lock = threading.Lock()
        self._paused_shown = False
        self._hold_lock = threading.Lock()
        self._closed = False
        before = set(threading.enumerate())
        self.handle = launch(model, self.shadow, key_callback=self.on_key,
                             show_left_ui=PANELS_SHOWN_AT_OPEN,
                             show_right_ui=PANELS_SHOWN_AT_OPEN)
        self._window_threads = _window_threads(before)
        # For an exit that skips close() (an exception): runs before mujoco.viewer's own exit
        # hooks (registered earlier, run later), which race the window's thread. A no-op
        # once closed.
        atexit.register(self.close)

    # -- the viewer's thread -------------------------------------------------------------
    def on_key(self, key: int) -> None:
        request = request_for_key(key, self._modifiers())
        if request is not None:
            self._push(request)

    def _push(self, request: ViewerRequest) -> None:
        with self._requests_lock:
            self._requests.append(request)

    # -- the node's loop ----------------------------------------------------------------
    def is_running(self) -> bool:
        return bool(self.handle.is_running())

    def copy_in(self, data: mujoco.MjData) -> None:
        """Refresh the shadow from the physics data (under the node's lock, so kept short)."""
        mujoco.mj_copyData(self.shadow, self.model, data)
        self.shadow.qacc_warmstart[:] = RESET_CANARY

    def sync(self) -> None:
        """Hand the shadow to the window; a reset the viewer did on it becomes a request."""
        self.handle.sync()
        if self.model.nv and self.shadow.qacc_warmstart[0] != RESET_CANARY:
            self._push(ViewerRequest.RESET_WORLD)

    def copy_out(self, data: mujoco.MjData) -> None:
        """Apply the window's mouse perturbation forces to the physics (under the lock)."""
        np.copyto(data.xfrc_applied, self.shadow.xfrc_applied)

    def take_requests(self) -> list[ViewerRequest]:
        with self._requests_lock:
            requests, self._requests = self._requests, []
        return requests

    def show_paused(self, paused: bool) -> None:
        """Overlay "PAUSED" while physics is paused (MuJoCo's own label needs its Pause)."""
        if paused == self._paused_shown:
            return
        if paused:
            left, right = PAUSED_TEXT
            self.handle.set_texts((mujoco.mjtFontScale.mjFONTSCALE_150,
                                   mujoco.mjtGridPos.mjGRID_TOP, left, right))
        else:
            self.handle.clear_texts()
        self._paused_shown = paused

    def hold(self, seconds: float) -> None:
        """Keep the render thread waiting at the top of its next frame for `seconds` (wall).

        Its drawing is paced this way (see sim_node's VIEWER_HOLD_S); nothing once closed.
        """
        with self._hold_lock:
            if self._closed:
                return
            with self.handle.lock():
                time.sleep(seconds)

    def close(self, timeout_s: float = CLOSE_TIMEOUT_S) -> None:
        """Close the window and wait until its thread has destroyed it; idempotent."""
        with self._hold_lock:  # a hold in progress ends first (see the class docstring)
            if self._closed:
                return
            self._closed = True
            self.handle.close()
        for thread in self._window_threads:
            thread.join(timeout_s)
