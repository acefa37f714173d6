"""The second round of tasks written only in Turtle from docs/tasks.md (docs/examples): a tall thin vase
put on a sill; a second cup of a class of its own, filled and not the bundled one; the pen put on the
base's platform by a goal alone; the pen and a toy block brought together; the cup sent to a bookcase in
another room, which no arm there can do. One runs in the simulation (PutVaseOnSill at seed 0); the green
cup's failure at seed 1 is checked where it arose (a hand in the spout), the others are planned only."""

from __future__ import annotations

import math
from pathlib import Path

from cbrs.actions.composer import Composer
from cbrs.actions.runner import run_task
from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.semantic_map import SemanticMap
from cbrs.sim import skills
from cbrs.sim.arms import ArmSide
from cbrs.sim.components import SimEnvironment
from cbrs.sim.geometry import Region, quat_to_matrix
from cbrs.sim.grasping import GraspKind, ObjectModel
from cbrs.sim.perception import ObjectEstimate
from cbrs.sim.world import open_world

EXAMPLES = Path(__file__).parent.parent / "docs" / "examples"
HOME, WORLD, SVC, LAB = PREFIXES["home"], PREFIXES["world"], PREFIXES["svc"], "https://example.org/lab#"


def _store(things: str | None, task: str) -> KnowledgeBase:
    kb = KnowledgeBase.open(":memory:")
    if things is not None:
        kb.load([EXAMPLES / things], graph="ontology")
        kb.load([EXAMPLES / things], graph="map")
    kb.load([EXAMPLES / task], graph="requirements")
    return kb


def test_a_tall_thin_vase_is_taken_from_over_its_top_and_set_down_upright() -> None:
    """A vase 25 cm tall, taken at half its height: on its way to the pre-grasp pose the hand swept into
    the vase's top (ApproachToObject stopped 15 cm short) and the re-plans knocked it over; it now comes
    down to that pose from over the top (skills._approach). Shorter vases that got to the sill were
    carried there tilted by 109 degrees, the joint-space carry having turned the hand half a turn about
    its side grasp's axis, and fell over as the hand opened; that turn is now kept for a top grasp only."""
    kb = _store("vase_and_sill.ttl", "put_vase_on_sill.ttl")
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        result = run_task(kb, "PutVaseOnSill", SimEnvironment(world, kb), composer=Composer(kb))
        vase = world.pose("Vase1")
    assert result.succeeded, result.report.reason if result.report else result.composition.unsatisfied
    assert result.replans == ()
    sill = SemanticMap.read(kb).things[LAB + "Sill1"].box
    assert sill.contains_xy(vase.position[0], vase.position[1])
    upright = quat_to_matrix(vase.orientation)[2, 2]  # the vase's axis against the vertical
    assert upright > math.cos(math.radians(5))


def test_a_hand_in_the_spout_is_no_pose_the_arm_can_hold() -> None:
    """FillTheGreenCup at seed 1: the left arm cannot take the green cup by its side grasp, and its top
    grasp passed every check though the hand cannot hold the cup so below the spout without being in the
    spout: the carry ran into the dispenser, stopped 6.6 cm short twice, and the run gave up. Such a pose
    is refused now (sim/arms.py: Kinematics.strikes), and the right arm's side grasp is left."""
    kb = _store("green_cup.ttl", "fill_the_green_cup.ttl")
    with open_world(seed=1, semantic_map=SemanticMap.read(kb)) as world:
        model = ObjectModel.of(world.map.objects[LAB + "Cup2"])
        x, y, z = world.pose("Cup2").position
        seen = ObjectEstimate(x, y, z, None, (0.06, 0.06, 0.09), "green", "Kinect01", 0.0, 100)
        below = SemanticMap.read(kb).things[WORLD + "BelowOfTap"].box
        spot = Region("BelowOfTap", below.min_x, below.max_x, below.min_y, below.max_y, below.min_z, below.max_z)
        from_the_top = skills.can_set_down(world, seen, ArmSide.LEFT, model.by(GraspKind.TOP), spot)
        by_the_side = skills.can_set_down(world, seen, ArmSide.RIGHT, model.by(GraspKind.SIDE), spot)
    assert "cannot hold the Cup2 by its top grasp over BelowOfTap" in from_the_top
    assert by_the_side == ""


def test_a_goal_about_where_the_pen_is_brings_the_base_to_the_table_first() -> None:
    """No step is named: the hand-over onto the platform needs the base at the table, so it drives there."""
    plan = Composer(_store(None, "load_pen_onto_base.ttl")).compose("LoadPenOntoBase").plan
    assert plan is not None
    components = plan.components()
    drive, load = SVC + "NavigateToPlace_P3DX01", SVC + "HandOverOntoPlatform_CytonDualArm01"
    assert components.index(drive) < components.index(load)
    assert SVC + "DeliverObject_P3DX01" not in components


def test_two_things_for_the_person_are_fetched_one_after_the_other() -> None:
    plan = Composer(_store("toy_block.ttl", "fetch_pen_and_block.ttl")).compose("FetchPenAndBlock").plan
    assert plan is not None and plan.method == "decomposed"
    assert plan.components().count(SVC + "DeliverObject_P3DX01") == 2


def test_a_cup_for_a_bookcase_in_another_room_has_no_plan_and_says_where_the_arms_work() -> None:
    kb = _store("bookcase.ttl", "cup_to_the_bookcase.ttl")
    result = Composer(kb).compose("CupToTheBookcase")
    assert result.plan is None
    passed = [why for need in result.unsatisfied for _, why in need.out_of_area]
    assert any("home:Kitchen" in why and "Bookcase1" in why and "home:LivingRoom" in why for why in passed), passed
