"""Atlas v1 joint names, in the order the DRCSim tutorial (and DRCSim) used them."""

from __future__ import annotations

#: The 28 joints in the tutorial's order: back/neck, left leg, right leg, left arm, right arm.
JOINT_NAMES: tuple[str, ...] = (
    'back_lbz', 'back_mby', 'back_ubx', 'neck_ay',
    'l_leg_uhz', 'l_leg_mhx', 'l_leg_lhy', 'l_leg_kny', 'l_leg_uay', 'l_leg_lax',
    'r_leg_uhz', 'r_leg_mhx', 'r_leg_lhy', 'r_leg_kny', 'r_leg_uay', 'r_leg_lax',
    'l_arm_usy', 'l_arm_shx', 'l_arm_ely', 'l_arm_elx', 'l_arm_uwy', 'l_arm_mwx',
    'r_arm_usy', 'r_arm_shx', 'r_arm_ely', 'r_arm_elx', 'r_arm_uwy', 'r_arm_mwx',
)

NUM_JOINTS: int = len(JOINT_NAMES)

#: Gazebo's scoped-name prefix; the tutorial sent 'atlas::back_lbz' etc.
ATLAS_PREFIX: str = 'atlas::'

JOINT_INDEX: dict[str, int] = {name: index for index, name in enumerate(JOINT_NAMES)}


def bare_joint_name(name: str) -> str:
    """Return `name` without the Gazebo `atlas::` prefix, if it has one."""
    return name[len(ATLAS_PREFIX):] if name.startswith(ATLAS_PREFIX) else name


def joint_index(name: str) -> int | None:
    """Tutorial-order index of joint `name`, bare or `atlas::`-prefixed; None if not Atlas's."""
    return JOINT_INDEX.get(bare_joint_name(name))
