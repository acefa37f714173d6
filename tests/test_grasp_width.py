"""How wide an object is across the jaws depends on the approach and on how it lies: a side grasp closes
the jaws across the direction the hand comes from, a top grasp across the object's long axis (or, when
perception saw none, across the narrower of what it saw). A box wider across the jaws than they open is
refused by a typed error naming it and its width, not tried and dropped (sim/grasping.py)."""

from __future__ import annotations

import math
import re
from dataclasses import replace
from pathlib import Path

import pytest

from cbrs.actions.composer import Composer
from cbrs.actions.runner import run_task
from cbrs.kb.hands import PANDA_HAND
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.semantic_map import SemanticMap
from cbrs.sim import skills
from cbrs.sim.arms import ArmSide
from cbrs.sim.components import SimContext, SimEnvironment
from cbrs.sim.errors import GraspTooWideError
from cbrs.sim.geometry import quat_to_matrix
from cbrs.sim.grasping import GraspKind, ObjectModel, compute_grasp_pose
from cbrs.sim.grounding import manipulation_of
from cbrs.sim.perception import ObjectEstimate, recognise_object
from cbrs.sim.run_checks import CannotGripError
from cbrs.sim.services import approach, pick_up
from cbrs.sim.values import GraspPlan, to_json
from cbrs.sim.world import open_world
from tests.home_layout import ARM_FACING, ARM_MOUNTS
from tests.test_turtle_tasks_arms import knowledge

HOME, WORLD = PREFIXES["home"], PREFIXES["world"]
DEVICE = "CytonDualArm01"
LEFT, RIGHT = ARM_MOUNTS["left"], ARM_MOUNTS["right"]
FACING = ARM_FACING["left"]  # both arms face +y, across the table: a side grasp's jaws close along x
CARTON = ObjectModel("Carton", "green", 0.08, 0.04, GraspKind.SIDE, 0.06, (GraspKind.SIDE, GraspKind.TOP), (0.16, 0.04))
"""A long box, 16 cm along its x axis and 4 cm along its y axis."""
CENTRE = (7.55, 3.15, 0.79)


def carton_in_the_map(
    approaches: str, size_x: float, size_y: float, yaw: float = 0.0, at: tuple[float, ...] = CENTRE
) -> str:
    return f"""@prefix home: <https://w3id.org/cbrs/home#> . @prefix world: <https://w3id.org/cbrs/world#> .
@prefix owl: <http://www.w3.org/2002/07/owl#> . @prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> .
home:Carton a owl:Class ; rdfs:subClassOf home:Artifact ;
    home:graspApproach "{approaches}" ; home:graspHeightRatio 0.75 .
world:Carton1 a home:Carton ; home:shapeKind "box" ; home:sizeX {size_x} ; home:sizeY {size_y} ; home:sizeZ 0.08 ;
    home:massKg 0.05 ; home:colourName "green" ; home:rgba "0.10 0.75 0.20 1" ;
    home:isLocatedOn world:KitchenTable ; home:x {at[0]} ; home:y {at[1]} ; home:yaw {yaw} .
"""


# -- the width across the jaws, by the model alone -----------------------------------------------------


@pytest.mark.parametrize("axis", [0.0, math.pi / 2.0, 0.7])
def test_a_top_grasp_closes_across_the_long_axis_however_the_box_lies(axis: float) -> None:
    for mount in (LEFT, RIGHT):
        grasp = compute_grasp_pose(CARTON.by(GraspKind.TOP), CENTRE, axis, mount, FACING)
        assert grasp.width == pytest.approx(0.04)


def test_a_side_grasp_of_a_box_lying_along_the_approach_closes_across_its_narrow_side() -> None:
    """A 7 x 4 cm box (the 16 cm carton lying so is too deep for the fingers: tests/test_grasp16_depth.py)."""
    short = replace(CARTON, footprint=(0.07, 0.04))
    grasp = compute_grasp_pose(short, CENTRE, math.pi / 2.0, LEFT, FACING)  # its long axis along y
    assert grasp.width == pytest.approx(0.04)


