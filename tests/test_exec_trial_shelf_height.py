"""An object taken from a shelf 10 cm above the table and loaded onto the base's platform (new-user trial
B, docs/examples/glasses_on_the_shelf.ttl). The carry's straight way down over the platform left the
right arm's elbow at the end of its range, where put_down_object's last 2.6 cm down had no inverse
kinematics: the hand-over failed after taking the glasses, three plans in a row. The dry run now plans
that way down too (skills.can_carry: "past lowering it onto ..."), and the carry comes down through joint
space to a posture from which the hand can lower it when the straight line would not (skills._down,
Kinematics.joint_path's down_to); FetchMyGlasses then brings them to the person (docs/tasks.md)."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from cbrs.kb import KnowledgeBase
from cbrs.kb.semantic_map import SemanticMap
from cbrs.sim import skills
from cbrs.sim.arms import ArmSide
from cbrs.sim.geometry import Pose2D
from cbrs.sim.perception import ObjectEstimate
from cbrs.sim.values import Manipulation
from cbrs.sim.world import open_world

EXAMPLES = Path(__file__).parent.parent / "docs" / "examples"
LAB = "https://example.org/lab#"


def test_the_glasses_come_down_over_the_platform_where_the_hand_can_lower_them(monkeypatch: pytest.MonkeyPatch) -> None:
    kb = KnowledgeBase.open(":memory:")
    for graph in ("ontology", "map"):
        kb.load([EXAMPLES / "glasses_on_the_shelf.ttl"], graph=graph)
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        glasses = world.map.objects[LAB + "Glasses1"]
        dock = world.map.things[LAB + "TableShelf1"].dock
        assert dock is not None
        base = Pose2D(dock.x, dock.y, dock.yaw)
        x, y, z = world.pose("Glasses1").position
        seen = ObjectEstimate(x, y, z, 0.0, glasses.size, glasses.colour, "map", 0.0, 0)
        model = Manipulation.of(glasses).model
        joints, started = world.arm(ArmSide.RIGHT).joint_positions(), world.time

        def straight(arm: Any, grasp: Any, region: Any, leg: Any, orientation: Any) -> Any:
            return arm.move_to(leg, orientation)

        down: Callable[..., Any] = skills._down
        monkeypatch.setattr(skills, "_down", straight)
        refused = skills.can_hand_over(world, seen, base, ArmSide.RIGHT, model)
        monkeypatch.setattr(skills, "_down", down)
        assert refused.startswith(
            "the right arm would not get the Glasses1 by its top grasp past lowering it onto OnRobotPlatform at "
            "(8.50, 2.20): no inverse kinematics"
        )
        assert skills.can_hand_over(world, seen, base, ArmSide.RIGHT, model) == ""
        assert world.arm(ArmSide.RIGHT).joint_positions() == joints and world.time == started  # planned only
