"""A side grasp stops where the palm meets the object's near side (sim/grasping.py, palm_stop): the hand,
tilted down 35 degrees, went on until its grasp point reached the object's centre, and the palm met a
7 cm bottle 1 cm before that, pushed it 2.3 cm and tipped it 8.5 degrees before the fingers closed
(PutWineOnCupboard, the 7 cm variant, seed 2: "PickUpObject: nothing between the fingers"). The rule is
checked by the model, on the Panda's collision meshes (nothing stepped) and once in the home."""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import replace
from pathlib import Path

import pybullet as p
import pytest

from cbrs.kb.hands import HandError
from cbrs.kb.semantic_map import SemanticMap
from cbrs.sim import skills
from cbrs.sim.arms import EE_LINK, PYBULLET_DATA, ArmSide, panda_urdf
from cbrs.sim.grasping import GraspKind, ObjectModel, compute_grasp_pose, palm_stop, side_orientation
from cbrs.sim.scene import bundled_map
from cbrs.sim.world import HomeWorld, open_world
from tests.helpers_examples import wine7_store
from tests.helpers_hands import LAB as HANDS_LAB
from tests.helpers_hands import read_lab_hands
from tests.home_layout import ARM_FACING, ARM_MOUNTS

WORLD, LAB = "https://w3id.org/cbrs/world#", "https://example.org/lab#"
HAND = bundled_map().hands[WORLD + "CytonDualArm01LeftArm"]
"""The bundled robot's hand as the shipped map describes it (the Panda hand)."""
LEFT, FACING = ARM_MOUNTS["left"], ARM_FACING["left"]
AT = (7.35, 3.30, 0.90)
PALM = HAND.palm_depth * math.cos(HAND.side_pitch) - HAND.side_palm_lead
"""How far behind the grasp point, along the level approach, the tilted palm's face reaches."""


def bottle(diameter: float) -> ObjectModel:
    """A bottle 30 cm tall held from the side at half its height."""
    return ObjectModel("Bottle", "green", 0.30, diameter, GraspKind.SIDE, 0.15)


def box(depth: float, kind: GraspKind = GraspKind.SIDE) -> ObjectModel:
    """A box 4 cm across the jaws and ``depth`` along the left arm's approach (+y), 30 cm tall."""
    return ObjectModel("Carton", "green", 0.30, 0.04, kind, 0.15, (), (0.04, depth))


# -- the rule, by the model alone ----------------------------------------------------------------------


@pytest.mark.parametrize("diameter", [0.06, 0.07])
def test_the_grasp_point_stops_short_of_the_centre_by_what_the_palm_would_push(diameter: float) -> None:
    grasp = compute_grasp_pose(bottle(diameter), AT, None, LEFT, FACING, hand=HAND)
    short = diameter / 2.0 - PALM
    assert palm_stop(diameter, HAND) == pytest.approx(short) and short > 0.0
    x, y, z = grasp.position
    # back along the level approach (the left arm faces +y), at the height the class says
    assert x == pytest.approx(AT[0]) and AT[1] - y == pytest.approx(short)
    assert z == pytest.approx(AT[2]) and grasp.bottom_offset == pytest.approx(0.15)  # held at half its height
    assert grasp.width == pytest.approx(diameter)  # the jaws still close to its diameter


def test_an_object_the_palm_does_not_reach_and_a_top_grasp_are_held_at_the_centre() -> None:
    assert 2.0 * PALM > 0.04
    assert palm_stop(0.04, HAND) == 0.0
    shallow = compute_grasp_pose(box(0.04), AT, math.pi / 2.0, LEFT, FACING, hand=HAND)
    top = compute_grasp_pose(box(0.07, GraspKind.TOP), AT, math.pi / 2.0, LEFT, FACING, hand=HAND)
    assert shallow.position[:2] == pytest.approx(AT[:2]) and top.position[:2] == pytest.approx(AT[:2])


def test_the_stop_follows_the_hand_and_the_lead() -> None:
    """The palm's place is the store's (palm depth and side pitch), and so is its lead."""
    unled = replace(HAND, side_palm_lead=0.0)
    assert palm_stop(0.07, unled) == pytest.approx(0.035 - HAND.palm_depth * math.cos(HAND.side_pitch))
    level = replace(HAND, side_pitch=0.0)
    assert palm_stop(0.07, level) == pytest.approx(0.035 - HAND.palm_depth + HAND.side_palm_lead)


def test_a_grippers_lead_is_its_own_else_its_classes_else_the_pandas(tmp_path: Path) -> None:
    models = "lab:LongPalm rdfs:subClassOf home:Gripper ; home:sidePalmLead 0.009 .\n"
    geometry = "home:jawOpening 0.08 ; home:palmDepth 0.034 ; home:fingerLength 0.046"
    robot = (
        "lab:Robot home:hasArm lab:Left , lab:Right .\n"
        'lab:Left home:armSide "left" ; home:hasGripper lab:LeftHand .\n'
        'lab:Right home:armSide "right" ; home:hasGripper lab:RightHand .\n'
        f"lab:LeftHand a lab:LongPalm ; {geometry} .\nlab:RightHand a home:Gripper ; {geometry} .\n"
    )
    hands = read_lab_hands(tmp_path, models, robot)
    assert hands[HANDS_LAB + "Left"].side_palm_lead == 0.009  # its class's
    assert hands[HANDS_LAB + "Right"].side_palm_lead == HAND.side_palm_lead  # unstated: the Panda's
    with pytest.raises(HandError, match="sidePalmLead"):
        read_lab_hands(tmp_path, models.replace("0.009", "-0.001"), robot)


