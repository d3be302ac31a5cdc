"""ROS plumbing for the benchmark: a private master, launching the simulator, cleanup.

Everything here is bounded in time and cleans up what it started: the master and each
launch run in their own process group (their own session), which is signalled as a
group on the way out. Nothing here touches another developer's master or processes.
"""

from __future__ import annotations

import os
import shutil
import signal
import socket
import subprocess
import sys
import time
import xmlrpc.client
from dataclasses import dataclass, field
from pathlib import Path

#: Longest wait for the master to answer (s, wall).
MASTER_TIMEOUT_S = 30.0
#: Longest wait for the simulator to publish /clock and the recorder to subscribe (s).
READY_TIMEOUT_S = 60.0
#: How long a launch gets to shut down after SIGINT (rosbag closes and indexes the bag).
STOP_TIMEOUT_S = 20.0

REPO_DIR = Path(__file__).resolve().parents[1]


class BenchError(RuntimeError):
    """The benchmark cannot run; the message says what to do."""


def check_environment() -> None:
    """Fail early, clearly, when `make setup` / `source ./env.sh` has not been done."""
    missing = [tool for tool in ('roscore', 'roslaunch', 'rosbag') if shutil.which(tool) is None]
    if missing:
        raise BenchError(f'{", ".join(missing)} not on PATH; run `make setup` and '
                         '`source ./env.sh` (or just `make bench`)')
    if not os.environ.get('TAC_WS'):
        raise BenchError('the workspace is not sourced; run `make bench`, or '
                         '`source ./env.sh` before `python3 bench/run_bench.py`')
    try:
        import mujoco  # noqa: F401
        import rosbags  # noqa: F401
        import rospy  # noqa: F401
        from osrf_msgs.msg import JointCommands  # noqa: F401
    except ImportError as err:
        raise BenchError(f'cannot import {err.name}; run `make setup` and `source ./env.sh`') \
            from err
    found = subprocess.run(['rospack', 'find', 'tutorial_atlas_control'], capture_output=True,
                           text=True, timeout=30, check=False)
    if found.returncode != 0:
        raise BenchError('rospack cannot find tutorial_atlas_control; run `make setup` '
                         'and `source ./env.sh`')