@pytest.mark.parametrize(("axis", "width"), [(0.0, 0.16), (math.pi / 4.0, 0.20 / math.sqrt(2.0))])
def test_a_side_grasp_across_a_long_box_is_refused_naming_it_and_its_width(axis: float, width: float) -> None:
    with pytest.raises(GraspTooWideError) as refused:
        compute_grasp_pose(CARTON, CENTRE, axis, LEFT, FACING)
    assert refused.value.name == "Carton" and refused.value.approach == "side"
    assert refused.value.width == pytest.approx(width) and refused.value.opening == PANDA_HAND.jaw_opening
    assert f"the Carton is {width * 100:.1f} cm wide across the jaws by its side grasp" in str(refused.value)
    assert "the hand opens 8.0 cm" in str(refused.value)


def test_a_box_whose_long_axis_was_not_seen_is_taken_across_the_narrower_of_what_was() -> None:
    """Perception gives no axis for a box less than three times as long as it is wide: its extents along
    x and y bound its width across jaws closing along x or y (exactly, as they are its extents so)."""
    block = ObjectModel("Block", "green", 0.08, 0.05, GraspKind.TOP, 0.06, (), (0.05, 0.07))
    along_y = compute_grasp_pose(block, CENTRE, None, LEFT, FACING, seen=(0.05, 0.07))
    assert along_y.width == pytest.approx(0.05)
    along_x = compute_grasp_pose(block, CENTRE, None, LEFT, FACING, seen=(0.07, 0.05))
    assert along_x.width == pytest.approx(0.05)
    assert abs(quat_to_matrix(along_y.orientation)[0, 1]) == pytest.approx(1.0)  # jaws along x, across its y
    assert abs(quat_to_matrix(along_x.orientation)[1, 1]) == pytest.approx(1.0)  # jaws along y, across its x
    assert block.by(GraspKind.SIDE).across(FACING - math.pi / 2.0, None, (0.07, 0.05)) == pytest.approx(0.07)
    assert block.across(0.3, None, None) == pytest.approx(math.hypot(0.05, 0.07))  # nothing seen: its diagonal


def test_the_fingers_close_to_the_chord_through_the_grasp_point_and_the_jaws_open_past_the_extent() -> None:
    """Narrow fingers touch a box turned to them where its chord through the grasp point ends, inside its
    extent: told to close to the extent, they stopped short of it. Not knowing how it lies, they close to
    its narrower side, the shortest chord through its centre, and stop where they touch it."""
    box = ObjectModel("Box", "green", 0.08, 0.04, GraspKind.SIDE, 0.06, (), (0.06, 0.04))
    closing = FACING - math.pi / 2.0
    grasp = compute_grasp_pose(box, CENTRE, closing + 0.3, LEFT, FACING)  # its x axis 0.3 rad off the jaws
    assert grasp.width == pytest.approx(0.06 / math.cos(0.3))
    assert box.across(closing, closing + 0.3) == pytest.approx(0.06 * math.cos(0.3) + 0.04 * math.sin(0.3))
    assert box.grip(closing, None) == pytest.approx(0.04)
    assert compute_grasp_pose(box, CENTRE, None, LEFT, FACING, seen=(0.07, 0.06)).width == pytest.approx(0.04)


def test_a_cylinder_and_a_width_given_alone_are_as_wide_whichever_way() -> None:
    cup = ObjectModel("Cup", "red", 0.10, 0.06, GraspKind.SIDE, 0.07)
    for axis in (None, 0.0, 1.0):
        assert compute_grasp_pose(cup, CENTRE, axis, LEFT, FACING).width == pytest.approx(0.06)
        assert compute_grasp_pose(cup.by(GraspKind.TOP), CENTRE, axis, LEFT, FACING).width == pytest.approx(0.06)


