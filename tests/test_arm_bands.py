"""What a carry keeps clear is the hand's, as the store describes it (kb/arm_bands.py, kb/hands.py): the corridor
its palm sweeps either side of the way (home:carryCorridor) and the bands of the arm behind a side grasp
(home:sideGraspBand, each a home:ArmBand), stated on the gripper or once on a class of it; unstated, the
Panda's, the arm and hand of every simulated robot; a band no arm can have is a HandError naming the gripper,
the property, the value and the band."""

from __future__ import annotations

from pathlib import Path

import pyoxigraph as ox
import pytest

from cbrs.kb import KnowledgeBase
from cbrs.kb.arm_bands import PANDA_SIDE_ARM, ArmBand
from cbrs.kb.hands import CARRY_CORRIDOR, Hand, HandError
from cbrs.kb.loader import parse_file
from cbrs.kb.namespaces import PREFIXES, GraphName
from cbrs.kb.resources import ontology_dir
from tests.helpers_hands import LAB, read_lab_hands

HOME, WORLD = PREFIXES["home"], PREFIXES["world"]
BAND, MAP = ox.NamedNode(HOME + "sideGraspBand"), ox.NamedNode(PREFIXES["graph"] + "map")
GEOMETRY = "home:jawOpening 0.085 ; home:palmDepth 0.04 ; home:fingerLength 0.05"

MODELS = f"""
lab:LongArmGripper rdfs:subClassOf home:Gripper ; {GEOMETRY} ;
    home:carryCorridor 0.07 ; home:sideGraspBand lab:Wrist , lab:Forearm .
lab:Wrist a home:ArmBand ; home:bandFrom 0.0 ; home:bandTo 0.12 ; home:bandHalfWidth 0.05 ; home:bandUnderside 0.0 .
lab:Forearm a home:ArmBand ; home:bandFrom 0.12 ; home:bandTo 0.4 ; home:bandHalfWidth 0.06 ; home:bandUnderside -0.05 .
"""
"""A lab's gripper model (the ontology graph) with a narrower corridor and an arm lower behind a side grasp."""

ROBOT = """
lab:Robot home:hasArm lab:Left , lab:Right .
lab:Left home:armSide "left" ; home:hasGripper lab:LeftHand .
lab:Right home:armSide "right" ; home:hasGripper lab:RightHand .
lab:LeftHand a lab:LongArmGripper .
lab:RightHand a lab:LongArmGripper ; home:sideGraspBand [ a home:ArmBand ;
    home:bandFrom 0.0 ; home:bandTo 0.3 ; home:bandHalfWidth 0.08 ; home:bandUnderside 0.02 ] .
"""
"""Two grippers of that model (the map graph); the right one's arm is described on it, as one band."""


def read(tmp_path: Path, models: str, robot: str = ROBOT) -> dict[str, Hand]:
    return read_lab_hands(tmp_path, models, robot)


def test_a_grippers_corridor_and_bands_are_its_own_else_its_classes(tmp_path: Path) -> None:
    hands = read(tmp_path, MODELS)
    left, right = hands[LAB + "Left"], hands[LAB + "Right"]
    assert left.carry_corridor == right.carry_corridor == 0.07
    assert left.side_arm == (ArmBand(0.0, 0.12, 0.05, 0.0), ArmBand(0.12, 0.4, 0.06, -0.05))  # back from the grasp
    assert right.side_arm == (ArmBand(0.0, 0.3, 0.08, 0.02),)  # its own band, not the class's two


def test_a_gripper_stating_neither_has_the_pandas(tmp_path: Path) -> None:
    hand = read(tmp_path, f"lab:LongArmGripper rdfs:subClassOf home:Gripper ; {GEOMETRY} .")[LAB + "Left"]
    assert (hand.carry_corridor, hand.side_arm) == (CARRY_CORRIDOR, PANDA_SIDE_ARM)


@pytest.mark.parametrize(
    ("change", "prop", "value", "problem"),
    [
        pytest.param(("home:bandUnderside -0.05 ", ""), "bandUnderside", None, "a band states all of", id="missing"),
        pytest.param(("home:bandTo 0.4", "home:bandTo 0.4 , 0.5"), "bandTo", "0.4 and 0.5", "one value", id="two"),
        pytest.param(("home:bandTo 0.4", "home:bandTo 0.1"), "bandTo", "0.1", "ends further back", id="backwards"),
        pytest.param(("home:bandTo 0.4", 'home:bandTo "far"'), "bandTo", "far", "not a number", id="text"),
        pytest.param(
            ("home:bandHalfWidth 0.06", "home:bandHalfWidth 0"), "bandHalfWidth", "0", "more than 0", id="flat"
        ),
        pytest.param(
            ("home:carryCorridor 0.07", "home:carryCorridor 0"), "carryCorridor", "0", "more than 0", id="corridor"
        ),
    ],
)
def test_a_band_or_corridor_no_hand_can_have_is_refused_naming_it(
    tmp_path: Path, change: tuple[str, str], prop: str, value: str | None, problem: str
) -> None:
    with pytest.raises(HandError) as refused:
        read(tmp_path, MODELS.replace(*change))
    error = refused.value
    assert (error.hand, error.property, error.value, error.source) == (
        LAB + "LeftHand",
        prop,
        value,
        LAB + "LongArmGripper",
    )
    assert problem in str(error)
    assert error.band == ("" if prop == "carryCorridor" else LAB + "Forearm")
    if prop != "carryCorridor":
        assert f"home:{prop}" in str(error) and " for its arm band Forearm from its class" in str(error)


def test_equally_near_classes_naming_other_bands_are_refused_naming_both(tmp_path: Path) -> None:
    models = MODELS + "lab:Short rdfs:subClassOf home:Gripper ; home:sideGraspBand lab:Wrist .\n"
    robot = ROBOT.replace("lab:LeftHand a lab:LongArmGripper .", "lab:LeftHand a lab:LongArmGripper , lab:Short .")
    with pytest.raises(HandError) as refused:
        read(tmp_path, models, robot)
    assert (refused.value.hand, refused.value.property) == (LAB + "LeftHand", "sideGraspBand")
    assert "its classes LongArmGripper (Forearm, Wrist) and Short (Wrist), equally near it, name other bands" in str(
        refused.value
    )


def test_a_map_seeded_before_the_bands_gets_them_on_upgrade() -> None:
    """A store whose map is world.ttl 0.4.0's (no corridor, no bands) is brought up to the bundled map: the
    hands' bands are then the store's, not a default."""
    kb = KnowledgeBase.open(":memory:")
    try:
        history = ontology_dir() / "history" / "world-0.4.0.ttl"
        bundled = parse_file(ontology_dir() / "world.ttl", GraphName.MAP).quads
        kb.store.replace(bundled, parse_file(history, GraphName.MAP).quads)
        assert not list(kb.store.quads(None, BAND, None, MAP))
        assert kb.upgrade().changed
        named = {(quad.subject.value, quad.object.value) for quad in kb.store.quads(None, BAND, None, MAP)}
        hands = {WORLD + "CytonDualArm01LeftHand", WORLD + "CytonDualArm01RightHand"}
        bands = {WORLD + "PandaSideGraspHandBand", WORLD + "PandaSideGraspForearmBand"}
        assert named == {(hand, band) for hand in hands for band in bands}
    finally:
        kb.close()
