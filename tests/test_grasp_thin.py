"""Thin objects and the jaws' clearance (sim/grasping.py ``held_height``, kb/hands.py): a top grasp keeps the
fingertips, which reach home:fingertipDepth below the grasp point, home:fingertipClearance above the surface
the object rests on (the ruler of docs/examples, 8 mm thick, taken at its class's half of that, had them
4 mm in the table, and the fingers closed over its top edge); an object no thicker than the clearance is
refused before anything moves; an object wider than the jaws' opening less each jaw's home:jawClearance is
refused. Checked on the computed grasp poses against the table's surface: no simulation run."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path
from typing import TypeVar

import pybullet as p
import pytest

from cbrs.actions.composer import Composer
from cbrs.kb import KnowledgeBase
from cbrs.kb.hands import FINGERTIP_CLEARANCE, JAW_CLEARANCE, HandError
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.semantic_map import SemanticMap
from cbrs.sim import skills
from cbrs.sim.components import SimEnvironment
from cbrs.sim.errors import GraspMisfitError, GraspTooThinError, GraspTooWideError
from cbrs.sim.grasping import GraspKind, ObjectModel, compute_grasp_pose, held_height
from cbrs.sim.run_checks import CannotGripError
from cbrs.sim.scene import bundled_map
from cbrs.sim.world import open_world
from tests.test_grasp16_depth import panda_pointing_down
from tests.test_hand_reader import hands_of

EXAMPLES = Path(__file__).parent.parent / "docs" / "examples"
WORLD, LAB = PREFIXES["world"], "https://example.org/lab#"
LEFT_ARM = WORLD + "CytonDualArm01LeftArm"
Refusal = TypeVar("Refusal", bound=Exception)
HAND = bundled_map().hands[LEFT_ARM]
"""The left arm's hand as the shipped map describes it (the Panda hand)."""
GRIPPER = "home:jawOpening 0.08 ; home:palmDepth 0.034 ; home:fingerLength 0.046"
"""A gripper's geometry, as the shipped map states the Panda's (without its fingertip depth)."""


@pytest.fixture(scope="module")
def ruler_map() -> SemanticMap:
    """The bundled map with the ruler of docs/examples."""
    kb = KnowledgeBase.open(":memory:")
    kb.load([EXAMPLES / "ruler.ttl"], graph="ontology")
    kb.load([EXAMPLES / "ruler.ttl"], graph="map")
    return SemanticMap.read(kb)


def _measured() -> tuple[float, float]:
    """The Panda's fingertips' lowest point below panda_grasptarget, and the open fingers' inner faces'
    distance from it, by the collision shapes' closest points (the hand pointing down, the fingers open)."""
    client = p.connect(p.DIRECT)
    try:
        body, target = panda_pointing_down(client)
        below = 0.05  # a plate's top this far below the grasp point
        plate = p.createCollisionShape(p.GEOM_BOX, halfExtents=(0.2, 0.2, 0.001), physicsClientId=client)
        plate_body = p.createMultiBody(
            0, plate, basePosition=(target[0], target[1], target[2] - below - 0.001), physicsClientId=client
        )
        point = p.createCollisionShape(p.GEOM_BOX, halfExtents=(0.0005, 0.0005, 0.0005), physicsClientId=client)
        probe = p.createMultiBody(0, point, basePosition=target, physicsClientId=client)
        gaps = [
            min(c[8] for c in p.getClosestPoints(plate_body, body, 0.2, linkIndexB=f, physicsClientId=client))
            for f in (9, 10)
        ]
        inner = [
            min(c[8] for c in p.getClosestPoints(probe, body, 0.2, linkIndexB=f, physicsClientId=client)) + 0.0005
            for f in (9, 10)
        ]
    finally:
        p.disconnect(physicsClientId=client)
    return below - min(gaps), min(inner)


def test_the_fingertip_depth_and_the_jaws_inner_faces_are_the_pandas() -> None:
    """Measured on the URDF's collision shapes: the fingertips 8.2 mm below the grasp point (less than
    the 1.2 cm fingerLength less palmDepth imply: those are bounding boxes, margins included), and the open
    fingers' inner faces 1.1 mm inside the stated opening on each side, within each jaw's clearance."""
    depth, inner = _measured()
    assert depth == pytest.approx(HAND.fingertip_depth, abs=0.0005)
    assert HAND.fingertip_depth < HAND.finger_length - HAND.palm_depth
    inside = HAND.jaw_opening / 2.0 - inner
    assert 0.0 < inside < HAND.jaw_clearance