def test_the_map_gives_a_box_its_footprint_and_a_value_about_it_gets_it_back(tmp_path: Path) -> None:
    smap = SemanticMap.read(knowledge(tmp_path, ("map", carton_in_the_map("side top", 0.16, 0.04))))
    carton = ObjectModel.of(smap.objects[WORLD + "Carton1"])
    assert carton.footprint == (0.16, 0.04) and carton.width == pytest.approx(0.04)
    assert ObjectModel.of(smap.objects[WORLD + "Cup"]).footprint is None
    value = to_json(GraspPlan(WORLD + "Carton1", carton), HOME + "GraspPose")  # one width in the JSON
    assert "footprint" not in str(value)

    class Context:
        map = smap

    known = manipulation_of(Context(), value).model  # type: ignore[arg-type]
    assert known.footprint == (0.16, 0.04) and known.preference == (GraspKind.SIDE, GraspKind.TOP)


# -- in the home --------------------------------------------------------------------------------------


def _seen(environment: SimEnvironment, at: tuple[float, ...] = CENTRE) -> ObjectEstimate:
    world = environment.world
    assert skills.clear_view(world).succeeded
    return recognise_object(world.camera("Kinect01").capture(), "green", near=(at[0], at[1]), radius=0.1)


def _approach_the_carton(environment: SimEnvironment, at: tuple[float, ...] = CENTRE) -> SimContext:
    """ApproachToObject on the carton as the plan gives it: its grasp plan and where the Kinect sees it."""
    world, context = environment.world, environment.context
    seen = _seen(environment, at)
    carton = world.map.objects[WORLD + "Carton1"]
    plan = to_json(GraspPlan(carton.iri, ObjectModel.of(carton)), HOME + "GraspPose")
    approach(context, {"graspPose": plan, "objectPosition": to_json(seen)}, DEVICE)
    return context


@pytest.mark.parametrize(("size_x", "size_y"), [(0.04, 0.16), (0.16, 0.04)])
def test_a_long_box_is_taken_from_the_top_across_its_narrow_side_lying_either_way(
    tmp_path: Path, size_x: float, size_y: float
) -> None:
    """The jaws close to 4 cm either way. Before, they closed to the box's y size whatever the approach:
    lying along y, 16 cm, wider than they open, and the hand came up with nothing between its fingers."""
    kb = knowledge(tmp_path, ("map", carton_in_the_map("top", size_x, size_y)))
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        context = _approach_the_carton(SimEnvironment(world, kb))
        assert context.grasp is not None and context.grasp.width == pytest.approx(0.04, abs=0.002)
        pick_up(context, {}, DEVICE)
        assert world.arm(context.arm).held == world.body("Carton1")
        assert world.pose("Carton1").position[2] > CENTRE[2] + 0.02  # lifted


def test_an_approach_too_wide_for_the_jaws_is_passed_over_saying_so(tmp_path: Path) -> None:
    """The box lies across the arms' facing: its side grasp (its class's first) would close the jaws
    across its 16 cm; the arm takes it from the top, and the choice says why not from the side."""
    kb = knowledge(tmp_path, ("map", carton_in_the_map("side top", 0.16, 0.04)))
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        context = _approach_the_carton(SimEnvironment(world, kb))
        assert context.grasp is not None and context.grasp.model.grasp is GraspKind.TOP
        pick_up(context, {}, DEVICE)
        assert world.arm(context.arm).held == world.body("Carton1")
    [choice] = context.choices
    assert [kind for kind, _ in choice.passed] == [GraspKind.SIDE]
    why = str(choice)  # the width by the yaw perception saw: 16 cm, give or take its error
    assert why.startswith("taking the Carton1: the left arm holds the Carton1 by its top grasp")
    assert re.search(
        r"not by its side grasp: the Carton1 is 1[56]\.\d cm wide across the jaws by its side grasp, and "
        r"the hand opens 8\.0 cm",
        why,
    )


