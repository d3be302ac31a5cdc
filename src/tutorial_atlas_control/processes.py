"""The ROS processes the demo, the tests and the benchmark start: a private master,
`atlas.launch`, and stopping everything they started.

Each master runs on a free localhost port, never 11311, so a user's running ROS session is
never touched. roslaunch starts each node in a session of its own (setsid), so neither its
process group nor its session holds its nodes: the process tree is read from /proc's
parent links, remembered while it runs, and whatever outlives roslaunch is killed by pid,
only while that pid still runs the command line it had (a reused pid is someone else's).
"""

from __future__ import annotations

import contextlib
import os
import random
import signal
import socket
import subprocess
import threading
import time
import xmlrpc.client
from collections.abc import Callable, Iterator, Mapping, Sequence
from pathlib import Path
from typing import IO, Self

from tutorial_atlas_control.errors import AtlasControlError

PACKAGE = 'tutorial_atlas_control'
#: Longest wait for a master to answer (s, wall).
MASTER_TIMEOUT_S = 60.0
#: How long roslaunch gets after SIGINT (the recorder closes and indexes its bag) before
#: it and everything it started are killed (s, wall).
STOP_TIMEOUT_S = 20.0
#: A master that accepts a connection but does not answer is not up (s).
XMLRPC_TIMEOUT_S = 5.0
POLL_PERIOD_S = 0.1
#: Where masters' ports are picked (below); the kernel's own picks come from
#: EPHEMERAL_RANGE_FILE's range (32768-60999 unless changed), which must not overlap.
MASTER_PORTS = range(20000, 32768)
EPHEMERAL_RANGE_FILE = Path('/proc/sys/net/ipv4/ip_local_port_range')
DEFAULT_EPHEMERAL_PORTS = range(32768, 61000)
#: Random candidates tried before falling back to a kernel-picked port.
PORT_TRIES = 50


class ProcessError(AtlasControlError):
    """A process did not start or answer in time; the message names it and its log."""


# ------------------------------------------------------------------------- /proc
def _stat(pid: int | str) -> list[str] | None:
    """/proc/PID/stat's fields after the command name (state, parent, ...), None if gone."""
    try:
        stat = (Path('/proc') / str(pid) / 'stat').read_text()
    except OSError:
        return None
    return stat[stat.rindex(')') + 2:].split()


def descendants(pid: int) -> list[int]:
    """Live (non-zombie) processes descended from `pid`, following /proc's parent links."""
    children: dict[int, list[int]] = {}
    for entry in Path('/proc').iterdir():
        fields = _stat(entry.name) if entry.name.isdigit() else None
        if fields is not None and fields[0] != 'Z':
            children.setdefault(int(fields[1]), []).append(int(entry.name))
    found, todo = [], [pid]
    while todo:
        for child in children.get(todo.pop(), []):
            found.append(child)
            todo.append(child)
    return found


def alive(pids: Sequence[int]) -> list[int]:
    """Those of `pids` that still run (zombies count as gone)."""
    return [pid for pid in pids if (fields := _stat(pid)) is not None and fields[0] != 'Z']


def command_line(pid: int) -> str:
    """`pid`'s command line, arguments joined by spaces; '' if it is gone."""
    try:
        raw = (Path('/proc') / str(pid) / 'cmdline').read_bytes()
    except OSError:
        return ''
    return raw.replace(b'\0', b' ').decode(errors='replace').strip()


def rss_kib(pid: int) -> int | None:
    """Resident memory of `pid` (KiB), None if it is gone."""
    try:
        status = (Path('/proc') / str(pid) / 'status').read_text()
    except OSError:
        return None
    for line in status.splitlines():
        if line.startswith('VmRSS:'):
            return int(line.split()[1])
    return None


def cpu_seconds(pid: int, reaped_children: bool = False) -> float:
    """CPU time `pid` has used (user + system, s), with that of the children it has waited for
    if `reaped_children`; 0.0 if it is gone."""
    fields = _stat(pid)
    if fields is None:
        return 0.0
    ticks = int(fields[11]) + int(fields[12])
    if reaped_children:
        ticks += int(fields[13]) + int(fields[14])
    return ticks / os.sysconf('SC_CLK_TCK')


def kill_if_unchanged(pids: Mapping[int, str]) -> None:
    """SIGKILL each pid that still runs the command line recorded for it."""
    for pid, command in pids.items():
        if command and command_line(pid) == command and alive([pid]):
            with contextlib.suppress(ProcessLookupError, PermissionError):
                os.kill(pid, signal.SIGKILL)


