"""The grasp planner, the arms, the skills and the predicates use the hand of the arm doing the work, as the
store describes it (kb/hands.py): a gripper described in Turtle with a narrower jaw refuses an object the
Panda hand takes, a shallower palm rules out a top grasp the Panda's allows, and a longer pre-grasp
distance moves the pre-grasp pose and what counts as near."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from cbrs.kb import KnowledgeBase
from cbrs.kb.hands import PANDA_HAND
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.semantic_map import SemanticMap
from cbrs.sim import predicates, skills
from cbrs.sim.arms import ArmSide
from cbrs.sim.errors import GraspTooWideError
from cbrs.sim.grasping import GraspKind, ObjectModel, compute_grasp_pose
from cbrs.sim.perception import ObjectEstimate
from cbrs.sim.scene import bundled_map
from cbrs.sim.world import open_world
from tests.home_layout import ARM_FACING, ARM_MOUNTS
from tests.test_hand_reader import LAB, hands_of

HOME, WORLD, GRAPH = PREFIXES["home"], PREFIXES["world"], PREFIXES["graph"]
CUP = ObjectModel.of(bundled_map().objects[WORLD + "Cup"])  # 6 cm across, side grasp first
WHERE = (7.45, 3.32, 0.80)
LEFT = (ARM_MOUNTS["left"], ARM_FACING["left"])
NARROW = "home:jawOpening 0.05 ; home:palmDepth 0.034 ; home:fingerLength 0.046"
"""A gripper like the Panda's whose jaws open 5 cm."""


def test_a_narrower_jaw_refuses_the_cup_the_panda_hand_takes(tmp_path: Path) -> None:
    narrow = hands_of(tmp_path, NARROW)[LAB + "Arm"]
    for kind in (GraspKind.SIDE, GraspKind.TOP):
        taken = compute_grasp_pose(CUP.by(kind), WHERE, None, *LEFT, hand=PANDA_HAND)
        assert taken.width == pytest.approx(0.06) and taken.hand is PANDA_HAND
        with pytest.raises(GraspTooWideError) as refused:
            compute_grasp_pose(CUP.by(kind), WHERE, None, *LEFT, hand=narrow)
        assert (refused.value.width, refused.value.opening) == (pytest.approx(0.06), 0.05)
        assert f"by its {kind.value} grasp, and the hand opens 5.0 cm" in str(refused.value)


def test_a_shallower_palm_rules_out_a_top_grasp_the_panda_hand_allows(tmp_path: Path) -> None:
    """The cup's top grasp holds it 3 cm below its top: the Panda's palm is 3.4 cm above the grasp point,
    a palm 2 cm above it would press on the cup."""
    shallow = hands_of(tmp_path, "home:jawOpening 0.08 ; home:palmDepth 0.02 ; home:fingerLength 0.046")
    top = CUP.by(GraspKind.TOP)
    assert skills.can_grip(top, PANDA_HAND) == ""
    refusal = skills.can_grip(top, shallow[LAB + "Arm"])
    assert "3.0 cm below its top" in refusal and "palm is 2.0 cm above" in refusal


def test_the_pregrasp_distance_is_the_hands(tmp_path: Path) -> None:
    far = "home:jawOpening 0.08 ; home:palmDepth 0.034 ; home:fingerLength 0.046 ; home:pregraspDistance 0.15"
    hand = hands_of(tmp_path, far)[LAB + "Arm"]
    grasp = compute_grasp_pose(CUP.by(GraspKind.TOP), WHERE, None, *LEFT, hand=hand)
    assert math.dist(grasp.pregrasp, grasp.position) == pytest.approx(0.15)
    assert grasp.pregrasp[2] == pytest.approx(grasp.position[2] + 0.15)  # straight up from a top grasp
    assert predicates.gripper_near_distance(hand) == pytest.approx(0.15 + predicates.APPROACH_SLACK)
    assert predicates.gripper_near_distance(PANDA_HAND) == pytest.approx(0.10 + predicates.APPROACH_SLACK)


def test_the_simulated_arm_takes_its_hand_from_the_store() -> None:
    """The left hand described with 5 cm jaws: the left arm's fingers open 5 cm, and asked whether it can
    take the cup where it stands it says the cup is too wide, before anything moves."""
    kb = KnowledgeBase.open(":memory:")
    try:
        kb.update(
            f"DELETE {{ GRAPH <{GRAPH}map> {{ ?hand <{HOME}jawOpening> ?old }} }} "
            f"INSERT {{ GRAPH <{GRAPH}map> {{ ?hand <{HOME}jawOpening> 0.05 }} }} "
            f"WHERE {{ GRAPH <{GRAPH}map> {{ <{WORLD}CytonDualArm01LeftArm> <{HOME}hasGripper> ?hand . "
            f"?hand <{HOME}jawOpening> ?old }} }}"
        )
        smap = SemanticMap.read(kb)
    finally:
        kb.store.close()
    with open_world(seed=0, semantic_map=smap) as world:
        left, right = world.arm(ArmSide.LEFT), world.arm(ArmSide.RIGHT)
        assert (left.hand.jaw_opening, left.open_width) == (0.05, 0.05)
        assert right.hand.jaw_opening == right.open_width == PANDA_HAND.jaw_opening
        left.open_gripper()
        assert left.gripper_width() == pytest.approx(0.05, abs=0.002)
        seen = ObjectEstimate(*WHERE, None, (0.06, 0.06, 0.10), "red", "Kinect01", world.time, 0)
        refusal = skills.can_take(world, seen, ArmSide.LEFT, CUP)
    assert refusal == str(GraspTooWideError("Cup", "side", 0.06, 0.05, left.hand.jaw_clearance))
