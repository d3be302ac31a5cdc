"""processes: finding and stopping a launch's process tree (roslaunch setsid()s its nodes)."""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import threading
import xmlrpc.server
from collections.abc import Iterator
from pathlib import Path

import pytest

from tutorial_atlas_control.errors import AtlasControlError
from tutorial_atlas_control.processes import (
    MASTER_PORTS,
    AtlasLaunch,
    ProcessError,
    _ephemeral_ports,
    alive,
    command_line,
    cpu_seconds,
    default_sigint,
    descendants,
    free_local_port,
    node_api,
    rss_kib,
    run_to_end,
    stop_tree,
    wait_until,
)

#: Guard (s) for child processes to start or be reaped, however busy the machine is.
GUARD_S = 30.0
#: A parent that ignores SIGINT, with a child in a session of its own that ignores it too
#: (as a roslaunch node that hangs on shutdown) and an ordinary child.
STUBBORN_TREE = "trap '' INT; setsid bash -c \"trap '' INT; sleep 300\" & sleep 300 & wait"


def session(pid: int) -> int:
    return int((Path('/proc') / str(pid) / 'stat').read_text().rsplit(')', 1)[1].split()[3])


def test_descendants_follow_parents_across_sessions_and_alive_drops_the_dead() -> None:
    parent = subprocess.Popen(['bash', '-c', 'setsid sleep 30 & sleep 30 & wait'])
    try:
        wait_until(lambda: len({session(pid) for pid in descendants(parent.pid)}) == 2,
                   GUARD_S, 'one child did not move to a session of its own')
        found = descendants(parent.pid)
        assert len(found) == 2, found
        assert alive(found) == found
    finally:
        for pid in [parent.pid, *descendants(parent.pid)]:
            subprocess.run(['kill', '-9', str(pid)], check=False)
        parent.wait()
    wait_until(lambda: alive(found) == [], GUARD_S, 'init did not reap the orphans')


def test_stop_tree_kills_what_ignores_sigint_including_other_sessions() -> None:
    parent = subprocess.Popen(['bash', '-c', STUBBORN_TREE], start_new_session=True)
    # Both sleeps running: before that, a forked child still shows its parent's command line
    # and has not set its trap yet.
    wait_until(
        lambda: [command_line(pid) for pid in descendants(parent.pid)].count('sleep 300') == 2,
        GUARD_S, 'children did not start')
    children = descendants(parent.pid)
    assert stop_tree(parent, timeout_s=0.5) is False, 'it had to be killed'
    assert parent.poll() == -signal.SIGKILL
    wait_until(lambda: alive(children) == [], GUARD_S, 'children survived')


def test_stop_tree_is_clean_when_sigint_stops_the_tree() -> None:
    # As roslaunch does: SIGINT handled by stopping the children, then exiting. The trap is
    # set before the child starts, and the child has exec'd before the signal is sent.
    parent = subprocess.Popen(['bash', '-c', "trap 'kill $!; exit 130' INT; sleep 300 & wait"],
                              start_new_session=True, preexec_fn=default_sigint)
    wait_until(lambda: [command_line(pid) for pid in descendants(parent.pid)] == ['sleep 300'],
               GUARD_S, 'the child did not start')
    children = descendants(parent.pid)
    assert stop_tree(parent, timeout_s=GUARD_S) is True
    wait_until(lambda: alive(children) == [], GUARD_S, 'children survived')


def test_a_reused_pid_is_left_alone() -> None:
    """Only pids still running their recorded command line are killed."""
    bystander = subprocess.Popen(['sleep', '300'])
    finished = subprocess.Popen(['true'])
    finished.wait()
    try:
        stop_tree(finished, known={bystander.pid: 'something else'})
        assert alive([bystander.pid]) == [bystander.pid]
    finally:
        bystander.kill()
        bystander.wait()