def test_a_box_allowed_only_an_approach_too_wide_for_the_jaws_is_refused_before_the_arm_moves(
    tmp_path: Path,
) -> None:
    kb = knowledge(tmp_path, ("map", carton_in_the_map("side", 0.16, 0.04)))
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        environment = SimEnvironment(world, kb)
        seen = _seen(environment)
        carton = world.map.objects[WORLD + "Carton1"]
        plan = to_json(GraspPlan(carton.iri, ObjectModel.of(carton)), HOME + "GraspPose")
        before = {side: world.arm(side).joint_positions() for side in ArmSide}
        with pytest.raises(GraspTooWideError) as refused:
            approach(environment.context, {"graspPose": plan, "objectPosition": to_json(seen)}, DEVICE)
        after = {side: world.arm(side).joint_positions() for side in ArmSide}
    assert refused.value.name == "Carton1" and refused.value.approach == "side"
    assert refused.value.width == pytest.approx(0.16, abs=0.01)
    for side in ArmSide:
        assert after[side] == pytest.approx(before[side], abs=1e-3)


PUT_CARTON_ON_TRAY = """@prefix cbrs: <https://w3id.org/cbrs/core#> . @prefix home: <https://w3id.org/cbrs/home#> .
@prefix req: <https://w3id.org/cbrs/requirement#> . @prefix svc: <https://w3id.org/cbrs/service#> .
req:PutCartonOnTray a cbrs:Requirement ; cbrs:requestedBy svc:CytonDualArm01 ; cbrs:deviceName "CytonDualArm01" ;
    cbrs:serviceName "PutCartonOnTray" ;
    cbrs:hasOWLSModel [ a cbrs:OWLSModel ;
        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "carton" ; cbrs:parameterType home:Carton ] ;
        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "place" ; cbrs:parameterType home:ObjectPlace ] ;
        cbrs:hasEffect [ a cbrs:Effect ; cbrs:conditionSubject home:Carton ; cbrs:conditionPredicate home:isLocated ;
            cbrs:conditionObject home:ObjectPlace ] ] .
"""
TRAY = """@prefix home: <https://w3id.org/cbrs/home#> . @prefix world: <https://w3id.org/cbrs/world#> .
world:TrayPlace a home:ObjectPlace ;
    home:minX 7.25 ; home:maxX 7.40 ; home:minY 3.10 ; home:maxY 3.25 ; home:minZ 0.75 ; home:maxZ 0.75 .
"""


@pytest.mark.parametrize("approaches", ["side", "side top"])
def test_a_task_on_a_box_too_wide_for_its_side_grasp_says_so(tmp_path: Path, approaches: str) -> None:
    """Allowed only its side grasp, the box is refused before anything moves: across the jaws it is too
    deep for the fingers, turned along them too wide (the run stopped at the approach with the width until
    the checks before a run asked the depth too: docs/tasks.md, "A fifth round"; it was "no collision-free
    joint path" before that); allowed "side top", it is carried to the tray from the top."""
    carton = carton_in_the_map(approaches, 0.16, 0.04)
    kb = knowledge(tmp_path, ("map", carton), ("map", TRAY), ("requirements", PUT_CARTON_ON_TRAY))
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        start, began = world.pose("Carton1").position, world.time
        if approaches == "side":
            deep = r"the Carton1 is 16\.0 cm deep along the hand's approach by its side grasp"
            with pytest.raises(CannotGripError, match=deep):
                run_task(kb, "PutCartonOnTray", SimEnvironment(world, kb), composer=Composer(kb))
            assert world.time == began and world.pose("Carton1").position == pytest.approx(start, abs=0.002)
            return
        result = run_task(kb, "PutCartonOnTray", SimEnvironment(world, kb), composer=Composer(kb))
    facts = {(r["thing"].value, r["relation"].value, r["other"].value) for r in kb.select("world_facts")}
    on_the_tray = (WORLD + "Carton1", HOME + "isLocated", WORLD + "TrayPlace") in facts
    assert result.succeeded, result.report.reason if result.report else result.composition.unsatisfied
    assert on_the_tray and not result.replans
