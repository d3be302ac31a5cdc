"""viewer.ViewerLink without a display: a fake passive viewer doing what MuJoCo's does on sync."""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from pathlib import Path

import mujoco
import numpy as np
import pytest

from tutorial_atlas_control.node.viewer import (
    CONTROL,
    KEY_R,
    KEY_SPACE,
    SHIFT,
    ViewerLink,
    ViewerRequest,
    request_for_key,
)

MJCF = """
<mujoco>
  <worldbody>
    <body name="ball" pos="0 0 1"><freejoint/><geom size="0.1" mass="1"/></body>
  </worldbody>
</mujoco>
"""
KEY_BACKSPACE = 259
KeyCallback = Callable[[int], None]
Physics = tuple[mujoco.MjModel, mujoco.MjData]


class FakeViewer:
    """Stands in for mujoco.viewer.Handle; `press_reset` does what the Reset button does."""

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData, key_callback,
                 **options: bool) -> None:
        self.model, self.data, self.key_callback = model, data, key_callback
        self.options = options  # launch_passive's show_left_ui, show_right_ui
        self.reset_pending = False
        self.force = np.zeros(6)
        self.texts: list[object] = []
        self.running = True

    def sync(self) -> None:
        if self.reset_pending:  # simulate.cc: mj_resetData + mj_forward on the user's data
            mujoco.mj_resetData(self.model, self.data)
            mujoco.mj_forward(self.model, self.data)
            self.reset_pending = False
        self.data.xfrc_applied[:] = 0.0  # then the perturbation of the mouse, if any
        self.data.xfrc_applied[1] = self.force

    def set_texts(self, texts: object) -> None:
        self.texts = [texts]

    def clear_texts(self) -> None:
        self.texts = []

    def is_running(self) -> bool:
        return self.running

    def close(self) -> None:
        self.running = False


@pytest.fixture()
def physics() -> tuple[mujoco.MjModel, mujoco.MjData]:
    model = mujoco.MjModel.from_xml_string(MJCF)
    data = mujoco.MjData(model)
    for _ in range(200):
        mujoco.mj_step(model, data)
    return model, data


def make_link(model: mujoco.MjModel,
              held: frozenset[str] = frozenset()) -> tuple[ViewerLink, FakeViewer]:
    viewers = []

    def launch(m: mujoco.MjModel, d: mujoco.MjData, key_callback,
               **options: bool) -> FakeViewer:
        viewers.append(FakeViewer(m, d, key_callback, **options))
        return viewers[-1]

    link = ViewerLink(model, launch=launch, modifiers=lambda: held)
    return link, viewers[0]


def refresh(link: ViewerLink, data: mujoco.MjData) -> list[ViewerRequest]:
    link.copy_in(data)
    link.sync()
    link.copy_out(data)
    return link.take_requests()


def test_the_viewer_never_gets_the_physics_data(physics) -> None:
    model, data = physics
    link, viewer = make_link(model)
    assert viewer.data is not data
    refresh(link, data)
    np.testing.assert_array_equal(viewer.data.qpos, data.qpos)
    assert viewer.data.time == data.time


def test_the_window_opens_with_the_3d_view_only(physics) -> None:
    """MuJoCo's two panels would leave the robot a third of the window; Tab shows them."""
    model, _ = physics
    _, viewer = make_link(model)
    assert viewer.options == {'show_left_ui': False, 'show_right_ui': False}


def test_reset_button_becomes_a_request_and_leaves_physics_alone(physics) -> None:
    model, data = physics
    link, viewer = make_link(model)
    qpos, time_s = data.qpos.copy(), data.time
    viewer.reset_pending = True
    assert refresh(link, data) == [ViewerRequest.RESET_WORLD]
    np.testing.assert_array_equal(data.qpos, qpos)  # no raw mj_resetData on the physics
    assert data.time == time_s  # nor a rewound clock
    assert refresh(link, data) == []  # one reset, one request


def test_reset_is_seen_at_time_zero(physics) -> None:
    model, _ = physics
    link, viewer = make_link(model)
    fresh = mujoco.MjData(model)
    mujoco.mj_forward(model, fresh)
    assert fresh.time == 0.0
    assert refresh(link, fresh) == []
    viewer.reset_pending = True
    assert refresh(link, fresh) == [ViewerRequest.RESET_WORLD]


def test_mouse_forces_reach_the_physics(physics) -> None:
    model, data = physics
    link, viewer = make_link(model)
    viewer.force = np.array([0.0, 0.0, 50.0, 0.0, 0.0, 0.0])
    refresh(link, data)
    np.testing.assert_array_equal(data.xfrc_applied[1], viewer.force)
    viewer.force = np.zeros(6)
    refresh(link, data)
    assert not data.xfrc_applied.any()


