"""node/single_instance.py: a second atlas.launch's nodes refuse a name a live node holds.

A stand-in master and node (XML-RPC servers in this process) answer lookupNode and getPid
as ROS 1's do; the simulator's command line refuses before rospy registers anything.
"""

from __future__ import annotations

import socket
import threading
from collections.abc import Iterator
from xmlrpc.server import SimpleXMLRPCServer

import pytest

pytest.importorskip('rosgraph', reason='needs ROS 1 (source ./env.sh)')

from tutorial_atlas_control.cli import atlas_sim
from tutorial_atlas_control.node import single_instance


def _serve(functions: dict) -> tuple[SimpleXMLRPCServer, str]:
    server = SimpleXMLRPCServer(('127.0.0.1', 0), logRequests=False, allow_none=True)
    for name, function in functions.items():
        server.register_function(function, name)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    return server, f'http://127.0.0.1:{server.server_address[1]}'


def _closed_port_uri() -> str:
    with socket.socket() as sock:
        sock.bind(('127.0.0.1', 0))
        return f'http://127.0.0.1:{sock.getsockname()[1]}/'


@pytest.fixture
def graph() -> Iterator[dict[str, str]]:
    """A master knowing /atlas_sim (a node that answers) and /recorder (one that is gone)."""
    node, node_uri = _serve({'getPid': lambda caller: [1, '', 4242]})
    nodes = {'/atlas_sim': node_uri + '/', '/recorder': _closed_port_uri()}

    def lookup(caller: str, name: str) -> list:
        return [1, '', nodes[name]] if name in nodes else [-1, f'unknown node [{name}]', '']

    master, master_uri = _serve({'lookupNode': lookup})
    yield {'master': master_uri, 'node': node_uri + '/'}
    master.shutdown()
    node.shutdown()


def test_a_live_node_is_found_a_gone_or_unknown_one_is_not(graph: dict[str, str]) -> None:
    assert single_instance.live_node_uri(graph['master'], '/atlas_sim') == graph['node']
    assert single_instance.live_node_uri(graph['master'], '/recorder') is None  # gone
    assert single_instance.live_node_uri(graph['master'], '/nobody') is None
    assert single_instance.live_node_uri(_closed_port_uri(), '/atlas_sim') is None  # no master


@pytest.mark.parametrize(('argv', 'name'), [
    (['x'], '/atlas_sim'),
    (['x', '__name:=atlas_sim', '__log:=/tmp/l.log'], '/atlas_sim'),
    (['x', '__name:=sim2'], '/sim2'),
    (['x', '__ns:=/robot'], '/robot/atlas_sim'),
])
def test_the_name_checked_is_the_one_the_node_would_register(argv: list[str],
                                                             name: str) -> None:
    assert single_instance.resolved_node_name('atlas_sim', argv) == name


def test_the_simulator_refuses_before_registering_with_one_line(
        graph: dict[str, str], monkeypatch: pytest.MonkeyPatch,
        capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.setenv('ROS_MASTER_URI', graph['master'])
    monkeypatch.setattr(atlas_sim.rospy, 'init_node', lambda *_: pytest.fail('registered'))
    assert atlas_sim.main(['atlas_sim_node.py', '__name:=atlas_sim']) == 1
    port = int(graph['master'].rsplit(':', 1)[1]) + 1
    assert capsys.readouterr().err == (
        f'atlas_sim: not started: /atlas_sim already runs on the ROS master {graph["master"]} '
        '(an atlas.launch is running there); that one goes on, this launch stops. Stop the '
        'first (Ctrl-C in its terminal) before launching again, or give this one its own '
        f'master: roslaunch -p {port} tutorial_atlas_control atlas.launch (and '
        f'ROS_MASTER_URI=http://localhost:{port} in the terminals that use it)\n')


def test_the_recorders_check_refuses_a_live_name_and_passes_a_gone_one(
        graph: dict[str, str], monkeypatch: pytest.MonkeyPatch,
        capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.setenv('ROS_MASTER_URI', graph['master'])
    assert single_instance.main(['m', 'record_run.sh', 'atlas_sim', '__name:=atlas_sim']) == 1
    assert capsys.readouterr().err == ('record_run.sh: not started: /atlas_sim already runs '
                                       f'on the ROS master {graph["master"]}\n')
    assert single_instance.main(['m', 'record_run.sh', 'recorder', '__name:=recorder']) == 0
    assert capsys.readouterr().err == ''
