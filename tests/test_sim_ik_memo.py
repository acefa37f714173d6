"""Inverse kinematics asked again with the same pose and seed posture is looked up, not solved again
(sim/arms.py: Kinematics._refine), and the answer looked up is the one a fresh solve gives, wherever the
kinematics copy was left in between."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pybullet as p
import pytest

from cbrs.sim import arms
from cbrs.sim.arms import ArmSide, Kinematics
from cbrs.sim.geometry import Region

MOUNTS = {
    ArmSide.LEFT: ((0.0, 0.2, 0.8), (0.0, 0.0, 0.0, 1.0)),
    ArmSide.RIGHT: ((0.0, -0.2, 0.8), (0.0, 0.0, 0.0, 1.0)),
}
TARGET = ((0.45, 0.25, 0.95), (1.0, 0.0, 0.0, 0.0))  # in front of the left arm, the hand pointing down


@pytest.fixture(scope="module")
def kinematics() -> Iterator[Kinematics]:
    k = Kinematics(MOUNTS)
    yield k
    k.close()


def _counting(monkeypatch: pytest.MonkeyPatch) -> list[int]:
    calls = [0]
    original = p.calculateInverseKinematics

    def counted(*args: Any, **kwargs: Any) -> Any:
        calls[0] += 1
        return original(*args, **kwargs)

    monkeypatch.setattr(arms.p, "calculateInverseKinematics", counted)
    return calls


def test_a_pose_asked_again_from_the_same_seed_is_not_solved_again(
    kinematics: Kinematics, monkeypatch: pytest.MonkeyPatch
) -> None:
    calls = _counting(monkeypatch)
    seed = arms.HOME_CONFIGURATIONS[ArmSide.LEFT]
    first = kinematics.solve(ArmSide.LEFT, *TARGET, [seed])
    solved = calls[0]
    assert solved >= 1
    kinematics.forward(ArmSide.LEFT, first.q)  # the copy left elsewhere
    again = kinematics.solve(ArmSide.LEFT, *TARGET, [seed])
    assert calls[0] == solved
    assert again == first
    other_seed = kinematics.solve(ArmSide.LEFT, *TARGET, [first.q])  # another seed posture is solved
    assert calls[0] > solved
    assert other_seed.position_error <= arms.IK_TOLERANCE


def test_the_answer_looked_up_is_what_a_fresh_solve_gives(kinematics: Kinematics) -> None:
    seed = arms.HOME_CONFIGURATIONS[ArmSide.LEFT]
    looked_up = kinematics.solve(ArmSide.LEFT, *TARGET, [seed])
    looked_up = kinematics.solve(ArmSide.LEFT, *TARGET, [seed])
    fresh = Kinematics(MOUNTS)
    try:
        fresh.forward(ArmSide.LEFT, [0.3, -0.2, 0.1, -2.0, 0.0, 1.8, 0.5])  # start it somewhere else
        assert fresh.solve(ArmSide.LEFT, *TARGET, [seed]) == looked_up
    finally:
        fresh.close()


def test_a_loose_answer_is_kept_apart_from_a_tight_one(kinematics: Kinematics) -> None:
    seed = arms.HOME_CONFIGURATIONS[ArmSide.LEFT]
    loose = kinematics.solve(ArmSide.LEFT, *TARGET, [seed], loose=True)
    tight = kinematics.solve(ArmSide.LEFT, *TARGET, [seed])
    assert 1e-4 <= loose.position_error <= arms.IK_TOLERANCE  # stopped short of the tight 0.1 mm
    assert tight.position_error < 1e-4
    assert kinematics.solve(ArmSide.LEFT, *TARGET, [seed], loose=True) == loose


def test_a_pose_whose_last_link_is_deep_in_a_fixed_thing_is_refused_without_solving(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Kinematics.wrist_strikes: the pose places the arm's last link; deep inside a box, every solution
    would push into it, so can_hold refuses it without a single inverse-kinematics call."""
    position, orientation = TARGET
    box = Region("Block", position[0] - 0.1, position[0] + 0.1, position[1] - 0.1, position[1] + 0.1, 0.9, 1.4)
    free = Kinematics(MOUNTS)
    blocked = Kinematics(MOUNTS, obstacles=[box])
    try:
        assert not free.wrist_strikes(ArmSide.LEFT, position, orientation)
        assert blocked.wrist_strikes(ArmSide.LEFT, position, orientation)
        solution = blocked.solve(ArmSide.LEFT, position, orientation, [arms.HOME_CONFIGURATIONS[ArmSide.LEFT]])
        assert solution.position_error <= arms.IK_TOLERANCE  # there is a posture; it pushes into the box
        assert blocked.strikes(ArmSide.LEFT, solution.q, {})
        above = (position[0], position[1], 1.6)  # the link clear of the box
        assert not blocked.wrist_strikes(ArmSide.LEFT, above, orientation)
    finally:
        free.close()
        blocked.close()
