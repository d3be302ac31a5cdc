"""AtlasSimulator without ROS: modes, pinning, resets, command merging, divergence."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from tutorial_atlas_control.command.arrays import CommandError
from tutorial_atlas_control.joints import JOINT_INDEX, NUM_JOINTS
from tutorial_atlas_control.sim import model as atlas_model
from tutorial_atlas_control.sim.controller import load_gains_yaml
from tutorial_atlas_control.sim.simulator import (
    AtlasSimulator,
    ControlMode,
    ModeError,
    PhysicsDivergenceError,
    parse_mode,
)

CONFIG = Path(__file__).resolve().parents[3] / 'config' / 'atlas_controller.yaml'


@pytest.fixture(scope='module')
def atlas() -> atlas_model.AtlasModel:
    return atlas_model.load_model()


@pytest.fixture
def sim(atlas: atlas_model.AtlasModel) -> AtlasSimulator:
    return AtlasSimulator(atlas, load_gains_yaml(CONFIG), time_to_unpin_s=0.5)


def pelvis_z(sim: AtlasSimulator) -> float:
    return float(sim.data.xpos[sim.atlas.pelvis_body_id][2])


def run(sim: AtlasSimulator, seconds: float) -> None:
    for _ in range(int(round(seconds / sim.dt_s))):
        sim.step()


def test_parse_mode_accepts_drcsim_modes_and_lists_them_otherwise() -> None:
    assert parse_mode('User') is ControlMode.USER
    assert parse_mode('ragdoll') is ControlMode.RAGDOLL
    with pytest.raises(ModeError, match="unknown control mode 'user'; valid modes: Stand, "
                                        'StandPrep, Freeze, ragdoll, User, Walk'):
        parse_mode('user')
    with pytest.raises(ModeError, match=r"'x{40}\.\.\.'"):
        parse_mode('x' * 10_000)
    with pytest.raises(ModeError):
        parse_mode('')
    # Step is entered through the AtlasSimInterface only, as in DRCSim.
    with pytest.raises(ModeError, match="unknown control mode 'Step'"):
        parse_mode('Step')


def test_torso_pinned_until_time_to_unpin_then_ragdoll_falls(sim: AtlasSimulator) -> None:
    start_z = pelvis_z(sim)
    sim.set_mode(ControlMode.RAGDOLL)
    run(sim, 0.45)
    assert sim.pinned
    assert pelvis_z(sim) == pytest.approx(start_z, abs=1e-3)
    run(sim, 1.5)
    assert not sim.pinned
    assert pelvis_z(sim) < 0.5


def test_sim_time_counts_whole_steps(sim: AtlasSimulator) -> None:
    run(sim, 0.25)
    assert sim.sim_time_ns == 250_000_000


def test_freeze_is_bumpless(sim: AtlasSimulator) -> None:
    run(sim, 1.0)
    before = sim.torque_nm.copy()
    sim.set_mode(ControlMode.FREEZE)
    sim.step()
    # The same torque keeps the robot where it is; only the dynamics of one step differ.
    assert np.max(np.abs(sim.torque_nm - before)) < 5.0
    frozen = sim.commands.law_command.position.copy()
    run(sim, 1.0)
    assert np.max(np.abs(sim.joint_positions() - frozen)) < 0.05


def test_user_mode_holds_until_the_first_command_then_merges_subsets(sim: AtlasSimulator) -> None:
    run(sim, 0.6)
    sim.set_mode(ControlMode.USER)
    held = sim.commands.law_command.position.copy()
    sim.receive_command(['atlas::l_arm_elx'], {'position': [0.8]})
    command = sim.commands.law_command
    elbow = JOINT_INDEX['l_arm_elx']
    assert command.position[elbow] == 0.8
    others = np.arange(NUM_JOINTS) != elbow
    np.testing.assert_array_equal(command.position[others], held[others])
    run(sim, 1.5)
    assert sim.joint_positions()[elbow] == pytest.approx(0.8, abs=0.1)


def test_refused_command_keeps_the_previous_one(sim: AtlasSimulator) -> None:
    sim.set_mode(ControlMode.USER)
    sim.receive_command(['neck_ay'], {'position': [0.3]})
    with pytest.raises(CommandError):
        sim.receive_command(['neck_ay'], {'position': [float('inf')]})
    assert sim.commands.law_command.position[JOINT_INDEX['neck_ay']] == 0.3


def test_reset_world_keeps_time_and_forgets_commands(sim: AtlasSimulator) -> None:
    sim.set_mode(ControlMode.RAGDOLL)
    run(sim, 2.0)
    sim.set_mode(ControlMode.USER)
    sim.receive_command(['neck_ay'], {'position': [0.3]})
    sim.reset_world()
    assert sim.sim_time_ns == 2_000_000_000
    assert sim.pinned and sim.user_command is None
    assert pelvis_z(sim) == pytest.approx(atlas_model.SPAWN_HEIGHT_M)
    np.testing.assert_array_equal(sim.joint_positions(), np.zeros(NUM_JOINTS))
    assert sim.config().last_reset_time_s == 2.0
    sim.reset_simulation()
    assert sim.sim_time_ns == 0


def test_divergence_is_raised_not_stepped_through(sim: AtlasSimulator) -> None:
    sim.data.qvel[sim.atlas.dof_adr[0]] = float('nan')
    with pytest.raises(PhysicsDivergenceError, match='physics diverged at t=0.001 s'):
        sim.step()
    sim.reset_world()
    sim.step()  # sound again after the reset
    assert np.isfinite(sim.data.qpos).all()


def test_same_inputs_give_bitwise_equal_runs(atlas: atlas_model.AtlasModel) -> None:
    gains = load_gains_yaml(CONFIG)
    runs = []
    for _ in range(2):
        sim = AtlasSimulator(atlas, gains)
        sim.set_mode(ControlMode.USER)
        sim.receive_command([], {'position': np.linspace(-0.2, 0.2, NUM_JOINTS)})
        run(sim, 0.5)
        runs.append(sim.data.qpos.copy())
    np.testing.assert_array_equal(runs[0], runs[1])


def test_config_names_the_model_and_timing(sim: AtlasSimulator) -> None:
    config = sim.config().to_dict()
    assert config['model_file'] == 'atlas_v1.xml'
    assert len(str(config['model_sha1'])) == 40
    assert config['timestep'] == 0.001
    assert config['time_to_unpin'] == 0.5
