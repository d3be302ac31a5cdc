"""Atlas walking, headless, in one command (`make demo TRAJ=walk_straight`, run_demo.py).

Does what a DRC-era user did in two terminals: start the simulator as DRCSim 2.7 did
(atlas.launch startup_mode:=bdi_stand: the balancing Stand from 2 s), then run a walking
client that streams footsteps through the AtlasSimInterface (walk_client.py); lets the robot
stand a moment, shuts everything down and summarises the bag: steps taken, distance, the
worst placement against the steps asked for, falls, and the footprints seen from above.
`make demo TRAJ=vrc_task_2` does the same on the VRC's walking course (vrc_task_2.launch,
scored) with the course walker, vrc_walker.py, gate to gate; its summary adds the score
and the course map.
"""

from __future__ import annotations

from pathlib import Path

from tutorial_atlas_control.demo.demo_node import (
    END_SETTLE_S,
    TRAJECTORY_STOP_TIMEOUT_S,
    Report,
    join,
    run_launched,
    silent,
    wait_sim_time,
)
from tutorial_atlas_control.processes import AtlasLaunch, run_to_end

__all__ = ['COURSE_WALKS', 'WALKS', 'run_course_demo', 'run_walk_demo']

#: The walks the demo knows: name -> (what it is, walk_client.py's arguments).
WALKS: dict[str, tuple[str, tuple[str, ...]]] = {
    'walk_straight': ('8 steps of 0.25 m straight ahead at 0.63 s a step',
                      ('--steps', '8', '--stride', '0.25')),
    'walk_twenty': ("the issue's 20 steps of 0.25 m (about 0.4 m/s)",
                    ('--steps', '20', '--stride', '0.25')),
    'walk_circle': ('two turns of a circle of radius 2 m, 60 steps a turn',
                    ('--circle', '2', '--steps', '120')),
}
#: The walks on the VRC course: name -> (what it is, vrc_walker.py's arguments).
COURSE_WALKS: dict[str, tuple[str, tuple[str, ...]]] = {
    'vrc_task_2': ("the VRC Task 2 course from the pen, gate to gate with vrc_walker.py, "
                   'scored', ('--to', 'gate_4')),
    'vrc_task_2_laser': ("the same course walked on what the head's laser sees (vrc_walker.py "
                         '--terrain laser: each leg planned on its height map)',
                         ('--to', 'gate_4', '--terrain', 'laser')),
}
#: Wall-clock bound (s) of the course walker (the course's physics runs slower than real
#: time on two cores: docs/vrc.md).
COURSE_TIMEOUT_S = 1800.0
#: Sim time (s) before the client starts: Stand balances from 2 s (DRCSim 2.7's start). Live,
#: rosrun's start-up puts the first WALK later still; from 4 s the eight steps walked 3 of 5
#: runs, from 3 s 7 of 8 (offline a walk sent exactly as Stand's transition ends, at 3.0 s,
#: falls sooner: bench/walk_pushes.py starts at 4 s).
WALK_START_S = 3.0
#: Wall-clock bound (s) of the client's walk.
WALK_TIMEOUT_S = 240.0


def run_walk_demo(walk: str, bag_dir: Path, real_time_factor: float, log_dir: Path,
                  progress: Report = silent, warn: Report = silent) -> Path:
    """Walk `walk` (a WALKS name) once; return the closed bag's path. A walk that falls
    is a result, not an error: walk_client.py's exit status is reported through `warn`."""
    return run_launched('atlas.launch startup_mode:=bdi_stand', {'startup_mode': 'bdi_stand'},
                        bag_dir, real_time_factor, log_dir,
                        lambda launch: _drive(launch, 'walk_client.py', WALKS[walk][1],
                                              WALK_TIMEOUT_S,
                                              'a fall, or a walk that did not end in Stand',
                                              progress, warn),
                        progress, warn)


def run_course_demo(walk: str, bag_dir: Path, real_time_factor: float, log_dir: Path,
                    progress: Report = silent, warn: Report = silent) -> Path:
    """Walk the course walk `walk` (a COURSE_WALKS name) once, headless (gzname:=gzserver),
    scored into `bag_dir`/vrc_task_2/score.log; return the closed bag's path. A fall or a
    gate not reached is a result: vrc_walker.py's exit status is reported through `warn`."""
    args = {'gzname': 'gzserver', 'course_markers': 'false',
            'score_dir': bag_dir / 'vrc_task_2'}
    return run_launched('vrc_task_2.launch', args, bag_dir, real_time_factor, log_dir,
                        lambda launch: _drive(launch, 'vrc_walker.py', COURSE_WALKS[walk][1],
                                              COURSE_TIMEOUT_S, 'a fall, or a gate not reached',
                                              progress, warn),
                        progress, warn, launch_file='vrc_task_2.launch')


def _drive(launch: AtlasLaunch, client: str, args: tuple[str, ...], timeout_s: float,
           failure: str, progress: Report, warn: Report) -> None:
    """From WALK_START_S of sim time, `rosrun tutorial_atlas_control client args` until it
    ends; a non-zero exit (`failure` says what it means) is reported through `warn`."""
    from rosgraph_msgs.msg import Clock  # noqa: PLC0415 - rospy loads only once a launch runs

    join(launch, 'tutorial_walk_demo')
    wait_sim_time(Clock, WALK_START_S)
    command = ['rosrun', 'tutorial_atlas_control', client, *args, '--timeout',
               f'{timeout_s:.0f}']
    progress('demo: ' + ' '.join(command))
    status = run_to_end(command, launch.env, timeout_s + 30.0, TRAJECTORY_STOP_TIMEOUT_S)
    if status != 0:
        warn(f'demo: {client} exited with status {status} ({failure})')
    wait_sim_time(Clock, END_SETTLE_S)
