"""What the stepping loop sends after each step, as topics.INTERFACE declares it.

The table's rows with a SimMessages wire are filled by plans and sent at their rate; the
on-demand ones are filled only when due and someone listens (an unheard one costs a test
per step). /clock, /ground_truth_odom, /tf, /atlas/controller_statistics, the
AtlasSimInterface's state (and the bag's copy of it) and the MultiSense SL head's topics
(sensors/head.py) have builders of their own.
"""

from __future__ import annotations

from collections.abc import Mapping

from tutorial_atlas_control import topics
from tutorial_atlas_control.asi import AtlasSimInterface
from tutorial_atlas_control.msgs import (
    AsiState,
    ControllerStatisticsWire,
    clock_bytes,
    encode_asi_state,
)
from tutorial_atlas_control.sensors import HeadSensors
from tutorial_atlas_control.sim import (
    AtlasSimulator,
    CommandAgeStatistics,
    LinkTransforms,
    RspSchedule,
    SimMessages,
)
from tutorial_atlas_control.stepping.outputs import LoopOutputs
from tutorial_atlas_control.stepping.schedule import STAMPED_AT_STEP_END, steps_between

__all__ = ['DEMAND_TOPICS', 'LINKS_TF_RATE_HZ', 'STEP_TOPICS', 'StepPublisher',
           'default_rates_hz']

#: The table's per-step messages filled by SimMessages at every due step.
STEP_TOPICS = tuple(topic for topic in topics.INTERFACE
                    if topic.delivery.message and not topic.on_demand)
#: DRCSim's messages filled only when due and someone listens.
DEMAND_TOPICS = tuple(topic for topic in topics.INTERFACE
                      if topic.delivery.message and topic.on_demand)
#: The links' /tf rate (Hz of sim time): robot_state_publisher's publish_frequency in
#: DRCSim's launch.
LINKS_TF_RATE_HZ = 50.0


def default_rates_hz() -> dict[str, float]:
    """Each rate key of the table (topics.Rate.key) with its default (Hz of sim time)."""
    return {topic.rate.key: topic.rate.default_hz for topic in topics.INTERFACE
            if topic.rate.key}


