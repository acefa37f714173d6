"""A joint-space reach takes the nearest inverse-kinematics solution whose path is clear, and checks
the paths nearest first, so that the farther ones need no checking."""

from __future__ import annotations

from collections.abc import Sequence

import pytest

from cbrs.sim.arms import ArmSide, Kinematics, _joint_distance
from cbrs.sim.grasping import ObjectModel, compute_grasp_pose
from cbrs.sim.world import open_world


def _checked(monkeypatch: pytest.MonkeyPatch, blocked: int) -> tuple[list[float], tuple[float, ...]]:
    """Reach the cup's pre-grasp pose with the left arm; the first ``blocked`` paths checked count as blocked. Returns
    the joint distances of the solutions whose paths were checked, in order, and where the arm went."""
    checked: list[float] = []
    original = Kinematics.path_clear

    def path_clear(
        self: Kinematics,
        side: ArmSide,
        start: Sequence[float],
        goal: Sequence[float],
        others: dict[ArmSide, Sequence[float]],
        min_height: float | None = None,
    ) -> bool:
        checked.append(_joint_distance(start, goal))
        return len(checked) > blocked and original(self, side, start, goal, others, min_height)

    monkeypatch.setattr(Kinematics, "path_clear", path_clear)
    with open_world(seed=0) as world:
        spec = world.arm_specs[ArmSide.LEFT]
        cup = ObjectModel.of(world.objects["Cup"])
        grasp = compute_grasp_pose(cup, world.pose("Cup").position, None, spec.mount, spec.yaw)
        arm = world.arm(ArmSide.LEFT)
        result = arm.reach(grasp.pregrasp, grasp.orientation)
        assert result.reached, result.reason
        return checked, arm.joint_positions()


def test_paths_are_checked_nearest_first_and_the_first_clear_one_is_taken(monkeypatch: pytest.MonkeyPatch) -> None:
    checked, _ = _checked(monkeypatch, blocked=0)
    assert len(checked) == 1


def test_a_blocked_nearest_path_falls_back_to_the_next_nearest(monkeypatch: pytest.MonkeyPatch) -> None:
    checked, _ = _checked(monkeypatch, blocked=1)
    assert len(checked) == 2
    assert checked[0] <= checked[1]