def stop_tree(process: subprocess.Popen, timeout_s: float = STOP_TIMEOUT_S,
              known: Mapping[int, str] | None = None) -> bool:
    """SIGINT `process`'s group, as Ctrl-C in a terminal; SIGKILL it after `timeout_s`.

    Then SIGKILL whatever it started that still runs (its tree now, plus `known`: pid ->
    command line of processes seen under it earlier). Returns False if it had to be killed.
    """
    tree = dict(known or {})
    tree.update({pid: command_line(pid) for pid in descendants(process.pid)})
    clean = True
    if process.poll() is None:
        _signal_group(process, signal.SIGINT)
        try:
            process.wait(timeout=timeout_s)
        except subprocess.TimeoutExpired:
            clean = False
            tree.update({pid: command_line(pid) for pid in descendants(process.pid)})
            _signal_group(process, signal.SIGKILL)
            process.wait()
    kill_if_unchanged(tree)
    return clean


def default_sigint() -> None:
    """`preexec_fn` for a child stopped with SIGINT: SIGINT back to its default action,
    and unblocked.

    A child inherits an ignored SIGINT (e.g. from a shell's background job), and a shell
    cannot even trap a signal ignored at its start; it also inherits the starting thread's
    signal mask, and a SIGINT blocked there stays pending forever (Python does not unblock
    it). stop_tree's Ctrl-C must reach it.
    """
    signal.signal(signal.SIGINT, signal.SIG_DFL)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})


def run_to_end(command: Sequence[str], env: Mapping[str, str], timeout_s: float,
               stop_timeout_s: float = STOP_TIMEOUT_S) -> int:
    """Run `command` (in a session of its own) to its end; its exit status.

    On Ctrl-C or after `timeout_s` its tree is stopped (stop_tree) before the
    KeyboardInterrupt or subprocess.TimeoutExpired goes on: the child must not outlive the
    caller, who may be interrupted alone (`kill -INT`, not a terminal's Ctrl-C to the group).
    A Ctrl-C arriving while the child is being started waits until its handle is held.
    """
    interrupted: list[int] = []
    process: subprocess.Popen | None = None
    try:
        with _sigint_deferred(interrupted):
            process = subprocess.Popen(list(command), env=dict(env), start_new_session=True,
                                       preexec_fn=default_sigint)
        if interrupted:
            raise KeyboardInterrupt
        return process.wait(timeout=timeout_s)
    except BaseException:
        if process is not None:
            stop_tree(process, stop_timeout_s)
        raise


@contextlib.contextmanager
def _sigint_deferred(caught: list[int]) -> Iterator[None]:
    """Within: SIGINT is noted in `caught` instead of raising KeyboardInterrupt (only where
    Python's default handler is installed, and only in the main thread, as signal requires)."""
    deferring = (threading.current_thread() is threading.main_thread()
                 and signal.getsignal(signal.SIGINT) is signal.default_int_handler)
    if deferring:
        signal.signal(signal.SIGINT, lambda signum, _frame: caught.append(signum))
    try:
        yield
    finally:
        if deferring:
            signal.signal(signal.SIGINT, signal.default_int_handler)


def _signal_group(process: subprocess.Popen, sig: int) -> None:
    """`sig` to the process group `process` leads (started with start_new_session)."""
    try:
        os.killpg(process.pid, sig)
    except ProcessLookupError:
        pass
    except PermissionError:  # not a group leader after all: the process alone
        process.send_signal(sig)


# ------------------------------------------------------------------------- a master
def _ephemeral_ports(path: Path = EPHEMERAL_RANGE_FILE) -> range:
    """The ports the kernel picks from for bind(0) and connect(): Linux's
    ip_local_port_range (its default when unreadable)."""
    try:
        low, high = (int(field) for field in path.read_text().split())
    except (OSError, ValueError):
        return DEFAULT_EPHEMERAL_PORTS
    return range(low, high + 1)


def free_local_port(choose: Callable[[range], int] = random.choice) -> int:
    """A TCP port free on the loopback interface now, for a master, picked below the
    kernel's ephemeral range.

    A port of that range that is free now may be a node's by the time roscore binds it
    (every node's XML-RPC and TCPROS server binds port 0), and roslaunch takes any XML-RPC
    server that answers getPid for a running master: it then starts no master and its
    nodes never register. Below the range only other explicit picks compete.
    """
    candidates = range(MASTER_PORTS.start, min(MASTER_PORTS.stop, _ephemeral_ports().start))
    for _ in range(PORT_TRIES if candidates else 0):
        if _can_bind_local(port := choose(candidates)):
            return port
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as sock:  # all taken: the kernel's
        sock.bind(('127.0.0.1', 0))
        return int(sock.getsockname()[1])


