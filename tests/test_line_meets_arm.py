"""A straight line that would take an arm into the other arm is refused, on the dry run and by the real
arm before it moves (sim/arms.py: Kinematics.line_meets_arm). The case is FetchMyGreenMug's at seed 1
(docs/tasks.md, a twentieth round): the left arm's carry of the mug from (7.30, 3.19) across to the relay
spot at (7.73, 3.07), by the torso, the right arm home. Planned on the inverse kinematics alone, the line
passed the relay spot's dry run, and the real arm stopped 1.3 cm short, its link 3 against the right
arm's link 2. The arms as the robot mounts them, no fixed things: the copies alone, no world."""

from __future__ import annotations

from collections.abc import Iterator

import pybullet as p
import pytest

from cbrs.sim.arms import HOME_CONFIGURATIONS, PYBULLET_DATA, Arm, ArmSide, Kinematics, PlannedArm, panda_urdf
from cbrs.sim.geometry import Quat, Vec3
from cbrs.sim.quiet import quiet_output

TURNED = (0.0, 0.0, 0.7071067811865475, 0.7071067811865476)  # the torso's arms face +y
MOUNTS = {ArmSide.LEFT: ((7.57, 2.55, 0.65), TURNED), ArmSide.RIGHT: ((7.93, 2.55, 0.65), TURNED)}
LIFTED = (-0.2330509, 0.5330799, 0.7062634, -1.9721873, -2.053075, 2.5546222, 2.8496772)
"""The left arm holding the mug lifted over where it stood, its hand side-on at (7.296, 3.188, 0.854), as
the relay spot's dry run had it (its loose pieces a little off the real arm's posture)."""
HAND: Quat = (0.6271946, 0.6271895, 0.326518, -0.3265675)
RELAY: Vec3 = (7.726, 3.066, 0.854)  # over the relay spot by the torso: the line runs into the right arm
AWAY = (0.0, -1.7, 0.0, -0.3, 0.0, 1.0, 0.785)  # the right arm leaning back, off the line


@pytest.fixture(scope="module")
def kinematics() -> Iterator[Kinematics]:
    k = Kinematics(MOUNTS)
    yield k
    k.close()


def _planned(kinematics: Kinematics) -> PlannedArm:
    return PlannedArm(ArmSide.LEFT, kinematics, LIFTED, {ArmSide.RIGHT: HOME_CONFIGURATIONS[ArmSide.RIGHT]})


def test_the_dry_run_refuses_a_line_into_the_other_arm(kinematics: Kinematics) -> None:
    planned = _planned(kinematics)
    result = planned.move_to(RELAY, HAND)
    assert not result.reached
    assert "run into the right arm" in result.reason
    assert planned.joint_positions() == LIFTED  # nothing planned past the refusal


def test_the_line_is_planned_as_the_real_arm_solves_it(kinematics: Kinematics) -> None:
    # loose pieces run out of inverse kinematics part-way, the real arm's do not: before, the dry run stopped
    # there and planned a joint-space move round the right arm, and the real arm went by the line
    assert isinstance(kinematics.line(ArmSide.LEFT, LIFTED, RELAY, HAND, loose=True), str)
    assert not isinstance(kinematics.line(ArmSide.LEFT, LIFTED, RELAY, HAND), str)
    away = PlannedArm(ArmSide.LEFT, kinematics, LIFTED, {ArmSide.RIGHT: AWAY})
    assert away.move_to(RELAY, HAND).reached  # the right arm out of the way, the line is taken


def test_the_real_arm_refuses_it_before_it_moves(kinematics: Kinematics) -> None:
    with quiet_output():
        client = p.connect(p.DIRECT)
    try:
        p.setAdditionalSearchPath(PYBULLET_DATA, physicsClientId=client)
        arms: dict[ArmSide, Arm] = {}
        for side, (mount, orientation) in MOUNTS.items():
            body = p.loadURDF(panda_urdf(), mount, orientation, useFixedBase=True, physicsClientId=client)
            arms[side] = Arm(client, side, body, kinematics, lambda seconds: None)
        for arm in arms.values():
            arm.peers = arms
        left = arms[ArmSide.LEFT]
        for joint, q in enumerate(LIFTED):
            p.resetJointState(left.body, joint, q, physicsClientId=client)
        result = left.move_to(RELAY, HAND)
        assert not result.reached
        assert "run into the right arm" in result.reason
        assert left.joint_positions() == pytest.approx(LIFTED, abs=1e-9)  # refused before any move
    finally:
        p.disconnect(physicsClientId=client)