@pytest.mark.parametrize(('key', 'held', 'expected'), [
    (KEY_SPACE, frozenset(), ViewerRequest.TOGGLE_PAUSE),
    (KEY_R, frozenset({SHIFT, CONTROL}), ViewerRequest.RESET_WORLD),
    (KEY_R, frozenset(), None),  # MuJoCo's own reflection toggle
    (KEY_R, frozenset({CONTROL}), None),
    (KEY_SPACE, frozenset({CONTROL}), None),
    (KEY_BACKSPACE, frozenset(), None),  # MuJoCo's Reset: seen at sync, not here
])
def test_keys(key: int, held: frozenset[str], expected: ViewerRequest | None) -> None:
    assert request_for_key(key, held) is expected


def test_key_callback_queues_until_taken(physics) -> None:
    model, data = physics
    link, viewer = make_link(model, frozenset({SHIFT, CONTROL}))
    viewer.key_callback(KEY_R)
    viewer.key_callback(KEY_R)
    assert refresh(link, data) == [ViewerRequest.RESET_WORLD, ViewerRequest.RESET_WORLD]
    assert link.take_requests() == []


def test_paused_overlay_follows_the_node(physics) -> None:
    model, _ = physics
    link, viewer = make_link(model)
    link.show_paused(True)
    assert len(viewer.texts) == 1 and 'PAUSED' in viewer.texts[0]
    link.show_paused(False)
    assert viewer.texts == []


class ThreadedFakeViewer(FakeViewer):
    """A fake with MuJoCo's threads: the window lives in a thread of its own (named as
    launch_passive's), the render loop's end takes the viewer's mutex, and after it the
    thread still destroys the window: what the interpreter's exit must not race."""

    FRAME_S = 0.001
    DESTROY_S = 0.2

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData,
                 key_callback: KeyCallback, **options: bool) -> None:
        super().__init__(model, data, key_callback, **options)
        self.mutex = threading.Lock()
        self.exit_requested = threading.Event()
        self.render_loop_ended = threading.Event()
        self.destroyed = False

        def _launch_internal() -> None:  # the name launch_passive's thread runs
            while not self.exit_requested.wait(self.FRAME_S):
                pass
            with self.mutex:  # simulate.cc: the render loop's end takes the mutex
                self.render_loop_ended.set()
            time.sleep(self.DESTROY_S)  # simulate.destroy(): the window goes
            self.destroyed = True

        threading.Thread(target=_launch_internal, daemon=True).start()

    def lock(self) -> threading.Lock:
        return self.mutex

    def close(self) -> None:
        # MuJoCo's close waits for the render loop's end holding the GIL: a hold in
        # progress elsewhere could never end. The fake cannot hold the GIL; it checks.
        assert not self.mutex.locked(), 'closed during a hold: a deadlock in MuJoCo'
        self.exit_requested.set()
        self.render_loop_ended.wait()
        super().close()


def make_threaded_link(model: mujoco.MjModel) -> tuple[ViewerLink, ThreadedFakeViewer]:
    viewers = []

    def launch(m: mujoco.MjModel, d: mujoco.MjData,
               key_callback: KeyCallback, **options: bool) -> ThreadedFakeViewer:
        viewers.append(ThreadedFakeViewer(m, d, key_callback, **options))
        return viewers[-1]

    link = ViewerLink(model, launch=launch, modifiers=frozenset)
    return link, viewers[0]


def test_close_returns_once_the_window_is_destroyed(physics: Physics) -> None:
    """The node's exit (glfw.terminate) comes right after close(): the window's thread must
    be done by then, or the node segfaults."""
    model, _ = physics
    link, viewer = make_threaded_link(model)
    link.close()
    assert viewer.destroyed
    link.close()  # again, as the exit hook does: nothing


def test_close_waits_for_a_hold_in_progress(physics: Physics) -> None:
    model, _ = physics
    link, viewer = make_threaded_link(model)
    hold_s = 0.3
    holder = threading.Thread(target=link.hold, args=(hold_s,))
    holder.start()
    while not viewer.mutex.locked():  # the hold has the viewer's mutex
        time.sleep(0.001)
    link.close()  # the fake fails if it gets the close during the hold
    holder.join()
    assert viewer.destroyed
    started_s = time.monotonic()
    link.hold(hold_s)  # closed: no more holds
    assert time.monotonic() - started_s < hold_s


def free_display() -> str:
    """An X display number no server uses here."""
    for number in range(87, 200):
        if not Path(f'/tmp/.X11-unix/X{number}').exists():
            return f':{number}'
    pytest.skip('no free X display number')


def test_an_unusable_display_is_named_before_glfw_can_end_the_process() -> None:
    from tutorial_atlas_control.node.viewer import display_problem
    display = free_display()
    assert display_problem(display) == (
        f'no X server answers at DISPLAY={display} (none running there, or a broken ssh -X '
        'forwarding)')
    assert display_problem('') == '$DISPLAY is not set'
    assert display_problem(None) == '$DISPLAY is not set'