def test_command_line_and_memory_of_a_process() -> None:
    child = subprocess.Popen(['sleep', '300'])
    try:
        wait_until(lambda: command_line(child.pid) == 'sleep 300', GUARD_S, 'no command line')
        assert rss_kib(child.pid) > 0
    finally:
        child.kill()
        child.wait()
    assert command_line(child.pid) == '' and rss_kib(child.pid) is None


def test_cpu_seconds_counts_reaped_children_only_when_asked() -> None:
    """A shell that has waited for a 0.3 CPU s child: its own time is ~0, with the reaped
    child's the busy loop's (a guard on a starved script's work measures this)."""
    busy = 'import time\nt = time.process_time()\nwhile time.process_time() - t < 0.3: pass'
    shell = subprocess.Popen(['sh', '-c', f'python3 -c "{busy}"; exec sleep 300'])
    try:
        wait_until(lambda: command_line(shell.pid) == 'sleep 300', GUARD_S, 'no sleep')
        assert cpu_seconds(shell.pid) < 0.1
        assert cpu_seconds(shell.pid, reaped_children=True) >= 0.29
    finally:
        shell.kill()
        shell.wait()
    assert cpu_seconds(shell.pid, reaped_children=True) == 0.0


def test_free_local_port_can_be_bound_and_is_below_the_kernel_s_own_picks() -> None:
    port = free_local_port()
    assert MASTER_PORTS.start <= port < _ephemeral_ports().start
    with socket.socket() as sock:
        sock.bind(('127.0.0.1', port))


def test_a_busy_port_in_the_range_is_passed_over() -> None:
    with socket.socket() as taken:
        for port in range(MASTER_PORTS.start, MASTER_PORTS.stop):
            try:
                taken.bind(('127.0.0.1', port))
            except OSError:
                continue
            break
        taken.listen()
        picks = iter([port, port + 1 if port + 1 in MASTER_PORTS else port - 1])
        picked = free_local_port(lambda ports: next(picks))
    assert picked != port


def test_the_ephemeral_range_is_read_from_proc_or_defaults(tmp_path: Path) -> None:
    table = tmp_path / 'ip_local_port_range'
    table.write_text('40000\t50000\n')
    assert _ephemeral_ports(table) == range(40000, 50001)
    assert _ephemeral_ports(tmp_path / 'missing') == range(32768, 61000)


def test_wait_until_names_what_did_not_happen() -> None:
    with pytest.raises(ProcessError, match=r'^the robot did not stand within 0 s$'):
        wait_until(lambda: False, 0.0, 'the robot did not stand')
    assert issubclass(ProcessError, AtlasControlError)


def test_a_launch_that_exits_is_reported_with_its_log(tmp_path: Path,
                                                      monkeypatch: pytest.MonkeyPatch) -> None:
    """A stand-in `roslaunch` on PATH that fails at once: one line naming the log."""
    fake = tmp_path / 'bin' / 'roslaunch'
    fake.parent.mkdir()
    fake.write_text('#!/bin/sh\necho "RLException: $*"\nexit 1\n')
    fake.chmod(0o755)
    monkeypatch.setenv('PATH', f'{fake.parent}{os.pathsep}{os.environ["PATH"]}')
    with AtlasLaunch(tmp_path / 'launch.log', {'gui': 'false'}) as launch:
        with pytest.raises(ProcessError) as err:
            launch.wait_master(GUARD_S)
        assert str(err.value) == f'roslaunch exited with status 1; see {tmp_path / "launch.log"}'
        assert f'-p {launch.port} tutorial_atlas_control atlas.launch gui:=false' in launch.output()


