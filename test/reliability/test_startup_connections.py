"""Every subscriber that connects at startup is accepted at once.

When the simulator advertises, the recorder, rosout and any tool connect to a dozen of its
topics together. rospy listens with a backlog of 5: the kernel dropped the connections past
it (TcpExtListenOverflows rose by 13 over five launches on a loaded 2-core machine) and the
subscribers retried a second or more later, so a run that ended within that second (the
forced-divergence test) left /atlas/sim_config out of its bag. The simulator now widens
its TCPROS accept queue (node/transport.widen_accept_queue); checked here on the listening
socket itself (`ss`), and by the recorder being connected to all its topics.
"""

from __future__ import annotations

import shutil
import subprocess

import pytest

from support.launch import SIM, TestLaunch
from tutorial_atlas_control.processes import node_api

#: Timing or memory claims: run alone, after make test's parallel part.
pytestmark = pytest.mark.serial

#: rospy's own backlog is 5; a dozen topics connect at once.
MIN_BACKLOG = 64


def tcpros_port(master_uri: str) -> int:
    """The port of the simulator's TCPROS server, as a subscriber learns it."""
    caller = '/test_startup_connections'
    code, message, protocol = node_api(master_uri, SIM, caller).requestTopic(
        caller, '/atlas/joint_states', [['TCPROS']])
    assert code == 1, message
    return int(protocol[2])


def listen_backlog(port: int) -> int:
    """The accept-queue length of the socket listening on `port` (ss's Send-Q column)."""
    result = subprocess.run(['ss', '-ltnH', f'sport = :{port}'], capture_output=True,
                            text=True, check=True)
    rows = [line.split() for line in result.stdout.splitlines() if line.strip()]
    assert len(rows) == 1, result.stdout
    return int(rows[0][2])


@pytest.mark.launch_args('paused:=true')
def test_the_simulator_accepts_a_dozen_connections_at_once(atlas_launch: TestLaunch) -> None:
    if shutil.which('ss') is None:
        pytest.fail('ss (iproute2) is not installed: run `make setup`')
    atlas_launch.wait_ready()  # includes: the recorder is connected to all of SIM's topics
    assert listen_backlog(tcpros_port(atlas_launch.uri)) >= MIN_BACKLOG
