"""How deep an object may be along a side grasp's approach: the fingers, 4.6 cm from the palm to their tips
and tilted down 35 degrees, span 3.8 cm of it; a deeper object meets the palm and is pushed until its near
face rests against it. A side grasp is refused (GraspTooDeepError: the object, its depth, the finger
length) when less than the hand's side-hold fraction (a half: its centre of mass within the fingertips) would
lie between them, and the approach choice takes the object from the top instead (sim/grasping.py). The hand is
the store's (ontologies/world.ttl, kb/hands.py)."""

from __future__ import annotations

import math
import re
from dataclasses import replace
from pathlib import Path

import pybullet as p
import pytest

from cbrs.actions.composer import Composer
from cbrs.actions.runner import run_task
from cbrs.kb.semantic_map import SemanticMap
from cbrs.sim import skills
from cbrs.sim.arms import EE_LINK, PYBULLET_DATA, ArmSide, panda_urdf
from cbrs.sim.components import SimEnvironment
from cbrs.sim.errors import GraspMisfitError, GraspTooDeepError
from cbrs.sim.grasping import GraspKind, ObjectModel, compute_grasp_pose
from cbrs.sim.run_checks import CannotGripError
from cbrs.sim.scene import bundled_map
from cbrs.sim.services import pick_up
from cbrs.sim.world import open_world
from tests.home_layout import ARM_FACING, ARM_MOUNTS
from tests.test_grasp_width import (
    CENTRE,
    DEVICE,
    HOME,
    PUT_CARTON_ON_TRAY,
    TRAY,
    WORLD,
    _approach_the_carton,
    carton_in_the_map,
)
from tests.test_turtle_tasks_arms import knowledge

LEFT = ARM_MOUNTS["left"]
FACING = ARM_FACING["left"]  # +y: a box lying along y lies along a side grasp's approach
HAND = bundled_map().hands[WORLD + "CytonDualArm01LeftArm"]
"""The left arm's hand as the shipped map describes it (the Panda hand)."""
SPAN = HAND.finger_length * math.cos(HAND.side_pitch)  # what the tilted fingers span along the approach
BESIDE_THE_CUP = (7.35, 3.30, 0.79)
"""Where the left hand takes a box from the side (the carton tests' own spot, 7.55 x 3.15, it cannot)."""


def deep_box(depth: float, approaches: tuple[GraspKind, ...] = (GraspKind.SIDE, GraspKind.TOP)) -> ObjectModel:
    """A 4 cm wide, 8 cm high box ``depth`` long along its y axis."""
    return ObjectModel("Carton", "green", 0.08, 0.04, approaches[0], 0.06, approaches, (0.04, depth))


def panda_pointing_down(client: int) -> tuple[int, tuple[float, float, float]]:
    """The Panda loaded into ``client``, its hand pointing down and its fingers open: the body, and where
    its grasp target (panda_grasptarget) is."""
    p.setAdditionalSearchPath(PYBULLET_DATA, physicsClientId=client)
    body = p.loadURDF(panda_urdf(), useFixedBase=True, physicsClientId=client)
    down = p.getQuaternionFromEuler((math.pi, 0.0, 0.0))
    q = p.calculateInverseKinematics(body, EE_LINK, (0.5, 0.0, 0.4), down, maxNumIterations=200, physicsClientId=client)
    for joint, angle in enumerate(q[:7]):
        p.resetJointState(body, joint, angle, physicsClientId=client)
    for finger in (9, 10):
        p.resetJointState(body, finger, 0.04, physicsClientId=client)
    target = p.getLinkState(body, EE_LINK, computeForwardKinematics=True, physicsClientId=client)[4]
    return body, target


def test_the_finger_length_is_the_robots_hand_from_the_palm_to_the_fingertips() -> None:
    """Measured on the Panda's URDF (its collision meshes, the hand pointing down): the palm's lowest
    point to the fingertips. The shipped map describes the robot's hands; this keeps them the URDF's."""
    client = p.connect(p.DIRECT)
    try:
        body, target = panda_pointing_down(client)
        palm = p.getAABB(body, 8, physicsClientId=client)[0][2]  # panda_hand's lowest point
        tips = min(p.getAABB(body, finger, physicsClientId=client)[0][2] for finger in (9, 10))
    finally:
        p.disconnect(physicsClientId=client)
    assert abs(target[2] - 0.4) < 0.005  # the hand is where it was put, pointing down
    assert palm - tips == pytest.approx(HAND.finger_length, abs=0.002)
    assert palm - target[2] == pytest.approx(HAND.palm_depth, abs=0.002)


