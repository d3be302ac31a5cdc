"""The simulator node across a restart of the ROS master.

ROS 1 nodes register with the master once: after `roscore` is restarted, the new master
knows none of them, and new clients (`rostopic echo`, traj_yaml.py) cannot find the
simulator, while everything already connected goes on. This watch asks the master for its
pid every POLL_S: when it stops answering, one line says so (the simulation goes on over
its connections); when a master answers again at the same URI with another pid, the node
registers again its publications, subscriptions (connecting to the publishers the master
lists) and services, and sets again the parameters that were set when it started and that
the new master lacks (the launch's: /use_sim_time, the gains, ...). One line says so.

Only this node comes back: the recorder and robot_state_publisher (roscpp) keep their
connections but stay unknown to the new master.
"""

from __future__ import annotations

import threading
import xmlrpc.client
from collections.abc import Callable
from typing import Any

import rosgraph
import rospy
from rospy.impl.registration import (
    RegManager,
    get_registration_listeners,
    get_service_manager,
    get_topic_manager,
)

__all__ = ['MasterWatch', 'back_line', 'gone_line', 'start_master_watch']

#: Wall seconds between looks at the master.
POLL_S = 1.0
#: Wall seconds an XML-RPC call to the master may take before it counts as gone.
CALL_TIMEOUT_S = 3.0
#: Polls in a row without an answer before the master counts as gone: one slow answer
#: (a master busy on a loaded machine) is no restart.
MISSES_FOR_GONE = 2
#: Parameters every master sets itself: never set again from the old one.
MASTER_OWN_PARAMS = frozenset({'run_id', 'rosdistro', 'rosversion', 'roslaunch'})


def gone_line(uri: str) -> str:
    return (f'the ROS master at {uri} went away: the simulation goes on over the connections '
            f'already made; new clients cannot find this node until a master is back at {uri}')


def back_line(uri: str, counts: tuple[int, int, int, int]) -> str:
    publications, subscriptions, services, parameters = counts
    return (f'a ROS master is back at {uri}: registered again {publications} publications, '
            f'{subscriptions} subscriptions and {services} services, and set again '
            f'{parameters} parameters')


class _Transport(xmlrpc.client.Transport):
    def make_connection(self, host: Any) -> Any:
        connection = super().make_connection(host)
        connection.timeout = CALL_TIMEOUT_S
        return connection


class MasterWatch:
    """Which master answers at `uri` (its pid), and what to do when that changes.

    `pid_now` is None while no master answers; `reregister` returns the counts of
    back_line. No threads here: start_master_watch polls.
    """

    def __init__(self, uri: str, first_pid: int | None, log_warn: Callable[[str], None],
                 log_info: Callable[[str], None]) -> None:
        self.uri = uri
        self.pid = first_pid
        self.gone = False
        self.misses = 0
        self._warn, self._info = log_warn, log_info

    def update(self, pid_now: int | None,
               reregister: Callable[[], tuple[int, int, int, int]]) -> None:
        if pid_now is None:
            self.misses += 1
            if not self.gone and self.misses >= MISSES_FOR_GONE:
                self.gone = True
                self._warn(gone_line(self.uri))
            return
        self.misses = 0
        if pid_now != self.pid:  # a new master, seen down or not (a quick restart)
            counts = reregister()
            self.pid, self.gone = pid_now, False
            self._info(back_line(self.uri, counts))
        elif self.gone:  # the same master answered again (a network hiccup)
            self.gone = False
            self._info(f'the ROS master at {self.uri} answers again')


def _master_pid(master: xmlrpc.client.ServerProxy, caller_id: str) -> int | None:
    try:
        code, _, pid = master.getPid(caller_id)
    except (OSError, xmlrpc.client.Error):
        return None
    return int(pid) if code == 1 else None


def _reregister(master: xmlrpc.client.ServerProxy, caller_id: str, node_uri: str,
                parameters: dict[str, Any]) -> tuple[int, int, int, int]:
    """Register the node's topics and services again as rospy's RegManager does at start,
    connect to the publishers the new master lists, set the missing parameters."""
    topic_manager, service_manager = get_topic_manager(), get_service_manager()
    with topic_manager.lock, service_manager.lock:
        publications = topic_manager.get_publications()
        subscriptions = topic_manager.get_subscriptions()
        services = service_manager.get_services()
    for topic, data_type in publications:
        master.registerPublisher(caller_id, topic, data_type, node_uri)
    managers = [listener for listener in get_registration_listeners().listeners
                if isinstance(listener, RegManager)]
    for topic, data_type in subscriptions:
        code, _, publishers = master.registerSubscriber(caller_id, topic, data_type, node_uri)
        if code == 1 and publishers:
            for manager in managers:
                manager.publisher_update(topic, publishers)
    for name, service_uri in services:
        master.registerService(caller_id, name, service_uri, node_uri)
    set_again = 0
    for key, value in parameters.items():
        code, _, present = master.hasParam(caller_id, f'/{key}')
        if code == 1 and not present:
            master.setParam(caller_id, f'/{key}', value)
            set_again += 1
    return len(publications), len(subscriptions), len(services), set_again


def start_master_watch(stop: threading.Event) -> None:
    """Snapshot the parameters now, then watch the master from a daemon thread until
    `stop` is set."""
    uri = rosgraph.get_master_uri()
    caller_id, node_uri = rospy.get_name(), rospy.core.get_node_uri()
    master = xmlrpc.client.ServerProxy(uri, transport=_Transport(), allow_none=True)
    # From the master itself: rospy.get_param('/') answers from rospy's parameter cache,
    # which holds only the parameters rospy subscribed to.
    try:
        code, _, tree = master.getParam(caller_id, '/')
    except (OSError, xmlrpc.client.Error):
        code, tree = 0, {}
    parameters = {key: value for key, value in (tree if code == 1 else {}).items()
                  if key not in MASTER_OWN_PARAMS}
    watch = MasterWatch(uri.rstrip('/'), _master_pid(master, caller_id), rospy.logwarn,
                        rospy.loginfo)

    def run() -> None:
        while not stop.wait(POLL_S):
            pid = _master_pid(master, caller_id)
            if stop.is_set() or rospy.is_shutdown():
                return
            try:
                watch.update(pid, lambda: _reregister(master, caller_id, node_uri, parameters))
            except (OSError, xmlrpc.client.Error) as err:  # gone again half-way: next poll
                rospy.logwarn(f'registering again with the ROS master at {uri} failed '
                              f'({err}); trying again')

    threading.Thread(target=run, name='master_watch', daemon=True).start()