def test_a_top_grasp_of_the_ruler_keeps_the_fingertips_above_the_table(ruler_map: SemanticMap) -> None:
    ruler = ruler_map.objects[LAB + "Ruler1"]
    table = ruler_map.things[ruler.support or ""].box.max_z
    model = ObjectModel.of(ruler)
    assert model.grasp is GraspKind.TOP and model.grasp_height == pytest.approx(0.004)  # 0.5 of 8 mm
    assert model.grasp_height < HAND.fingertip_depth  # there, the fingertips would be in the table
    arm = ruler_map.arms[LEFT_ARM]
    centre = (ruler.start.x, ruler.start.y, table + ruler.size[2] / 2.0)
    pose = compute_grasp_pose(model, centre, ruler.start.yaw, arm.mount, arm.yaw, hand=HAND)
    tips = pose.position[2] - HAND.fingertip_depth
    assert tips == pytest.approx(table + FINGERTIP_CLEARANCE)
    assert pose.bottom_offset == pose.model.grasp_height == pytest.approx(HAND.fingertip_depth + FINGERTIP_CLEARANCE)
    # the object hangs from the raised grasp point: the pose says where its bottom is
    assert pose.position[2] - pose.bottom_offset == pytest.approx(table)
    # a hand keeping its fingertips higher raises the grasp point as much
    wary = replace(HAND, fingertip_clearance=0.005)
    higher = compute_grasp_pose(model, centre, ruler.start.yaw, arm.mount, arm.yaw, hand=wary)
    assert higher.position[2] - HAND.fingertip_depth == pytest.approx(table + 0.005)


@pytest.mark.parametrize(
    "model",
    [
        pytest.param(ObjectModel("Pen", "blue", 0.016, 0.016, GraspKind.TOP, 0.012, (), (0.14, 0.016)), id="pen"),
        pytest.param(ObjectModel("Cup", "red", 0.10, 0.06, GraspKind.SIDE, 0.07), id="cup"),
        pytest.param(ObjectModel("Wafer", "red", 0.002, 0.03, GraspKind.SIDE, 0.001), id="side-grasped"),
    ],
)
def test_a_grasp_with_the_fingertips_clear_of_the_surface_keeps_its_class_grasp_height(model: ObjectModel) -> None:
    """The pen's 12 mm (0.75 of 16 mm) is above the tips' 8.2 + 2 mm; a side grasp is not raised."""
    assert held_height(model, HAND) == model.grasp_height


def test_an_object_too_thin_to_hold_above_its_surface_is_refused_naming_it_and_the_numbers() -> None:
    card = ObjectModel("Card", "red", 0.0015, 0.05, GraspKind.TOP, 0.00075, (), (0.085, 0.054))
    with pytest.raises(GraspTooThinError) as refused:
        compute_grasp_pose(card, (7.9, 3.1, 0.75075), 0.0, (7.57, 2.55, 0.65), math.pi / 2.0, hand=HAND)
    error = refused.value
    assert isinstance(error, GraspMisfitError)  # passed over for the next approach its class allows
    assert (error.name, error.approach, error.height) == ("Card", "top", 0.0015)
    assert (error.fingertip_depth, error.clearance) == (HAND.fingertip_depth, FINGERTIP_CLEARANCE)
    assert "the Card is 0.15 cm thick" in str(error) and "0.20 cm above the surface" in str(error)
    assert held_height(card, replace(HAND, fingertip_clearance=0.001)) == pytest.approx(0.0092)


def refused_before_moving(
    things: list[Path], task_file: Path, task: str, error: type[Refusal], seed: int = 0
) -> Refusal:
    """The ``error`` the checks before a run raise for ``task`` (of ``task_file``), with ``things`` (Turtle
    for the ontology and the map) added to the bundled store: asked before anything moves, and nothing
    moved or held when it is raised."""
    kb = KnowledgeBase.open(":memory:")
    kb.load(things, graph="ontology")
    kb.load(things, graph="map")
    kb.load([task_file], graph="requirements")
    plan = Composer(kb).compose(task).plan
    assert plan is not None
    requirements = {r.iri: r for r in kb.requirements()}
    with open_world(seed=seed, semantic_map=SemanticMap.read(kb)) as world:
        start = world.time
        with pytest.raises(error) as refused:
            SimEnvironment(world, kb).given(plan, requirements)
        assert world.time == start and not world.arm("left").held and not world.arm("right").held
    return refused.value