def free_port() -> int:
    """A TCP port nobody listens on now (the kernel's pick), for a private master."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as sock:
        sock.bind(('127.0.0.1', 0))
        return int(sock.getsockname()[1])


def children(pid: int) -> list[int]:
    """Direct children of `pid` (from /proc)."""
    found = []
    for entry in Path('/proc').iterdir():
        if not entry.name.isdigit():
            continue
        try:
            stat = (entry / 'stat').read_text()
        except OSError:
            continue
        # pid (comm) state ppid ...; comm may contain spaces, so split after ')'.
        if int(stat.rsplit(')', 1)[1].split()[1]) == pid:
            found.append(int(entry.name))
    return found


def descendants(pid: int) -> list[int]:
    result, todo = [], [pid]
    while todo:
        for child in children(todo.pop()):
            result.append(child)
            todo.append(child)
    return result


def cmdline(pid: int) -> str:
    try:
        return Path(f'/proc/{pid}/cmdline').read_bytes().replace(b'\0', b' ').decode(
            errors='replace')
    except OSError:
        return ''


def cpu_seconds(pid: int) -> float:
    """utime + stime of `pid` (s), 0.0 if it is gone."""
    try:
        fields = Path(f'/proc/{pid}/stat').read_text().rsplit(')', 1)[1].split()
    except OSError:
        return 0.0
    return (int(fields[11]) + int(fields[12])) / os.sysconf('SC_CLK_TCK')


def _kill_pids(pids: dict[int, str]) -> None:
    """SIGKILL each pid still running the command line it had when we recorded it."""
    for pid, command in pids.items():
        if not command or cmdline(pid) != command:
            continue  # gone (or the pid was reused): not ours
        try:
            os.kill(pid, signal.SIGKILL)
        except (ProcessLookupError, PermissionError):
            pass


def _stop_group(process: subprocess.Popen, timeout_s: float,
                known: dict[int, str] | None = None) -> None:
    """SIGINT the process's group, then SIGTERM, then SIGKILL, each bounded.

    roslaunch puts each node in a session of its own, so the nodes it started are
    collected first and killed by id if they outlive it.
    """
    started = dict(known or {})
    started.update({pid: cmdline(pid) for pid in descendants(process.pid)})
    if process.poll() is not None:
        try:  # children may outlive the leader
            os.killpg(process.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        _kill_pids(started)
        return
    for sig, wait_s in ((signal.SIGINT, timeout_s), (signal.SIGTERM, 5.0),
                        (signal.SIGKILL, 5.0)):
        try:
            os.killpg(process.pid, sig)
        except ProcessLookupError:
            break
        try:
            process.wait(wait_s)
            break
        except subprocess.TimeoutExpired:
            continue
    try:  # stragglers in the group (e.g. a node that ignored SIGINT)
        os.killpg(process.pid, signal.SIGKILL)
    except ProcessLookupError:
        pass
    _kill_pids(started)


@dataclass
class Master:
    """A roscore of our own on a free port; env() is what child processes need."""

    work_dir: Path
    port: int = field(default_factory=free_port)
    process: subprocess.Popen | None = None

    @property
    def uri(self) -> str:
        return f'http://localhost:{self.port}'

    def env(self) -> dict[str, str]:
        env = dict(os.environ)
        env['ROS_MASTER_URI'] = self.uri
        env.setdefault('ROS_HOSTNAME', 'localhost')
        env['ROS_LOG_DIR'] = str(self.work_dir / 'ros_log')
        env['PYTHONWARNINGS'] = 'ignore::SyntaxWarning'  # rospy's queue_size=None warning
        return env

    def start(self) -> None:
        log = (self.work_dir / 'roscore.log').open('w')
        self.process = subprocess.Popen(['roscore', '-p', str(self.port)], env=self.env(),
                                        stdout=log, stderr=subprocess.STDOUT,
                                        stdin=subprocess.DEVNULL, start_new_session=True)
        deadline = time.monotonic() + MASTER_TIMEOUT_S
        proxy = xmlrpc.client.ServerProxy(self.uri)
        while time.monotonic() < deadline:
            if self.process.poll() is not None:
                raise BenchError(f'roscore -p {self.port} exited; see {log.name}')
            try:
                code, _, _ = proxy.getSystemState('/tac_bench')
                if code == 1:
                    return
            except OSError:
                pass
            time.sleep(0.2)
        raise BenchError(f'roscore -p {self.port} did not answer within {MASTER_TIMEOUT_S} s')

    def system_state(self) -> tuple[list, list, list]:
        code, msg, state = xmlrpc.client.ServerProxy(self.uri).getSystemState('/tac_bench')
        if code != 1:
            raise BenchError(f'master: {msg}')
        return state

    def subscribers(self, topic: str) -> list[str]:
        for name, nodes in self.system_state()[1]:
            if name == topic:
                return list(nodes)
        return []

    def stop(self) -> None:
        if self.process is not None:
            _stop_group(self.process, 10.0)
            self.process = None


@dataclass
class Launch:
    """One `roslaunch` of the simulator (and recorder) on our master."""

    master: Master
    launch_file: str
    args: dict[str, str]
    log_path: Path
    process: subprocess.Popen | None = None
    #: pid -> command line of every process seen under our roslaunch (killed if orphaned).
    known: dict[int, str] = field(default_factory=dict)

    def command(self) -> list[str]:
        if self.launch_file.endswith('.launch') and os.path.sep in self.launch_file:
            target = [self.launch_file]
        else:
            target = ['tutorial_atlas_control', self.launch_file]
        return (['roslaunch', '-p', str(self.master.port), '--wait', *target]
                + [f'{key}:={value}' for key, value in self.args.items()])

    def start(self) -> None:
        log = self.log_path.open('w')
        self.process = subprocess.Popen(self.command(), env=self.master.env(), stdout=log,
                                        stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL,
                                        start_new_session=True)

    def node_pid(self, name: str) -> int | None:
        """Pid of the launched node `__name:=name` (a descendant of our roslaunch)."""
        if self.process is None:
            return None
        for pid in descendants(self.process.pid):
            command = cmdline(pid)
            self.known[pid] = command
            if f'__name:={name} ' in command + ' ':
                return pid
        return None

    def check_alive(self) -> None:
        if self.process is not None and self.process.poll() is not None:
            raise BenchError(f'roslaunch exited ({self.process.returncode}); last lines of '
                             f'{self.log_path}:\n{tail(self.log_path)}')

    def stop(self) -> None:
        if self.process is not None:
            _stop_group(self.process, STOP_TIMEOUT_S, self.known)
            self.process = None

    def __enter__(self) -> Launch:
        self.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()


def tail(path: Path, lines: int = 15) -> str:
    try:
        return '\n'.join(path.read_text(errors='replace').splitlines()[-lines:])
    except OSError:
        return '(no log)'


def load_average() -> str:
    try:
        return ' '.join(Path('/proc/loadavg').read_text().split()[:3])
    except OSError:
        return '?'


def cpu_stat() -> list[int]:
    """The machine's aggregate CPU jiffies from /proc/stat (user ... steal)."""
    try:
        return [int(v) for v in Path('/proc/stat').read_text().split('\n', 1)[0].split()[1:9]]
    except (OSError, ValueError):
        return [0] * 8


def busy_and_steal(before: list[int], after: list[int]) -> tuple[float, float]:
    """(busy %, steal %) of all CPUs between two cpu_stat() readings.

    Steal is time the hypervisor gave our virtual CPUs to someone else: other tenants'
    load that `uptime` inside this machine does not show.
    """
    delta = [b - a for a, b in zip(before, after)]
    total = sum(delta) or 1
    idle = delta[3] + delta[4]
    return 100.0 * (total - idle - delta[7]) / total, 100.0 * delta[7] / total


def wait_until(predicate, timeout_s: float, what: str, poll_s: float = 0.1,
               alive=None) -> None:
    """Poll `predicate` until true; BenchError naming `what` after `timeout_s` (wall)."""
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if alive is not None:
            alive()
        if predicate():
            return
        time.sleep(poll_s)
    raise BenchError(f'timed out after {timeout_s:.0f} s waiting for {what}')


def log(text: str) -> None:
    print(f'[bench {time.strftime("%H:%M:%S")}] {text}', file=sys.stderr, flush=True)
