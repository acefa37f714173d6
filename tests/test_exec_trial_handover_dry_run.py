"""The hand-over dry-runs the loader's moves as the approach choice does (arm_choice.who_loads,
hold_choice.first_clear; skills.can_hand_over), a lone approach too. The pen (one approach, top) set
at (7.72, 3.30): the right arm, the one that reaches the platform, can hold the pre-grasp, grasp and
letting-go poses, but its planning finds no collision-free joint path to the pre-grasp pose. Before,
the plan's check passed, the base drove 5.6 m to the table and the hand-over failed there twice after
moving; now the run is refused by the plan's check, before the base drives off, naming the pen, the
arm and the move."""

from __future__ import annotations

import pytest

from cbrs.actions.composer import Composer
from cbrs.actions.runner import run_task
from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.semantic_map import SemanticMap
from cbrs.sim.arms import ArmSide
from cbrs.sim.components import CannotLoadError, SimEnvironment
from cbrs.sim.world import open_world

WORLD = PREFIXES["world"]


def test_a_lone_approach_the_loaders_planning_refuses_is_refused_before_the_base_drives_off() -> None:
    kb = KnowledgeBase.open(":memory:")
    kb.update(
        "DELETE { GRAPH graph:map { world:Pen home:x ?x ; home:y ?y } } "
        "INSERT { GRAPH graph:map { world:Pen home:x 7.72 ; home:y 3.30 } } "
        "WHERE { GRAPH graph:map { world:Pen home:x ?x ; home:y ?y } }"
    )
    before = set(kb.store.quads())
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        pen, base, started = world.pose("Pen").position, world.base_pose(), world.time
        joints = {side: world.arm(side).joint_positions() for side in ArmSide}
        with pytest.raises(CannotLoadError) as refused:
            run_task(kb, "FetchMyPen", SimEnvironment(world, kb), composer=Composer(kb))
        assert world.base_pose().distance_to(base.x, base.y) < 0.01
        assert world.pose("Pen").position == pytest.approx(pen, abs=1e-4)
        assert {side: world.arm(side).joint_positions() for side in ArmSide} == joints
        assert world.time - started < 1.0  # the cameras' look before planning, no move
    assert refused.value.thing == WORLD + "Pen"
    message = str(refused.value)
    assert "loading the Pen onto the platform: refused before anything moved" in message
    assert "the right arm would not get the Pen by its top grasp past reaching the pre-grasp pose" in message
    assert "no collision-free joint path" in message
    assert set(kb.store.quads()) == before