def test_a_missing_roslaunch_is_one_line(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv('PATH', str(tmp_path))
    with pytest.raises(ProcessError, match=r'^roslaunch is not on PATH; run `make setup`'):
        AtlasLaunch(tmp_path / 'launch.log', {})


@pytest.fixture
def fake_master() -> Iterator[str]:
    """A master on localhost that knows one node, /known, itself an XML-RPC server whose
    getBusInfo answers one connection row."""
    servers = []
    for _ in range(2):
        server = xmlrpc.server.SimpleXMLRPCServer(('127.0.0.1', 0), logRequests=False)
        threading.Thread(target=server.serve_forever, daemon=True).start()
        servers.append(server)
    master, node = servers
    node_uri = f'http://127.0.0.1:{node.server_address[1]}/'
    node.register_function(lambda caller: [1, '', [[1, '/sink', 'o', 'TCPROS', '/t']]],
                           'getBusInfo')
    master.register_function(
        lambda caller, name: [1, '', node_uri] if name == '/known'
        else [-1, f'unknown node [{name}]', ''], 'lookupNode')
    try:
        yield f'http://127.0.0.1:{master.server_address[1]}/'
    finally:
        for server in servers:
            server.shutdown()
            server.server_close()


def test_node_api_reaches_a_known_node_and_names_an_unknown_one(fake_master: str) -> None:
    code, _, rows = node_api(fake_master, '/known', '/caller').getBusInfo('/caller')
    assert (code, rows) == (1, [[1, '/sink', 'o', 'TCPROS', '/t']])
    with pytest.raises(OSError, match=r'^/gone: unknown node \[/gone\]$'):
        node_api(fake_master, '/gone', '/caller')


def test_node_api_without_a_master_is_an_os_error() -> None:
    with pytest.raises(OSError):
        node_api(f'http://127.0.0.1:{free_local_port()}/', '/known', '/caller')


def _pid_written_to(path: Path) -> int:
    wait_until(lambda: path.exists() and path.read_text().strip() != '', GUARD_S,
               f'the child did not write {path}')
    return int(path.read_text())


def test_run_to_end_returns_the_exit_status() -> None:
    assert run_to_end(['bash', '-c', 'exit 3'], os.environ, GUARD_S) == 3


def test_run_to_end_stops_the_child_when_its_caller_alone_gets_ctrl_c(tmp_path: Path) -> None:
    pid_file = tmp_path / 'pid'
    child = f'echo $$ > {pid_file}; exec sleep 300'

    def interrupt_once_started() -> None:
        _pid_written_to(pid_file)
        os.kill(os.getpid(), signal.SIGINT)  # to this process only, as `kill -INT`

    threading.Thread(target=interrupt_once_started, daemon=True).start()
    with pytest.raises(KeyboardInterrupt):
        run_to_end(['bash', '-c', child], os.environ, GUARD_S, stop_timeout_s=GUARD_S)
    assert not alive([_pid_written_to(pid_file)])


def test_run_to_end_stops_the_child_at_its_timeout(tmp_path: Path) -> None:
    pid_file = tmp_path / 'pid'
    with pytest.raises(subprocess.TimeoutExpired) as timeout:
        run_to_end(['bash', '-c', f'echo $$ > {pid_file}; exec sleep 300'], os.environ, 1.0)
    assert timeout.value.cmd[0] == 'bash'
    assert not alive([_pid_written_to(pid_file)])


def test_a_ctrl_c_while_the_child_starts_is_raised_once_it_can_be_stopped(
        monkeypatch: pytest.MonkeyPatch) -> None:
    real_popen = subprocess.Popen
    started: list[int] = []

    def popen_then_ctrl_c(*args: object, **kwargs: object) -> subprocess.Popen:
        process = real_popen(*args, **kwargs)  # type: ignore[call-overload]
        started.append(process.pid)
        os.kill(os.getpid(), signal.SIGINT)  # lands before Popen has returned its handle
        return process

    monkeypatch.setattr(subprocess, 'Popen', popen_then_ctrl_c)
    with pytest.raises(KeyboardInterrupt):
        run_to_end(['sleep', '300'], os.environ, GUARD_S, stop_timeout_s=GUARD_S)
    assert started
    assert not alive(started)
