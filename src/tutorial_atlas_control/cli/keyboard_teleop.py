"""Command line of keyboard_teleop.py: DRCSim's keyboard teleop for Atlas, in a terminal.

Each walking key sends a goal to DRCSim's actionlib server atlas/bdi_control (start the
simulator with `roslaunch tutorial_atlas_control atlas.launch bdi_control:=true`, then press
S for Stand; or with startup_mode:=bdi_stand, standing from 2 s): lower case one WALK goal of
the steps, capitals one STEP goal per step. The screen shows what every key does, the
settings, where the robot is and how the last goal ended. Keys (asi/teleop.py):
u i o / j l / m , . walk; 1-9 steps; - = stride; S stand; R stand up from the harness;
H harness; Q quit. Options: -h/--help; ROS remapping arguments (name:=value) are accepted.
"""

from __future__ import annotations

import curses
import logging
import os
import sys
import threading
from collections.abc import Sequence

import actionlib
import rosgraph
import rospy
from actionlib_msgs.msg import GoalStatus
from atlas_msgs.msg import (
    AtlasSimInterfaceState,
    WalkDemoAction,
    WalkDemoGoal,
)
from rosgraph.roslogging import RosStreamHandler
from std_msgs.msg import String

from tutorial_atlas_control import topics
from tutorial_atlas_control.asi import Behavior, Settings, ego_steps, key_action
from tutorial_atlas_control.cli.asi_link import step_message
from tutorial_atlas_control.cli.convention import (
    EXIT_INTERRUPTED,
    EXIT_REFUSED,
    node_arguments,
    print_error,
)

PROG = 'keyboard_teleop.py'
ACTION = 'atlas/bdi_control'
#: How long (s, wall time) to wait for the action server.
SERVER_TIMEOUT_S = 30.0
#: DRCSim's scripts' harness drop: StandPrep this long in the harness, then nominal, Stand
#: this long after (s of sim time).
HARNESS_PREP_S, LANDING_S = 5.0, 0.3


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of scripts/keyboard_teleop.py (`argv` with the program name first)."""
    argv = list(sys.argv if argv is None else argv)
    refused = node_arguments(PROG, __doc__, rospy.myargv(argv)[1:])
    if refused is not None:
        return refused
    if not (sys.stdin.isatty() and sys.stdout.isatty()):
        print_error(PROG, 'needs a terminal: its standard input and output must be a tty '
                          '(run it in a terminal, not through a pipe or roslaunch)')
        return EXIT_REFUSED
    uri = rosgraph.get_master_uri()
    if not rosgraph.is_master_online(uri):
        print_error(PROG, f'no ROS master at {uri}: start the simulator first')
        return EXIT_REFUSED
    rospy.init_node('keyboard_teleop', anonymous=True, argv=argv, disable_signals=True)
    client = actionlib.SimpleActionClient(ACTION, WalkDemoAction)
    print(f'{PROG}: waiting for {ACTION} (up to {SERVER_TIMEOUT_S:.0f} s; atlas.launch '
          'bdi_control:=true serves it)', flush=True)
    if not client.wait_for_server(rospy.Duration(SERVER_TIMEOUT_S)):
        print_error(PROG, f'no {ACTION} server within {SERVER_TIMEOUT_S:.0f} s: start the '
                          'simulator with bdi_control:=true')
        return EXIT_REFUSED
    for stale in ('COLUMNS', 'LINES'):  # curses takes the terminal's own size, not these
        os.environ.pop(stale, None)
    keep_logs_off_the_screen()
    try:
        curses.wrapper(Teleop(client).run)
    except KeyboardInterrupt:
        return EXIT_INTERRUPTED
    except curses.error as error:  # a terminal curses cannot drive (TERM unknown, too small)
        print_error(PROG, f'cannot draw in this terminal (TERM={os.environ.get("TERM", "")}): '
                          f'{error}')
        return EXIT_REFUSED
    finally:
        rospy.signal_shutdown('teleop closed')
    return 0


def keep_logs_off_the_screen(logger: logging.Logger | None = None) -> int:
    """Stop rospy's terminal output (the `rosout` logger's RosStreamHandler): the screen is
    curses'. A log line there (actionlib's "Got a transition callback on a goal handle that
    we're not tracking", for a finished goal's late status) broke a screen line in two. The
    lines still go to the node's log file and /rosout. Returns how many handlers went."""
    logger = logger or logging.getLogger('rosout')
    streams = [h for h in logger.handlers if isinstance(h, RosStreamHandler)]
    for handler in streams:
        logger.removeHandler(handler)
    return len(streams)