# -- the rule, by the model alone ----------------------------------------------------------------------


@pytest.mark.parametrize("depth", [0.10, 0.16])
def test_a_box_deeper_than_the_fingers_hold_is_refused_from_the_side_naming_it_its_depth_and_the_fingers(
    depth: float,
) -> None:
    with pytest.raises(GraspTooDeepError) as refused:
        compute_grasp_pose(deep_box(depth), BESIDE_THE_CUP, math.pi / 2.0, LEFT, FACING, hand=HAND)
    error = refused.value
    assert isinstance(error, GraspMisfitError)  # passed over like a box too wide for the jaws
    assert error.name == "Carton" and error.approach == "side"
    assert error.depth == pytest.approx(depth) and error.finger_length == HAND.finger_length
    assert error.held == pytest.approx(SPAN) and error.least == HAND.side_hold
    assert f"the Carton is {depth * 100:.1f} cm deep along the hand's approach by its side grasp" in str(error)
    assert "the fingers are 4.6 cm long: 3.8 cm of it would lie between them, less than the 50%" in str(error)


def test_the_limit_is_where_the_centre_of_mass_reaches_the_fingertips() -> None:
    """At a side hold of a half, a box up to twice the fingers' span along the approach is held from the side."""
    limit = SPAN / HAND.side_hold
    assert 0.07 < limit < 0.08
    assert (
        compute_grasp_pose(deep_box(limit - 1e-4), BESIDE_THE_CUP, math.pi / 2.0, LEFT, FACING, hand=HAND).width == 0.04
    )
    with pytest.raises(GraspTooDeepError):
        compute_grasp_pose(deep_box(limit + 1e-3), BESIDE_THE_CUP, math.pi / 2.0, LEFT, FACING, hand=HAND)


def test_depth_is_along_the_approach_and_a_top_grasp_is_not_limited_by_it() -> None:
    """A 7.8 x 4 cm box: lying across the approach the jaws (with no clearance) pass its 7.8 cm and the fingers
    hold all of its 4 cm depth; lying along it, the fingers would hold 3.8 of 7.8 cm; askew, its extent along
    the approach."""
    box = deep_box(0.078)
    snug = replace(HAND, jaw_clearance=0.0)  # 7.8 cm passes the 8 cm jaws only with no clearance to spare
    across = compute_grasp_pose(box, BESIDE_THE_CUP, 0.0, LEFT, FACING, hand=snug)  # its long axis along x
    assert across.model.grasp is GraspKind.SIDE and across.width == pytest.approx(0.078)
    with pytest.raises(GraspTooDeepError) as along:
        compute_grasp_pose(box, BESIDE_THE_CUP, math.pi / 2.0, LEFT, FACING, hand=HAND)
    assert along.value.depth == pytest.approx(0.078)
    with pytest.raises(GraspTooDeepError) as askew:  # 0.2 rad off the approach
        compute_grasp_pose(box, BESIDE_THE_CUP, math.pi / 2.0 - 0.2, LEFT, FACING)
    assert askew.value.depth == pytest.approx(0.078 * math.cos(0.2) + 0.04 * math.sin(0.2))
    top = compute_grasp_pose(deep_box(0.16).by(GraspKind.TOP), BESIDE_THE_CUP, math.pi / 2.0, LEFT, FACING, hand=HAND)
    assert top.width == pytest.approx(0.04)
    cup = ObjectModel("Cup", "red", 0.10, 0.06, GraspKind.SIDE, 0.07)  # 6 cm across: 3.8 of it held
    assert compute_grasp_pose(cup, CENTRE, None, LEFT, FACING).width == pytest.approx(0.06)


def test_the_fraction_a_hold_needs_is_the_hands() -> None:
    box = deep_box(0.10)
    loose, firm = replace(HAND, side_hold=0.3), replace(HAND, side_hold=0.7)
    assert (
        compute_grasp_pose(box, BESIDE_THE_CUP, math.pi / 2.0, LEFT, FACING, hand=loose).model.grasp is GraspKind.SIDE
    )
    with pytest.raises(GraspTooDeepError) as refused:
        compute_grasp_pose(deep_box(0.06), BESIDE_THE_CUP, math.pi / 2.0, LEFT, FACING, hand=firm)
    assert refused.value.least == 0.7 and "less than the 70% a hold needs" in str(refused.value)


# -- in the home --------------------------------------------------------------------------------------


