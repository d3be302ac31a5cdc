"""A test-side client of the simulator: subscribes to its topics, calls its services.

Shared by the rostest nodes; waits are bounded by wall-clock deadlines so that a
broken simulator fails a test instead of hanging it.
"""

from __future__ import annotations

import json
import threading
import time
import xmlrpc.client
from collections.abc import Callable, Sequence

import rosgraph
import rospy
from geometry_msgs.msg import WrenchStamped
from nav_msgs.msg import Odometry
from osrf_msgs.msg import JointCommands
from rosgraph_msgs.msg import Clock, Log
from sensor_msgs.msg import JointState
from std_msgs.msg import String
from std_srvs.srv import Empty

#: Longest a single wait may take (s, wall) before the test fails.
WALL_TIMEOUT_S = 60.0
#: How recent (s of sim time) a reading must be: /ground_truth_odom comes at 100 Hz.
FRESH_S = 0.02


class SimProbe:
    """Latest messages from the simulator, plus helpers to drive it."""

    def __init__(self, keep_joint_states: bool = False) -> None:
        self.lock = threading.Lock()
        self.clock_ns = -1
        self.joint_state: JointState | None = None
        self.odom: Odometry | None = None
        self.contacts: dict[str, WrenchStamped] = {}
        self.warnings: list[str] = []
        self.keep_joint_states = keep_joint_states
        self.joint_states: list[JointState] = []
        #: time.monotonic() at each kept joint state's arrival (s).
        self.joint_state_arrivals_s: list[float] = []
        self.configs: list[dict] = []
        #: Each /atlas/current_control_mode the simulator said, in order.
        self.modes: list[str] = []
        rospy.Subscriber('/clock', Clock, self._on_clock, queue_size=1000)
        rospy.Subscriber('/atlas/joint_states', JointState, self._on_joint_state, queue_size=2000)
        rospy.Subscriber('/ground_truth_odom', Odometry, self._on_odom, queue_size=100)
        for side in ('l', 'r'):
            rospy.Subscriber(f'/atlas/{side}_foot_contact', WrenchStamped,
                             self._on_contact, callback_args=side, queue_size=100)
        rospy.Subscriber('/rosout', Log, self._on_log, queue_size=100)
        rospy.Subscriber('/atlas/sim_config', String, self._on_config, queue_size=10)
        rospy.Subscriber('/atlas/current_control_mode', String, self._on_mode, queue_size=10)
        self.mode_pub = rospy.Publisher('/atlas/control_mode', String, queue_size=10, latch=True)
        self.command_pub = rospy.Publisher('/atlas/joint_commands', JointCommands, queue_size=10)

    # -- callbacks -----------------------------------------------------------------------
    def _on_clock(self, msg: Clock) -> None:
        self.clock_ns = msg.clock.to_nsec()

    def _on_joint_state(self, msg: JointState) -> None:
        with self.lock:
            self.joint_state = msg
            if self.keep_joint_states:
                self.joint_states.append(msg)
                self.joint_state_arrivals_s.append(time.monotonic())

    def _on_odom(self, msg: Odometry) -> None:
        self.odom = msg

    def _on_contact(self, msg: WrenchStamped, side: str) -> None:
        self.contacts[side] = msg

    def _on_config(self, msg: String) -> None:
        with self.lock:
            self.configs.append(json.loads(msg.data))

    def _on_mode(self, msg: String) -> None:
        with self.lock:
            self.modes.append(msg.data)

    def _on_log(self, msg: Log) -> None:
        if msg.level >= Log.WARN:
            with self.lock:
                self.warnings.append(msg.msg)

    # -- waiting -------------------------------------------------------------------------
    def wait_until(self, predicate: Callable[[], bool], what: str,
                   timeout_s: float = WALL_TIMEOUT_S) -> None:
        deadline = time.monotonic() + timeout_s
        while not predicate():
            if time.monotonic() > deadline or rospy.is_shutdown():
                raise AssertionError(f'timed out after {timeout_s} s waiting for {what}')
            time.sleep(0.005)

    def wait_ready(self) -> None:
        self.wait_until(lambda: self.joint_state is not None and self.odom is not None,
                        'the simulator to publish /atlas/joint_states and /ground_truth_odom')
        self.wait_until(lambda: self.command_pub.get_num_connections() > 0,
                        'the simulator to subscribe to /atlas/joint_commands')

    def sim_time_s(self) -> float:
        return self.clock_ns / 1e9

    def wait_sim(self, seconds: float) -> None:
        """Let `seconds` of sim time pass, and the joint states of that time arrive.

        /clock and /atlas/joint_states come on separate connections, each read by its own
        thread: at real_time_factor 0 on a loaded host the joint states lagged the clock
        by 210-320 ms of sim time (a fresh-clone run kept 790 of a second's 1000).
        """
        target_ns = self.clock_ns + int(seconds * 1e9)
        self.wait_until(lambda: self.clock_ns >= target_ns, f'{seconds} s of sim time')
        self.wait_until(lambda: self.joint_state is not None
                        and self.joint_state.header.stamp.to_nsec() >= target_ns,
                        f'/atlas/joint_states to reach the sim time {target_ns / 1e9:.3f} s')

    def _wait_fresh(self, latest: Callable[[], object], what: str) -> None:
        """Wait until `latest()` is stamped within FRESH_S of the clock (subscriber queues
        can lag behind /clock when the simulator runs faster than real time)."""
        fresh_ns = int(FRESH_S * 1e9)

        def is_fresh() -> bool:
            # Within FRESH_S of the clock on either side: also rejects a reading from before
            # a reset_simulation rewound the clock.
            msg = latest()
            return msg is not None and abs(msg.header.stamp.to_nsec() - self.clock_ns) <= fresh_ns

        self.wait_until(is_fresh, f'a {what} within {FRESH_S} s of the current sim time')

    def pelvis_z(self) -> float:
        return self.pelvis_z_stamped()[1]

    def pelvis_z_stamped(self) -> tuple[int, float]:
        """(stamp ns, pelvis height m) of one fresh /ground_truth_odom reading.

        The wait for a fresh reading lets sim time run on: the stamp says when it was measured.
        """
        self._wait_fresh(lambda: self.odom, '/ground_truth_odom')
        odom = self.odom
        return odom.header.stamp.to_nsec(), odom.pose.pose.position.z

    def position(self, joint: str) -> float:
        self._wait_fresh(lambda: self.joint_state, '/atlas/joint_states')
        return self.joint_state.position[self.joint_state.name.index(joint)]

    # -- driving -------------------------------------------------------------------------
    def call(self, service: str) -> None:
        rospy.wait_for_service(service, timeout=WALL_TIMEOUT_S)
        rospy.ServiceProxy(service, Empty)()

    def reset(self, service: str) -> int:
        """Call a /gazebo/reset_* service; return the sim time (ns) the simulator reset at.

        Taken from the /atlas/sim_config it re-publishes, not from this probe's /clock,
        which can lag behind the simulator when it runs faster than real time.
        """
        with self.lock:
            seen = len(self.configs)
        before_ns = self.clock_ns
        self.call(service)
        self.wait_until(lambda: len(self.configs) > seen, f'/atlas/sim_config after {service}')
        with self.lock:
            reset_ns = round(self.configs[-1]['last_reset_time'] * 1e9)
        if reset_ns < before_ns:  # reset_simulation: wait for the rewound clock
            self.wait_until(lambda: self.clock_ns < before_ns, f'/clock to rewind ({service})')
        self.wait_until(lambda: self.clock_ns >= reset_ns, f'/clock to reach the {service}')
        return reset_ns

    def set_mode(self, mode: str) -> None:
        self.mode_pub.publish(String(data=mode))

    def set_mode_applied(self, mode: str) -> None:
        """set_mode, and wait until the simulator says it switched."""
        with self.lock:
            seen = len(self.modes)
        self.set_mode(mode)
        self.wait_until(lambda: mode in self.modes[seen:], f'/atlas/current_control_mode {mode}')

    def restart_held(self, service: str = '/gazebo/reset_world') -> int:
        """The robot at its initial pose in the start's hold (Stand's mode, no behaviour:
        the tutorial's start): Stand, then a reset in it. Returns reset()'s sim time."""
        self.set_mode_applied('Stand')
        return self.reset(service)

    def send(self, names: Sequence[str], **arrays: Sequence[float]) -> None:
        self.command_pub.publish(JointCommands(name=list(names), **arrays))

    def warnings_containing(self, text: str) -> list[str]:
        with self.lock:
            return [w for w in self.warnings if text in w]