class Teleop:
    """The screen, the keys, and the goals under way."""

    def __init__(self, client: actionlib.SimpleActionClient) -> None:
        self.client = client
        self.settings = Settings()
        self.last = 'ready: press a walking key'
        self.robot = 'robot: (no state yet)'
        #: The behaviour the last state said (None before one).
        self.behavior: int | None = None
        self.busy = threading.Lock()
        self.modes = rospy.Publisher(topics.MODE, String, queue_size=10)
        self.control_modes = rospy.Publisher(topics.CONTROL_MODE, String, queue_size=10)
        rospy.Subscriber(topics.ASI_STATE, AtlasSimInterfaceState, self._on_state,
                         queue_size=1)

    def _on_state(self, state: AtlasSimInterfaceState) -> None:
        position = state.pos_est.position
        self.behavior = state.current_behavior
        try:
            behaviour = Behavior(state.current_behavior).name
        except ValueError:
            behaviour = str(state.current_behavior)
        self.robot = f'robot: x {position.x:6.2f}  y {position.y:6.2f}  behaviour {behaviour}'

    def run(self, screen: curses.window) -> None:
        curses.curs_set(0)
        screen.timeout(100)
        while not rospy.is_shutdown():
            self._draw(screen)
            key = screen.getch()
            if key < 0:
                continue
            action, value = key_action(chr(key) if key < 256 else '', self.settings)
            if action == 'quit':
                return
            if action == 'settings':
                assert isinstance(value, Settings)
                self.settings = value
            elif action in ('walk', 'step'):
                self._start(self._walk if action == 'walk' else self._step, str(value))
            elif action == 'stand up':
                self._start(self._stand_up, 'stand up from the harness')
            elif action == 'stand':
                self._start(self._stand, 'stand')
            elif action == 'harness':
                self.modes.publish(String(data='harnessed'))
                self.last = 'in the harness (/atlas/mode harnessed)'

    def _draw(self, screen: curses.window) -> None:
        lines = [f'Atlas keyboard teleop (DRCSim\'s key map) -- {ACTION}',
                 '  walk:  u i o  curve left, forward, curve right',
                 '         j   l  turn left, turn right      , back',
                 '         m   .  side step left, right',
                 '  capitals (U I O J L M < >): the same, one static step at a time',
                 f'  1-9 steps: {self.settings.steps}    - = shorter, longer stride: '
                 f'{self.settings.stride_m:.2f} m',
                 '  S stand   R stand up from the harness   H harness   Q quit',
                 '', self.robot, f'last: {self.last}']
        rows, columns = screen.getmaxyx()  # the terminal as it is now (resizes included)
        screen.erase()
        for row, line in enumerate(lines[:rows]):
            screen.addnstr(row, 0, line, max(1, columns - 1))
        screen.refresh()

    def _start(self, work: object, what: str) -> None:
        """Run `work(what)` on a thread, one at a time."""
        if not self.busy.acquire(blocking=False):
            self.last = f'{what}: ignored, a goal is under way'
            return

        def run() -> None:
            try:
                work(what)  # type: ignore[operator]
            finally:
                self.busy.release()
        threading.Thread(target=run, daemon=True).start()

    def _walk(self, move: str) -> None:
        steps = ego_steps(move, self.settings)
        goal = WalkDemoGoal(behavior=WalkDemoGoal.WALK,
                            steps=[step_message(step) for step in steps])
        self._send(goal, f'{move}, {len(steps)} steps')

    def _step(self, move: str) -> None:
        steps = ego_steps(move, self.settings)
        for number, step in enumerate(steps, 1):
            goal = WalkDemoGoal(behavior=WalkDemoGoal.STEP)
            goal.step_params.desired_step = step_message(step)
            if not self._send(goal, f'{move} step by step, step {number} of {len(steps)}'):
                return

    def _send(self, goal: WalkDemoGoal, what: str) -> bool:
        self.last = f'{what}: sent'
        self.client.send_goal(goal)
        self.client.wait_for_result()
        state = self.client.get_state()
        if state == GoalStatus.SUCCEEDED:
            self.last = f'{what}: succeeded'
            return True
        text = self.client.get_goal_status_text()
        self.last = f'{what}: {"aborted" if state == GoalStatus.ABORTED else "ended"}' + (
            f' ({text})' if text else '') + self._remedy()
        return False

    def _remedy(self) -> str:
        """What to do when the library is not in a behaviour a goal can start from."""
        if self.behavior in (Behavior.USER, Behavior.FREEZE, Behavior.STAND_PREP):
            return f'; the robot is in {Behavior(self.behavior).name}: press S for Stand first'
        return ''

    def _stand(self, what: str) -> None:
        self._send(WalkDemoGoal(behavior=WalkDemoGoal.STAND), what)

    def _stand_up(self, what: str) -> None:
        """DRCSim's scripts: harnessed, StandPrep, 5 s, nominal, 0.3 s, Stand."""
        self.last = f'{what}: StandPrep in the harness'
        self.modes.publish(String(data='harnessed'))
        self.control_modes.publish(String(data='StandPrep'))
        rospy.sleep(HARNESS_PREP_S)
        self.modes.publish(String(data='nominal'))
        rospy.sleep(LANDING_S)
        self.control_modes.publish(String(data='Stand'))
        self.last = f'{what}: Stand'