def test_a_deep_box_allowed_only_its_side_grasp_is_refused_before_the_arm_moves(tmp_path: Path) -> None:
    """Before, the left hand took a 4 x 10 cm box lying along its approach by the side: the palm pushed it
    1.9 cm on, and the jaws closed on its near 3.8 cm, its centre 1 cm beyond the fingertips."""
    kb = knowledge(tmp_path, ("map", carton_in_the_map("side", 0.04, 0.10, at=BESIDE_THE_CUP)))
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        environment = SimEnvironment(world, kb)
        assert skills.clear_view(world).succeeded  # as the look before the approach leaves them
        before = {side: world.arm(side).joint_positions() for side in ArmSide}
        with pytest.raises(GraspTooDeepError) as refused:
            _approach_the_carton(environment, BESIDE_THE_CUP)
        after = {side: world.arm(side).joint_positions() for side in ArmSide}
    assert refused.value.name == "Carton1" and refused.value.depth == pytest.approx(0.10, abs=0.01)
    assert environment.context.grasp is None
    for side in ArmSide:
        assert after[side] == pytest.approx(before[side], abs=1e-3)


def test_a_deep_box_allowed_side_and_top_is_taken_from_the_top_saying_why_not_from_the_side(tmp_path: Path) -> None:
    kb = knowledge(tmp_path, ("map", carton_in_the_map("side top", 0.04, 0.10, at=BESIDE_THE_CUP)))
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        context = _approach_the_carton(SimEnvironment(world, kb), BESIDE_THE_CUP)
        assert context.grasp is not None and context.grasp.model.grasp is GraspKind.TOP
        pick_up(context, {}, DEVICE)
        carton = world.pose("Carton1").position
        hand = world.arm(context.arm).ee_pose().position
        assert world.arm(context.arm).held == world.body("Carton1")
    assert math.dist(carton[:2], hand[:2]) < 0.005  # held at its centre, not pushed on
    [choice] = context.choices
    assert [kind for kind, _ in choice.passed] == [GraspKind.SIDE]
    assert re.search(
        r"taking the Carton1: the left arm holds the Carton1 by its top grasp \(not by its side grasp: the Carton1 "
        r"is 1\d\.\d cm deep along the hand's approach by its side grasp, and the fingers are 4\.6 cm long",
        str(choice),
    )


def test_a_box_the_fingers_hold_enough_of_is_still_taken_from_the_side(tmp_path: Path) -> None:
    kb = knowledge(tmp_path, ("map", carton_in_the_map("side top", 0.04, 0.06, at=BESIDE_THE_CUP)))
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        context = _approach_the_carton(SimEnvironment(world, kb), BESIDE_THE_CUP)
        assert context.grasp is not None and context.grasp.model.grasp is GraspKind.SIDE
        pick_up(context, {}, DEVICE)
        assert world.arm(context.arm).held == world.body("Carton1")
    assert context.choices[0].passed == ()


@pytest.mark.parametrize(("approaches", "at"), [("side", BESIDE_THE_CUP), ("side top", CENTRE)])
def test_a_task_on_a_deep_box_stops_saying_so_or_takes_it_from_the_top(
    tmp_path: Path, approaches: str, at: tuple[float, float, float]
) -> None:
    """Allowed only its side grasp, the run is refused before anything moves with the depth, in the
    approach's words (it stopped at the approach, 1.1 s simulated at seed 0, until the checks before a run
    asked the same: docs/tasks.md, "A fifth round"); allowed "side top", the box is carried to the tray
    from the top, no re-plan."""
    carton = carton_in_the_map(approaches, 0.04, 0.10, at=at)
    kb = knowledge(tmp_path, ("map", carton), ("map", TRAY), ("requirements", PUT_CARTON_ON_TRAY))
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        start, began = world.pose("Carton1").position, world.time
        environment = SimEnvironment(world, kb)
        if approaches == "side":
            deep = r"the Carton1 is 10\.\d cm deep along the hand's approach by its side grasp"
            with pytest.raises(CannotGripError, match=deep):
                run_task(kb, "PutCartonOnTray", environment, composer=Composer(kb))
            assert world.time == began and world.pose("Carton1").position == pytest.approx(start, abs=0.002)
            return
        result = run_task(kb, "PutCartonOnTray", environment, composer=Composer(kb))
    facts = {(r["thing"].value, r["relation"].value, r["other"].value) for r in kb.select("world_facts")}
    on_the_tray = (WORLD + "Carton1", HOME + "isLocated", WORLD + "TrayPlace") in facts
    assert result.succeeded, result.report.reason if result.report else result.composition.unsatisfied
    assert on_the_tray and not result.replans
    assert [c.model.grasp for c in environment.context.choices] == [GraspKind.TOP]
