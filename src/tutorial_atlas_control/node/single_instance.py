"""One atlas.launch per master: a node refuses to start under a name a live node holds.

ROS 1's master hands a name to the newest node that registers it and shuts the older one
down. A second atlas.launch on a master the first launch started would so stop the first
simulator, whose required node ends the first launch, master included: both launches
would be left without a working setup. So the simulator, the recorder and
robot_state_publisher ask the master first, before they register anything, whether a
node of their name is registered there and answers; if one does, they refuse in one line
and the first launch goes on untouched. A registration whose node no longer answers (a
node killed without unregistering) is no reason to refuse.
"""

from __future__ import annotations

import os
import sys
import xmlrpc.client
from collections.abc import Sequence
from typing import Any
from urllib.parse import urlparse

import rosgraph
import rosgraph.names

__all__ = ['companion_refusal_line', 'live_node_uri', 'refusal_line', 'refuse_if_running',
           'resolved_node_name']

#: Wall seconds an XML-RPC call (to the master or to the registered node) may take.
CALL_TIMEOUT_S = 3.0
#: The caller id of these look-ups, as the master logs it.
CALLER_ID = '/tutorial_atlas_control_single_instance'
#: The master's port when ROS_MASTER_URI names none (ROS 1's default).
DEFAULT_MASTER_PORT = 11311


class _Transport(xmlrpc.client.Transport):
    def make_connection(self, host: Any) -> Any:
        connection = super().make_connection(host)
        connection.timeout = CALL_TIMEOUT_S
        return connection


def _proxy(uri: str) -> xmlrpc.client.ServerProxy:
    return xmlrpc.client.ServerProxy(uri, transport=_Transport())


def live_node_uri(master_uri: str, name: str) -> str | None:
    """The XML-RPC URI of the node registered as `name` on the master, if it answers.

    None when the master does not answer, knows no such node, or the node it lists does
    not answer (gone without unregistering).
    """
    try:
        code, _message, uri = _proxy(master_uri).lookupNode(CALLER_ID, name)
        if code != 1:
            return None
        code, _message, _pid = _proxy(uri).getPid(CALLER_ID)
    except (OSError, xmlrpc.client.Error):
        return None
    return str(uri) if code == 1 else None


def _port_for_another_master(master_uri: str) -> int:
    """A port to suggest for a master of its own: the next one after this master's."""
    port = urlparse(master_uri).port or DEFAULT_MASTER_PORT
    return port + 1


def refusal_line(prog: str, name: str, master_uri: str) -> str:
    """The one line of a node that does not start because `name` runs on the master."""
    port = _port_for_another_master(master_uri)
    return (f'{prog}: not started: {name} already runs on the ROS master {master_uri} '
            '(an atlas.launch is running there); that one goes on, this launch stops. '
            'Stop the first (Ctrl-C in its terminal) before launching again, or give this '
            f'one its own master: roslaunch -p {port} tutorial_atlas_control atlas.launch '
            f'(and ROS_MASTER_URI=http://localhost:{port} in the terminals that use it)')


def resolved_node_name(default: str, argv: Sequence[str]) -> str:
    """The node's global name as rospy and roscpp resolve it: `__name:=` and `__ns:=` of
    `argv` (roslaunch's), else `default` in $ROS_NAMESPACE."""
    mappings = rosgraph.names.load_mappings(list(argv))
    namespace = rosgraph.names.get_ros_namespace(argv=list(argv))
    return rosgraph.names.ns_join(namespace, mappings.get('__name', default))


def companion_refusal_line(prog: str, name: str, master_uri: str) -> str:
    """The shorter line of the launch's other nodes: the simulator's says what to do."""
    return f'{prog}: not started: {name} already runs on the ROS master {master_uri}'


def refuse_if_running(prog: str, default_name: str, argv: Sequence[str], *,
                      full: bool = True) -> bool:
    """True, after printing refusal_line (companion_refusal_line unless `full`) on stderr,
    when a live node holds the node's name on the master."""
    name = resolved_node_name(default_name, argv)
    master_uri = rosgraph.get_master_uri(env=os.environ, argv=list(argv)).rstrip('/')
    if live_node_uri(master_uri, name) is None:
        return False
    line = refusal_line if full else companion_refusal_line
    print(line(prog, name, master_uri), file=sys.stderr)
    return True


def main(argv: Sequence[str] | None = None) -> int:
    """`python3 -m tutorial_atlas_control.node.single_instance PROG NAME [ROS args]`: exit 1
    with refusal_line when NAME runs on the master (record_run.sh's check), else 0."""
    args = list(sys.argv if argv is None else argv)
    plain = [arg for arg in args[1:] if ':=' not in arg]
    if len(plain) != 2:
        print('usage: python3 -m tutorial_atlas_control.node.single_instance PROG NAME '
              '[name:=value ...]', file=sys.stderr)
        return 2
    prog, name = plain
    try:
        return 1 if refuse_if_running(prog, name, args, full=False) else 0
    except KeyboardInterrupt:  # the launch stopping meanwhile (its simulator refused)
        return 130


if __name__ == '__main__':
    sys.exit(main())
