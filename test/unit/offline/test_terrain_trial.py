"""offline/terrain_trial.py's worlds and tools/terrain_walk.py's arguments, without walking:
the mud stands 0.46 m over the floor along the walk and pushes nothing; the stairs rise (or
fall) a riser a tread; a bad case or seed is one line and exit 2."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import mujoco
import pytest

from tutorial_atlas_control.offline import MUD_DEPTH_M, TERRAINS, mud_model
from tutorial_atlas_control.offline.terrain_trial import (
    RAMP_START_M,
    STAIR_COUNT,
    STAIR_RISE_M,
    STAIR_TREAD_M,
    stairs_model,
)
from tutorial_atlas_control.sim import Ground, MudDrag

TOOL = Path(__file__).resolve().parents[3] / 'tools' / 'terrain_walk.py'


def test_the_mud_covers_the_walk_to_its_depth_and_pushes_nothing(tmp_path: Path) -> None:
    atlas = mud_model(tmp_path)
    model = atlas.model
    mud = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, 'mud_atlas')
    assert mud >= 0
    assert (model.geom_contype[mud], model.geom_conaffinity[mud]) == (0, 0)
    centre, half = model.geom_pos[mud], model.geom_size[mud]
    assert centre[2] + half[2] == pytest.approx(MUD_DEPTH_M)
    longest = max(case.steps * case.stride_m for case in TERRAINS.values()
                  if case.mud_damping is not None)
    assert centre[0] - half[0] < -0.3 and centre[0] + half[0] > longest + 0.5
    assert MudDrag.for_model(model, atlas.path, 40.0) is not None  # the drag finds its mud


@pytest.mark.parametrize('rise_m', [0.15, -0.15])
def test_the_stairs_rise_a_riser_a_tread_to_their_landing(rise_m: float) -> None:
    """Up: the floor, then each 0.4 m tread 0.15 m higher, the landing at 0.6 m; down the
    same from a landing under the start (the ground under the middle of each tread)."""
    atlas = stairs_model(rise_m)
    data = mujoco.MjData(atlas.model)
    mujoco.mj_forward(atlas.model, data)
    ground = Ground(atlas.model, data)
    treads = [RAMP_START_M + (k + 0.5) * STAIR_TREAD_M for k in range(STAIR_COUNT)]
    heights = [ground.height_m(x, 0.0) for x in [0.0, *treads, treads[-1] + STAIR_TREAD_M]]
    top = STAIR_RISE_M * STAIR_COUNT
    up = [0.0, *(STAIR_RISE_M * (k + 1) for k in range(STAIR_COUNT)), top]
    down = [top, *(STAIR_RISE_M * (STAIR_COUNT - 1 - k) for k in range(STAIR_COUNT)), 0.0]
    assert heights == pytest.approx(up if rise_m > 0.0 else down, abs=1e-6)


@pytest.mark.parametrize(('args', 'line'), [
    (['mud_9', '1'], "terrain_walk.py: error: argument CASE: invalid choice: 'mud_9' (choose "
     "from 'down_16deg', 'down_8deg', 'mud_40', 'mud_70', 'ramp_down_22deg', 'ramp_up_22deg', "
     "'stairs_down_15cm', 'stairs_up_15cm', 'up_16deg', 'up_8deg')"),
    (['mud_40', 'x'], "terrain_walk.py: error: argument SEED: seed 'x' is not an integer or "
     'none'),
    (['--push', '-1', 'mud_40', '1'], "terrain_walk.py: error: argument --push: '-1' must be a "
     'number >= 0')])
def test_a_bad_case_or_seed_is_one_line_and_exit_2(args: list[str], line: str) -> None:
    done = subprocess.run([sys.executable, str(TOOL), *args], capture_output=True, text=True,
                          timeout=60, check=False)
    assert done.returncode == 2
    assert done.stdout == ''
    assert done.stderr.splitlines()[-1] == line
