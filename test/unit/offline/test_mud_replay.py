"""A run in a world with mud, offline, replays exactly; the mud is what the replay needs."""

from __future__ import annotations

from pathlib import Path

from tutorial_atlas_control.joints import NUM_JOINTS
from tutorial_atlas_control.offline.player import run_offline
from tutorial_atlas_control.offline.replay import replay_bag
from tutorial_atlas_control.offline.world import OfflineWorld
from tutorial_atlas_control.sim import MODEL_PATH


def _mud_world(tmp_path: Path) -> Path:
    """Atlas with a mud box over its feet and lower legs (z -0.05 to 0.35)."""
    box = ('<geom name="mud_atlas" type="box" size="1 1 0.2" pos="0 0 0.15" contype="0" '
           'conaffinity="0" group="1"/>\n    <body name="pelvis"')
    path = tmp_path / 'atlas_in_mud.xml'
    path.write_text(MODEL_PATH.read_text().replace('<body name="pelvis"', box, 1))
    return path


def test_a_run_in_mud_replays_exactly_and_strays_without_the_mud(tmp_path: Path) -> None:
    world = _mud_world(tmp_path)
    trajectory = tmp_path / 'knee.yaml'
    bent = ['0'] * NUM_JOINTS
    bent[6:9] = ['-0.3', '0.6', '-0.3']  # the left leg bends in the mud
    trajectory.write_text('knee:\n  - [0.3, "' + ' '.join(bent) + '"]\n')
    bag = tmp_path / 'mud.bag'
    run_offline(str(trajectory), 'knee', bag, settle_s=0.3, start_after_s=1.1,
                world=OfflineWorld(world, mud_damping=70.0))
    result = replay_bag(bag, model_path=world)
    assert result.config.mud_damping == 70.0
    assert result.reproduced
    assert result.joint_position.max_abs == 0.0 and result.joint_velocity.max_abs == 0.0
    without = replay_bag(bag, model_path=MODEL_PATH)
    assert without.joint_velocity.max_abs > 1e-3, 'the recorded run felt the mud'