# -- on the Panda's collision meshes -------------------------------------------------------------------


@pytest.fixture(scope="module")
def panda() -> Iterator[tuple[int, int]]:
    """A pybullet client with the Panda, its hand in a side grasp's pose (tilted down by the hand's pitch,
    coming in along +x) and its fingers open: the client and the body."""
    client = p.connect(p.DIRECT)
    p.setAdditionalSearchPath(PYBULLET_DATA, physicsClientId=client)
    body = p.loadURDF(panda_urdf(), useFixedBase=True, physicsClientId=client)
    turn = side_orientation(0.0, HAND.side_pitch)
    q = p.calculateInverseKinematics(
        body, EE_LINK, (0.55, 0.0, 0.35), turn, maxNumIterations=500, residualThreshold=1e-6, physicsClientId=client
    )
    for joint, angle in enumerate(q[:7]):
        p.resetJointState(body, joint, angle, physicsClientId=client)
    for finger in (9, 10):
        p.resetJointState(body, finger, HAND.jaw_opening / 2.0, physicsClientId=client)
    yield client, body
    p.disconnect(physicsClientId=client)


def _gap(client: int, body: int, shape: int, ahead: float) -> float:
    """The hand's closest distance (negative: overlap) to a 60 cm tall ``shape`` whose centre is ``ahead`` of
    the grasp point along the level approach and whose top is 15 cm above it."""
    state = p.getLinkState(body, EE_LINK, computeForwardKinematics=True, physicsClientId=client)
    gx, gy, gz = state[4]
    thing = p.createMultiBody(0, shape, basePosition=(gx + ahead, gy, gz - 0.15), physicsClientId=client)
    try:
        points = [
            point[8]
            for link in (8, 9, 10)
            for point in p.getClosestPoints(body, thing, 0.05, linkIndexA=link, physicsClientId=client)
        ]
    finally:
        p.removeBody(thing, physicsClientId=client)
    return min(points, default=0.05)


@pytest.mark.parametrize(("kind", "depth"), [("cylinder", 0.07), ("cylinder", 0.06), ("box", 0.07)])
def test_the_palm_stops_at_the_near_side_not_in_it(panda: tuple[int, int], kind: str, depth: float) -> None:
    """Measured on the URDF: at the grasp point the rule gives, the palm is clear of a tall object's near side
    by less than a millimetre; at the object's centre, as before, it stood 1.2 cm into a 7 cm one."""
    client, body = panda
    state = p.getLinkState(body, EE_LINK, computeForwardKinematics=True, physicsClientId=client)
    assert state[4] == pytest.approx((0.55, 0.0, 0.35), abs=1e-4)  # the hand is where it was put
    if kind == "cylinder":
        shape = p.createCollisionShape(p.GEOM_CYLINDER, radius=depth / 2.0, height=0.60, physicsClientId=client)
    else:
        shape = p.createCollisionShape(p.GEOM_BOX, halfExtents=(depth / 2.0, 0.02, 0.30), physicsClientId=client)
    stop = palm_stop(depth, HAND)
    assert 0.0 <= _gap(client, body, shape, stop) < 0.001
    if depth >= 0.07:
        assert _gap(client, body, shape, 0.0) < -0.01


# -- in the home ---------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def home(tmp_path_factory: pytest.TempPathFactory) -> Iterator[HomeWorld]:
    """The bundled home with the wine bottle narrowed to 7 cm (docs/tasks.md, "the 7 cm variant"), seed 2."""
    kb = wine7_store(tmp_path_factory.mktemp("wine"))
    with open_world(seed=2, semantic_map=SemanticMap.read(kb)) as world:
        yield world


def test_the_right_hand_takes_the_7cm_bottle_without_pushing_it(home: HomeWorld) -> None:
    """Taken where it stands (its true centre, no perception): before, the palm pushed it 1.2 cm and tipped
    it as the fingers closed; now it is lifted where it stood, upright."""
    side = ArmSide.RIGHT
    assert skills.clear_view(home).succeeded
    spec, hand = home.arm_specs[side], home.arm(side).hand
    stood = home.pose("WineBottle1").position
    model = ObjectModel.of(home.map.objects[LAB + "WineBottle1"]).by(GraspKind.SIDE)
    grasp = compute_grasp_pose(model, stood, None, spec.mount, spec.yaw, hand=hand)
    assert math.dist(grasp.position[:2], stood[:2]) == pytest.approx(palm_stop(0.07, hand))
    assert skills.approach_object(home, side, grasp).succeeded
    taken = skills.pick_up_object(home, side, grasp)
    assert taken.succeeded, taken.reason
    held = home.pose("WineBottle1")
    up = p.getMatrixFromQuaternion(held.orientation)[8]
    assert math.dist(held.position[:2], stood[:2]) < 0.003  # lifted where it stood
    assert math.degrees(math.acos(min(1.0, up))) < 1.0