def bus_connections(node: str, caller_id: str = '/sim_probe') -> list[list]:
    """`node`'s getBusInfo (its XML-RPC API, what `rosnode info` shows): one
    [id, peer, direction, transport, topic, connected, info] per connection."""
    uri = rosgraph.Master(caller_id).lookupNode(node)
    code, text, connections = xmlrpc.client.ServerProxy(uri).getBusInfo(caller_id)
    if code != 1:
        raise AssertionError(f'getBusInfo of {node}: {text}')
    return connections


def transports_to(peer: str, topic: str, node: str = '/atlas_sim') -> list[str]:
    """The transports (TCPROS, UDPROS) of `node`'s connections to `peer` on `topic`."""
    return [c[3] for c in bus_connections(node) if c[1] == peer and c[4] == topic]


def messages_received(topic: str, node: str = '/atlas_sim', caller_id: str = '/sim_probe') -> int:
    """How many `topic` messages `node` has read from this node's publisher (its getBusStats
    and getBusInfo: rospy counts each message as it reads it, before its callback)."""
    uri = xmlrpc.client.ServerProxy(rosgraph.Master(caller_id).lookupNode(node))
    mine = rospy.get_node_uri()
    ids = {c[0] for c in uri.getBusInfo(caller_id)[2]
           if c[2] == 'i' and c[4] == topic and c[1] == mine}
    _publish, subscribe, _services = uri.getBusStats(caller_id)[2]
    return sum(connection[2] for name, connections in subscribe if name == topic
               for connection in connections if connection[0] in ids)


#: A client that left this many steps of joint states unanswered or more was held up (a
#: loaded host starves it; how often is a speed, make bench's controller ages) ...
STALL_STEPS = 20
#: ... and its joint lags its commands for about this long after (s of sim time): the arm's
#: PD (200 N m/rad) takes up the difference in a few tens of ms.
STALL_RECOVERY_S = 0.2


def after_stalls(answered_ns: Sequence[int], step_ns: int) -> set[int]:
    """Of the sorted stamps of the answered joint states, those in a client's stall (a gap of
    STALL_STEPS steps or more between two answers) or in the STALL_RECOVERY_S after it:
    there the joint tracks the last command the client could send, not the current one."""
    recovery_ns = int(STALL_RECOVERY_S * 1e9)
    stalled: set[int] = set()
    for before, after in zip(answered_ns, answered_ns[1:]):
        if after - before >= STALL_STEPS * step_ns:
            stalled.update(t for t in answered_ns if after <= t <= after + recovery_ns)
    return stalled