def _can_bind_local(port: int) -> bool:
    """Whether `port` can be bound on the loopback interface now."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as sock:
        try:
            sock.bind(('127.0.0.1', port))
        except OSError:
            return False
        return True


def ros_environment(port: int, ros_log_dir: Path | None = None,
                    base: Mapping[str, str] | None = None) -> dict[str, str]:
    """The environment of a ROS client of the master on localhost:`port`."""
    env = dict(os.environ if base is None else base)
    env['ROS_MASTER_URI'] = f'http://localhost:{port}'
    env.setdefault('ROS_HOSTNAME', 'localhost')
    if ros_log_dir is not None:
        env['ROS_LOG_DIR'] = str(ros_log_dir)
    return env


class _TimeoutTransport(xmlrpc.client.Transport):
    def make_connection(self, host: object) -> object:
        connection = super().make_connection(host)
        connection.timeout = XMLRPC_TIMEOUT_S
        return connection


def system_state(master_uri: str) -> tuple[dict[str, list[str]], dict[str, list[str]]]:
    """(publishers, subscribers) of each topic: the master's getSystemState.

    Raises OSError while the master does not answer.
    """
    proxy = xmlrpc.client.ServerProxy(master_uri, transport=_TimeoutTransport())
    code, message, state = proxy.getSystemState('/tutorial_atlas_control_processes')
    if code != 1:
        raise OSError(f'{master_uri}: {message}')
    return dict(state[0]), dict(state[1])


def node_api(master_uri: str, node: str, caller: str) -> xmlrpc.client.ServerProxy:
    """`node`'s XML-RPC API (getBusInfo, requestTopic), looked up on the master as `caller`.

    Raises OSError while the master does not answer or does not know `node`.
    """
    proxy = xmlrpc.client.ServerProxy(master_uri, transport=_TimeoutTransport())
    code, message, uri = proxy.lookupNode(caller, node)
    if code != 1:
        raise OSError(f'{node}: {message}')
    return xmlrpc.client.ServerProxy(uri, transport=_TimeoutTransport())


def wait_until(condition: Callable[[], bool], timeout_s: float, failure: str,
               check: Callable[[], None] | None = None) -> None:
    """Poll `condition` until true, for at most `timeout_s` (wall).

    Raises ProcessError(f'{failure} within {timeout_s} s'); `check` runs before each poll
    and raises if waiting is pointless (a process died).
    """
    deadline = time.monotonic() + timeout_s
    while True:
        if check is not None:
            check()
        if condition():
            return
        if time.monotonic() > deadline:
            raise ProcessError(f'{failure} within {timeout_s:.0f} s')
        time.sleep(POLL_PERIOD_S)


def master_online(master_uri: str) -> bool:
    try:
        system_state(master_uri)
    except OSError:
        return False
    return True


class _RosProcess:
    """A ROS process (`env` names its master) whose output goes to a log file; stopped
    with its whole tree."""

    name = 'process'

    def __init__(self, command: Sequence[str], env: Mapping[str, str], log_path: Path) -> None:
        self.env = dict(env)
        self.log_path = log_path
        log_path.parent.mkdir(parents=True, exist_ok=True)
        self._log: IO[str] = log_path.open('w')
        #: pid -> command line of every process seen under this one (see stop_tree).
        self.known: dict[int, str] = {}
        try:
            self.process = subprocess.Popen(
                list(command), env=self.env, stdout=self._log, stderr=subprocess.STDOUT,
                stdin=subprocess.DEVNULL, start_new_session=True, preexec_fn=default_sigint)
        except FileNotFoundError:
            self._log.close()
            raise ProcessError(f'{command[0]} is not on PATH; run `make setup` and '
                               '`source ./env.sh`') from None

    @property
    def uri(self) -> str:
        return self.env['ROS_MASTER_URI']

    def subscribers(self, topic: str) -> list[str]:
        """Nodes subscribed to `topic` now; [] while the master is not up."""
        try:
            return system_state(self.uri)[1].get(topic, [])
        except OSError:
            return []

    def pids(self) -> list[int]:
        """This process and everything it started that still runs."""
        tree = descendants(self.process.pid)
        self.known.update({pid: command_line(pid) for pid in tree})
        return alive([self.process.pid, *tree])

    def pid_of(self, fragment: str) -> int | None:
        """The process, or one it started, whose command line contains `fragment`."""
        for pid in self.pids():
            if fragment in self.known.get(pid, ''):
                return pid
        return None

    def output(self) -> str:
        """Everything the process has written so far (also after close())."""
        if not self._log.closed:
            self._log.flush()
        return self.log_path.read_text(errors='replace')

    def tail(self, lines: int = 15) -> str:
        return '\n'.join(self.output().splitlines()[-lines:])

    def check_running(self) -> None:
        """ProcessError naming the log if the process has exited."""
        status = self.process.poll()
        if status is not None:
            raise ProcessError(f'{self.name} exited with status {status}; see {self.log_path}')

    def interrupt(self, timeout_s: float = STOP_TIMEOUT_S) -> float:
        """SIGINT, as Ctrl-C; the seconds until every process of the tree was gone
        (`timeout_s` if some were not: close() kills them)."""
        pids = self.pids()  # before: once the leader is gone, its orphans have no parent link
        started_s = time.monotonic()
        _signal_group(self.process, signal.SIGINT)
        while alive(pids) and time.monotonic() - started_s < timeout_s:
            time.sleep(0.02)
        gone_s = time.monotonic() - started_s
        with contextlib.suppress(subprocess.TimeoutExpired):
            self.process.wait(timeout=max(0.0, timeout_s - gone_s))
        return gone_s

    def close(self, timeout_s: float = STOP_TIMEOUT_S) -> bool:
        """Stop the tree (see stop_tree); False if it had to be killed. Idempotent."""
        self.pids()
        clean = stop_tree(self.process, timeout_s, self.known)
        self._log.close()
        return clean

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


class RosMaster(_RosProcess):
    """`roscore` on a free localhost port; `env` is what its clients need."""

    name = 'roscore'

    def __init__(self, log_path: Path, ros_log_dir: Path | None = None,
                 extra_env: Mapping[str, str] | None = None) -> None:
        self.port = free_local_port()
        env = ros_environment(self.port, ros_log_dir)
        env.update(extra_env or {})
        super().__init__(['roscore', '-p', str(self.port)], env, log_path)

    def wait_online(self, timeout_s: float = MASTER_TIMEOUT_S) -> None:
        wait_until(lambda: master_online(self.uri), timeout_s,
                   f'roscore -p {self.port} did not answer (see {self.log_path})',
                   self.check_running)


class AtlasLaunch(_RosProcess):
    """`roslaunch tutorial_atlas_control atlas.launch ARG:=VALUE ...`.

    Without `master` roslaunch starts a master of its own on a free port; with a RosMaster,
    it waits for that master (several launches may then run on it in turn); with another
    AtlasLaunch, it runs as a second terminal's plain `roslaunch` does: on the master that
    launch started, without starting one. `base_env`, the
    environment to start from without a master (default: this process's), lets a caller
    run another workspace's package, e.g. an install space's.
    """

    name = 'roslaunch'

    def __init__(self, log_path: Path, args: Mapping[str, object], *,
                 master: RosMaster | AtlasLaunch | None = None,
                 ros_log_dir: Path | None = None,
                 launch_file: str = 'atlas.launch',
                 base_env: Mapping[str, str] | None = None) -> None:
        if master is None:
            self.port = free_local_port()
            env, wait = ros_environment(self.port, base=base_env), []
        else:
            wait = ['--wait'] if isinstance(master, RosMaster) else []
            self.port, env = master.port, dict(master.env)
        if ros_log_dir is not None:
            env['ROS_LOG_DIR'] = str(ros_log_dir)
        self.args = {key: str(value) for key, value in args.items()}
        target = [launch_file] if os.path.sep in launch_file else [PACKAGE, launch_file]
        super().__init__(['roslaunch', '-p', str(self.port), *wait, *target,
                          *(f'{key}:={value}' for key, value in self.args.items())],
                         env, log_path)

    def wait_master(self, timeout_s: float = MASTER_TIMEOUT_S) -> None:
        """Until the launch's master answers (roslaunch starts it first)."""
        wait_until(lambda: master_online(self.uri), timeout_s,
                   f'the ROS master of roslaunch -p {self.port} did not answer '
                   f'(see {self.log_path})', self.check_running)