def test_a_ruler_too_thin_for_every_hand_is_refused_before_anything_moves(tmp_path: Path) -> None:
    thin = tmp_path / "ruler.ttl"
    thin.write_text(
        (EXAMPLES / "ruler.ttl").read_text(encoding="utf-8").replace("home:sizeZ 0.008", "home:sizeZ 0.0015"),
        encoding="utf-8",
    )
    error = refused_before_moving([thin], EXAMPLES / "fetch_my_ruler.ttl", "FetchMyRuler", CannotGripError)
    assert error.thing == LAB + "Ruler1" and error.http_status == 422
    assert {arm for arm, _, _ in error.refusals} == {LEFT_ARM, WORLD + "CytonDualArm01RightArm"}
    assert "the Ruler1 is 0.15 cm thick" in str(error) and "home:fingertipClearance" in str(error)


def test_an_object_wider_than_the_jaws_less_their_clearance_is_refused_naming_it() -> None:
    """The wine bottle of docs/examples, 7.5 cm across, in the 8 cm jaws: 2.5 mm each side, less than the
    3.5 mm a jaw clears an object by; a hand whose store says no clearance takes it."""
    bottle = ObjectModel("WineBottle1", "green", 0.30, 0.075, GraspKind.SIDE, 0.15)
    where, mount, facing = (7.45, 3.15, 0.90), (7.57, 2.55, 0.65), math.pi / 2.0
    with pytest.raises(GraspTooWideError) as refused:
        compute_grasp_pose(bottle, where, None, mount, facing, hand=HAND)
    assert refused.value.clearance == JAW_CLEARANCE == HAND.jaw_clearance
    assert "opens 8.0 cm, less 0.35 cm clear of each jaw: at most 7.3 cm" in str(refused.value)
    assert HAND.widest == pytest.approx(0.073)
    assert compute_grasp_pose(replace(bottle, width=0.073), where, None, mount, facing, hand=HAND).width == 0.073
    # the skills' own check, asked before a take wherever the object is, holds the jaws to the same width
    assert "at most 7.3 cm" in skills.can_grip(bottle, HAND)
    assert skills.can_grip(replace(bottle, width=0.073), HAND) == ""


def test_the_wine_bottle_is_refused_before_anything_moves() -> None:
    """PutWineOnCupboard (docs/examples): the bottle's class allows only a side grasp, and no hand's jaws
    pass its 7.5 cm with their clearance, whatever the seed; before, the hand moving in pushed it over."""
    places = [EXAMPLES / "wine_bottle.ttl", EXAMPLES / "low_cupboard.ttl"]
    task = EXAMPLES / "put_wine_on_cupboard.ttl"
    error = refused_before_moving(places, task, "PutWineOnCupboard", CannotGripError, seed=1)
    assert error.thing == LAB + "WineBottle1"
    assert {approach for _, approach, _ in error.refusals} == {"side"}
    assert "at most 7.3 cm" in str(error) and "home:jawClearance" in str(error)


def test_the_bundled_objects_fit_the_jaws_with_their_clearance() -> None:
    smap = bundled_map()
    for obj in smap.objects.values():
        model = ObjectModel.of(obj)
        assert model.width <= HAND.widest, obj.iri
        assert held_height(model, HAND) >= model.grasp_height


def test_the_store_states_the_fingertips_and_the_clearances(tmp_path: Path) -> None:
    """Unstated, the fingertips reach what the palm depth and finger length imply; stated, the store's."""
    assert HAND.fingertip_depth == 0.0082 and HAND.fingertip_clearance == FINGERTIP_CLEARANCE
    (implied,) = hands_of(tmp_path, GRIPPER).values()
    assert implied.fingertip_depth == pytest.approx(0.012)
    assert (implied.fingertip_clearance, implied.jaw_clearance) == (FINGERTIP_CLEARANCE, JAW_CLEARANCE)
    stated = f"{GRIPPER} ; home:fingertipDepth 0.009 ; home:fingertipClearance 0 ; home:jawClearance 0.001"
    (hand,) = hands_of(tmp_path, stated).values()
    assert (hand.fingertip_depth, hand.fingertip_clearance, hand.jaw_clearance) == (0.009, 0.0, 0.001)


@pytest.mark.parametrize(
    ("said", "prop", "problem"),
    [
        ("home:fingertipDepth 0.02", "fingertipDepth", "at most home:fingerLength less home:palmDepth"),
        ("home:fingertipClearance -0.001", "fingertipClearance", "at least 0"),
        ("home:jawClearance 0.04", "jawClearance", "must leave room within home:jawOpening"),
    ],
)
def test_a_fingertip_or_clearance_no_hand_can_have_is_refused(
    tmp_path: Path, said: str, prop: str, problem: str
) -> None:
    with pytest.raises(HandError) as refused:
        hands_of(tmp_path, f"{GRIPPER} ; {said}")
    assert refused.value.property == prop and problem in str(refused.value)
