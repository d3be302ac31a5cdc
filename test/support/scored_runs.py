"""A scored offline run for the bag tools' tests: the robot teleported through gates (as
DRCSim's scoring checks did, with Pose()'s all-zero quaternion), recorded with /vrc_score."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from tutorial_atlas_control.offline.player import OfflinePlayer, open_offline_bag
from tutorial_atlas_control.sim.simulator import AtlasSimulator
from tutorial_atlas_control.sim.vrc import pose_input

#: (sim s, x m, y m): through gate_0 (x 1 at y -38) and gate_1 (y -22 at x 0), each from its
#: near side to its far side in the next teleport.
GATE_TELEPORTS = ((0.5, 0.7, -38.0), (0.6, 1.3, -38.0), (0.8, 0.0, -22.3), (0.9, 0.0, -21.7))


def record_teleported_run(sim: AtlasSimulator, bag: Path, score_dir: Path, until_s: float,
                          teleports: Sequence[tuple[float, float, float]] = GATE_TELEPORTS,
                          scans: bool = False) -> Path:
    """Run `sim` offline to `until_s`, scored into `score_dir`, teleporting the pelvis to
    (x, y, 1 m) at each teleport's sim time; the bag at `bag` (with the laser's scans if
    `scans`)."""
    sink = open_offline_bag(bag, scans)
    try:
        player = OfflinePlayer(sim, sink, score_dir=score_dir)
        player.write_config()
        player.publish()
        for t_s, x_m, y_m in teleports:
            player.advance(t_s - player.now_s())
            sim.apply_input(pose_input((x_m, y_m, 1.0), (0.0, 0.0, 0.0, 0.0)))
        player.advance(until_s - player.now_s())
        player.write_steps()
    finally:
        sink.close()
    return bag
