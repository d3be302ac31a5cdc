"""The `cameras` section: what the head's stereo cameras cost and the rate they reach.

Each run launches the simulator at real_time_factor:=1.0 once per case: nobody looking
(`none`), the left image subscribed (`left`, what rviz's sensors view asks for), both images
(`pair`, what stereo_image_proc asks for), and in the VRC course (vrc_task_2.launch)
nobody looking and the left image (`course_none`, `course_left`). Over the window: the
achieved factor (/clock), the images received per second of sim time (their stamps; the
goal is DRCSim's 30 Hz), and the CPU per second of sim time of the simulator and of the
camera node (multisense_cameras, niceness 10, one rasterizer thread). The images are
counted by their stamps only (no copy kept). Keys: cameras_<case>_rtf, cameras_<case>_hz,
cameras_<case>_node_cpu, cameras_<case>_camera_cpu.
"""

from __future__ import annotations

import struct
import threading
import time
from pathlib import Path

from harness import BenchError, Master
from online import Probes, _clock_series, _launch, _wait_ready

from tutorial_atlas_control import topics
from tutorial_atlas_control.processes import cpu_seconds

REPO = Path(__file__).resolve().parents[1]
COURSE_LAUNCH = REPO / 'launch' / 'vrc_task_2.launch'
#: (case, sides subscribed, launch file: None for the bench's, extra launch arguments).
CASES = (('none', (), None, {}), ('left', ('left',), None, {}),
         ('pair', ('left', 'right'), None, {}),
         ('course_none', (), COURSE_LAUNCH, {'gzname': 'gzserver', 'course_markers': 'false'}),
         ('course_left', ('left',), COURSE_LAUNCH, {'gzname': 'gzserver',
                                                     'course_markers': 'false'}))
_HEADER = struct.Struct('<III')


class StampCounter:
    """Subscribes to one image topic; keeps only the stamps (ns) that arrive while on."""

    def __init__(self, topic: str) -> None:
        import rospy

        self.lock = threading.Lock()
        self.on = False
        self.stamps: list[int] = []
        self.subscriber = rospy.Subscriber(topic, rospy.AnyMsg, self._on_message,
                                           queue_size=1, buff_size=1 << 24)

    def _on_message(self, msg: object) -> None:
        _, secs, nsecs = _HEADER.unpack_from(msg._buff, 0)  # type: ignore[attr-defined]
        with self.lock:
            if self.on:
                self.stamps.append(secs * 1_000_000_000 + nsecs)

    def close(self) -> None:
        self.subscriber.unregister()


def _window(master: Master, launch_file: str, probes: Probes, work_dir: Path, name: str,
            sides: tuple[str, ...], extra: dict[str, str], warmup_s: float,
            window_s: float) -> dict[str, float]:
    with _launch(master, launch_file, work_dir, name, 1.0, extra_args=extra) as launch:
        _wait_ready(master, launch, probes)
        counters = [StampCounter(f'{topics.CAMERA_NAMESPACE}/{side}/image_raw')
                    for side in sides]
        try:
            time.sleep(warmup_s)
            pids = {'node': launch.node_pid('atlas_sim'),
                    'camera': launch.node_pid('multisense_cameras')}
            if pids['camera'] is None:
                raise BenchError(f'{name}: no multisense_cameras node in the launch')
            cpu0 = {key: cpu_seconds(pid) for key, pid in pids.items()}
            for counter in counters:
                counter.on = True
            probes.clock.start()
            time.sleep(window_s)
            samples = probes.clock.stop()
            for counter in counters:
                counter.on = False
            cpu1 = {key: cpu_seconds(pid) for key, pid in pids.items()}
            launch.check_running()
        finally:
            for counter in counters:
                counter.close()
    wall, sim = _clock_series(samples)
    sim_s = float(sim[-1] - sim[0])
    rates = [len(counter.stamps) / sim_s for counter in counters]
    return {'rtf': sim_s / float(wall[-1] - wall[0]), 'hz': min(rates) if rates else 0.0,
            'node_cpu': (cpu1['node'] - cpu0['node']) / sim_s,
            'camera_cpu': (cpu1['camera'] - cpu0['camera']) / sim_s}


def camera_run(master: Master, launch_file: str, probes: Probes, work_dir: Path, name: str,
               warmup_s: float, window_s: float) -> dict[str, float]:
    """One run of every case: the section's keys."""
    values = {}
    for case, sides, case_launch, extra in CASES:
        figures = _window(master, str(case_launch or launch_file), probes, work_dir,
                          f'{name}_{case}', sides, extra, warmup_s, window_s)
        values.update({f'cameras_{case}_{key}': value for key, value in figures.items()})
    return values