class StepPublisher:
    """Serializes what is due at each step into the outbox (called under the loop's lock).

    Args:
        rates_hz: rate (Hz of sim time; 0 = every step) by the table's rate keys
            (topics.Rate.key), and 'links_tf' (default LINKS_TF_RATE_HZ); a key not given
            takes the table's default.
        links: with a /tf outlet, the links' transforms published in robot_state_publisher's
            stead (link_transforms.py), at rates_hz['links_tf']; None: not.
        asi: the AtlasSimInterface whose state goes out every step while someone listens
            (its end_step is the tick's, after this); None: no such state.
    """

    def __init__(self, sim: AtlasSimulator, outputs: LoopOutputs, rates_hz: Mapping[str, float],
                 statistics: CommandAgeStatistics, links: LinkTransforms | None,
                 asi: AtlasSimInterface | None = None) -> None:
        self.sim = sim
        #: The MultiSense SL head: the spindle stepped each step, its messages on demand.
        self.head = HeadSensors(sim.model, sim.data, sim.dt_s, sim.sensor_seed)
        self.scan_outlet = outputs.outlets.get(topics.LASER_SCAN)
        self.head_joint_state_outlet = outputs.outlets.get(topics.HEAD_JOINT_STATES)
        self.head_imu_outlet = outputs.outlets.get(topics.HEAD_IMU)
        self.asi = asi
        self.asi_outlet = outputs.outlets.get(topics.ASI_STATE) if asi is not None else None
        self.asi_seq = 0
        #: The bag's copy of the state: at its rate and at each change of (behaviour, status).
        self.asi_recorded_outlet = (outputs.outlets.get(topics.ASI_STATE_RECORDED)
                                    if asi is not None else None)
        self.asi_recorded_seq = 0
        self.asi_recorded_key: tuple[int, int] | None = None
        self.outbox = outputs.outbox
        outlets = outputs.outlets
        rates_hz = {**default_rates_hz(), **rates_hz}
        self.every = every = {key: steps_between(rate, sim.dt_s) for key, rate in rates_hz.items()}
        # What each message holds is sim_messages' (shared with offline runs).
        self.messages = messages = SimMessages(sim)
        # Those due at the same steps are filled by one plan (at the launch's rates, all).
        due_together: dict[int, list[str]] = {}
        for topic in STEP_TOPICS:
            due_together.setdefault(every[topic.rate.key], []).append(topic.delivery.message)
        self.fill_plans = tuple((steps, messages.fill_plan(names))
                                for steps, names in due_together.items())
        # (every how many steps, wire message, outlet, stamped at the step's end).
        self.step_wires = tuple(
            (every[topic.rate.key], messages.step_wires[topic.delivery.message],
             outlets[topic.name], topic.name in STAMPED_AT_STEP_END)
            for topic in STEP_TOPICS)
        # (every how many steps, fill (True: send), wire message, outlet, stamped at end).
        self.demand_wires = tuple(
            (every[topic.rate.key], *_demand(messages, topic.delivery.message),
             outlets[topic.name], topic.name in STAMPED_AT_STEP_END)
            for topic in DEMAND_TOPICS if topic.name in outlets)
        self.clock_outlet = outlets[topics.CLOCK]
        self.odom_outlet = outlets[topics.GROUND_TRUTH_ODOM]
        self.tf_outlet = outlets.get(topics.TF)
        # The links' /tf, decided as robot_state_publisher decides on each joint_states.
        self.links_schedule: RspSchedule | None = None
        if links is not None and self.tf_outlet is not None:
            messages.use_link_transforms(links)
            self.links_schedule = RspSchedule(rates_hz.get('links_tf', LINKS_TF_RATE_HZ))
        # /atlas/controller_statistics, fed and published only while someone listens.
        self.statistics = statistics
        self.statistics_msg = ControllerStatisticsWire()
        self.statistics_outlet = outlets[topics.CONTROLLER_STATISTICS]

    def publish(self, count: int) -> None:
        """Serialize what is due at step `count` into the outbox."""
        sim = self.sim
        now_ns = sim.sim_time_ns
        outbox = self.outbox
        wanted = outbox.wanted
        if wanted(self.clock_outlet):
            # Only the latest time goes out per flush: every step when paced, about one
            # per FLUSH_PERIOD_S of wall time at real_time_factor 0 (what a sim-time timer
            # sees at real time); spares the recorder one message in five.
            outbox.replace(self.clock_outlet, clock_bytes(now_ns))
        for every, plan in self.fill_plans:
            if count % every == 0:
                plan()
        # Poses and sensors describe the state at the start of the last step (schedule.py).
        sensed_ns = sim.state_time_ns
        for every, message, outlet, at_end in self.step_wires:
            if count % every == 0 and wanted(outlet):
                outbox.add(outlet, message.stamped(now_ns if at_end else sensed_ns))
        for every, fill, message, outlet, at_end in self.demand_wires:
            if count % every == 0 and wanted(outlet) and fill():
                outbox.add(outlet, message.stamped(now_ns if at_end else sensed_ns))
        messages = self.messages
        if count % self.every['odom'] == 0 and wanted(self.odom_outlet):
            outbox.add(self.odom_outlet, messages.odometry(sensed_ns))
        tf_outlet = self.tf_outlet
        if tf_outlet is not None and count % self.every['tf'] == 0 and wanted(tf_outlet):
            outbox.add(tf_outlet, messages.pelvis_tf(sensed_ns))
        links = self.links_schedule  # stamped as the joint_states published with them
        if (links is not None and count % self.every['joint_states'] == 0
                and links.due(now_ns) and wanted(tf_outlet)):
            outbox.add(tf_outlet, messages.links_tf(now_ns))
            outbox.add(tf_outlet, self.head.hokuyo_tf(now_ns))
        self._publish_head(count, sensed_ns, now_ns)
        asi_outlet = self.asi_outlet
        state = None
        if asi_outlet is not None and wanted(asi_outlet):
            self.asi_seq += 1
            assert self.asi is not None  # an outlet only with one
            state = self.asi.state()
            body = encode_asi_state(state, self.asi_seq)
            outbox.add(asi_outlet, len(body).to_bytes(4, 'little') + body)
        recorded = self.asi_recorded_outlet
        if recorded is not None and wanted(recorded):
            self._record_asi_state(count, recorded, state)

    def _publish_head(self, count: int, sensed_ns: int, now_ns: int) -> None:
        """The head's laser scan, spindle joint state and IMU, when due and heard."""
        wanted, outbox, head = self.outbox.wanted, self.outbox, self.head
        scan = self.scan_outlet
        if scan is not None and count % self.every['laser'] == 0 and wanted(scan):
            outbox.add(scan, head.scan(sensed_ns))
        joints = self.head_joint_state_outlet
        if joints is not None and count % self.every['head_joint_states'] == 0 and wanted(joints):
            outbox.add(joints, head.joint_state(now_ns))
        imu = self.head_imu_outlet
        if imu is not None and count % self.every['head_imu'] == 0 and wanted(imu):
            outbox.add(imu, head.imu(sensed_ns))

    def _record_asi_state(self, count: int, outlet: object, state: AsiState | None) -> None:
        """The bag's copy of the state, when due or changed (`state`: built already)."""
        asi = self.asi
        assert asi is not None  # an outlet only with one
        key = asi.status_key()
        if count % self.every['asi_state_recorded'] and key == self.asi_recorded_key:
            return
        self.asi_recorded_key = key
        self.asi_recorded_seq += 1
        body = encode_asi_state(state or asi.state(), self.asi_recorded_seq)
        self.outbox.add(outlet, len(body).to_bytes(4, 'little') + body)

    def publish_step(self, count: int) -> None:
        """After step `count`: the spindle's step, the step's messages, and the command age
        into the statistics' window and, when due, out."""
        self.head.step()
        self.publish(count)
        if not self.outbox.wanted(self.statistics_outlet):
            return
        now_ns = self.sim.sim_time_ns
        stats = self.statistics
        stats.update(now_ns)
        if stats.publication_due(now_ns):
            self.statistics_msg.set_values(stats.age_s, stats.mean_s, stats.variance_s2,
                                           stats.window_s)
            self.outbox.add(self.statistics_outlet, self.statistics_msg.stamped(now_ns))


def _demand(messages: SimMessages, name: str) -> tuple[object, object]:
    """(fill, wire message) of SimMessages' on-demand message `name`."""
    wire, fill = messages.on_demand[name]
    return fill, wire
