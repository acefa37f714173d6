"""A robot's hands are read from the store (kb/hands.py, the named query robot_hands): the shipped map's
Panda hands, the defaults where the store says nothing, and a typed error naming the gripper, its arm and
robot, the property and the value for a description no hand can have."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import pytest

from cbrs.kb import KnowledgeBase, Store
from cbrs.kb.hands import PANDA_HAND, PREGRASP_DISTANCE, SIDE_HOLD, SIDE_PITCH, Hand, HandError, read_hands
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.resources import ontology_dir
from cbrs.kb.semantic_map import MapError, SemanticMap
from cbrs.sim.scene import bundled_map

HOME, WORLD, SVC, GRAPH = PREFIXES["home"], PREFIXES["world"], PREFIXES["svc"], PREFIXES["graph"]
LAB = "http://example.org/lab#"

ARMS = f"""@prefix home: <{HOME}> .
@prefix lab:  <{LAB}> .
lab:Robot home:hasArm lab:Arm .
lab:Arm home:armSide "left" ; home:hasGripper lab:Hand .
"""


def hands_of(tmp_path: Path, hand: str, arms: str = ARMS) -> dict[str, Hand]:
    """The hands read from a store holding the core ontology and, in the map graph, ``arms`` and the
    statements ``hand`` makes of lab:Hand."""
    kb = KnowledgeBase(Store.open(":memory:"))
    kb.load([ontology_dir() / "core.ttl"], graph="ontology")
    path = tmp_path / "hand.ttl"
    path.write_text(arms + (f"lab:Hand {hand} .\n" if hand else ""), encoding="utf-8")
    kb.load([path], graph="map")
    return read_hands(kb)


def test_the_shipped_hands_are_the_panda_hands_stated_in_the_map() -> None:
    """ontologies/world.ttl states the Panda hand's geometry on both hands and no policy: read, each is the
    hand the simulated arms have, the named gripper kept."""
    hands = bundled_map().hands
    sides = {"Left": WORLD + "CytonDualArm01LeftArm", "Right": WORLD + "CytonDualArm01RightArm"}
    assert set(hands) == set(sides.values())
    for side, arm in sides.items():
        assert hands[arm].iri == f"{WORLD}CytonDualArm01{side}Hand"
        assert hands[arm] == replace(PANDA_HAND, iri=hands[arm].iri)


def test_one_robots_hands_are_read_by_binding_it() -> None:
    kb = KnowledgeBase.open(":memory:")
    try:
        assert read_hands(kb, robot=SVC + "CytonDualArm01") == bundled_map().hands
        assert read_hands(kb, robot=SVC + "P3DX01") == {}  # a robot with no arm
    finally:
        kb.store.close()


def test_a_hand_states_its_geometry_and_takes_the_default_policy(tmp_path: Path) -> None:
    hand = hands_of(tmp_path, "home:jawOpening 0.05 ; home:palmDepth 0.02 ; home:fingerLength 0.03")[LAB + "Arm"]
    assert hand == Hand(0.05, 0.02, 0.03, SIDE_HOLD, SIDE_PITCH, PREGRASP_DISTANCE, LAB + "Hand")


def test_a_policy_the_store_states_wins_over_the_default(tmp_path: Path) -> None:
    stated = (
        "home:jawOpening 0.08 ; home:palmDepth 0.034 ; home:fingerLength 0.046 ; "
        "home:sideHoldFraction 0.7 ; home:sideGraspPitch 0.5 ; home:pregraspDistance 0.12"
    )
    hand = hands_of(tmp_path, stated)[LAB + "Arm"]
    assert (hand.side_hold, hand.side_pitch, hand.pregrasp_distance) == (0.7, 0.5, 0.12)
    assert hand.side_span == pytest.approx(0.046 * math.cos(0.5))


def test_an_arm_the_map_gives_no_gripper_has_the_panda_hand(tmp_path: Path) -> None:
    bare = f"@prefix home: <{HOME}> .\n@prefix lab: <{LAB}> .\nlab:Robot home:hasArm lab:Arm .\n"
    assert hands_of(tmp_path, "", arms=bare) == {LAB + "Arm": PANDA_HAND}


GEOMETRY = "home:palmDepth 0.034 ; home:fingerLength 0.046"


@pytest.mark.parametrize(
    ("statements", "prop", "value", "says"),
    [
        pytest.param(f"home:jawOpening -0.05 ; {GEOMETRY}", "jawOpening", "-0.05", "more than 0", id="negative-jaw"),
        pytest.param(
            "home:jawOpening 0.08 ; home:palmDepth 0.034 ; home:fingerLength 0",
            "fingerLength",
            "0",
            "more than 0",
            id="zero-fingers",
        ),
        pytest.param(f'home:jawOpening "wide" ; {GEOMETRY}', "jawOpening", "wide", "not a number", id="not-a-number"),
        pytest.param(
            f"home:jawOpening 0.08, 0.05 ; {GEOMETRY}", "jawOpening", "0.05 and 0.08", "one value", id="two-values"
        ),
        pytest.param(
            f"home:jawOpening 0.08 ; {GEOMETRY} ; home:sideHoldFraction 1.5",
            "sideHoldFraction",
            "1.5",
            "at most 1",
            id="hold-over-one",
        ),
        pytest.param(
            f"home:jawOpening 0.08 ; {GEOMETRY} ; home:sideGraspPitch 1.6",
            "sideGraspPitch",
            "1.6",
            "below pi/2",
            id="pitch-past-vertical",
        ),
        pytest.param(
            "home:jawOpening 0.08 ; home:palmDepth 0.05 ; home:fingerLength 0.046",
            "palmDepth",
            "0.05",
            "home:fingerLength 0.046",
            id="palm-beyond-fingertips",
        ),
        pytest.param(
            "home:jawOpening 0.08 ; home:palmDepth 0.034 ; home:fingerLenght 0.046",
            "fingerLength",
            None,
            "did you mean home:fingerLength for its home:fingerLenght '0.046'?",
            id="misspelt-geometry",
        ),
    ],
)
def test_a_hand_no_gripper_can_have_is_refused_naming_it(
    tmp_path: Path, statements: str, prop: str, value: str | None, says: str
) -> None:
    with pytest.raises(HandError) as refused:
        hands_of(tmp_path, statements)
    error = refused.value
    assert isinstance(error, MapError)  # a map error like the others: 422 where it reaches the web
    assert (error.hand, error.arm, error.robot, error.property, error.value) == (
        LAB + "Hand",
        LAB + "Arm",
        LAB + "Robot",
        prop,
        value,
    )
    message = str(error)
    assert "Hand (http://example.org/lab#Hand) (the gripper of Arm of Robot)" in message
    assert f"home:{prop}" in message and says in message


def test_an_arm_with_two_grippers_is_refused(tmp_path: Path) -> None:
    arms = ARMS + "lab:Arm home:hasGripper lab:Other .\n"
    with pytest.raises(HandError) as refused:
        hands_of(tmp_path, f"home:jawOpening 0.08 ; {GEOMETRY}", arms=arms)
    assert refused.value.property == "hasGripper" and refused.value.value == f"{LAB}Hand and {LAB}Other"
    assert "Arm (http://example.org/lab#Arm) (an arm of Robot) has home:hasGripper" in str(refused.value)
    assert "an arm ends in one gripper" in str(refused.value)


def test_reading_the_semantic_map_refuses_a_bad_hand() -> None:
    """The map is read with its hands: a negative jaw opening stops it, as a negative size does."""
    kb = KnowledgeBase.open(":memory:")
    try:
        kb.update(
            f"DELETE {{ GRAPH <{GRAPH}map> {{ ?hand <{HOME}jawOpening> ?old }} }} "
            f"INSERT {{ GRAPH <{GRAPH}map> {{ ?hand <{HOME}jawOpening> -0.08 }} }} "
            f"WHERE {{ GRAPH <{GRAPH}map> {{ <{WORLD}CytonDualArm01LeftArm> <{HOME}hasGripper> ?hand . "
            f"?hand <{HOME}jawOpening> ?old }} }}",
            check_map=False,  # broken on purpose, for the reader to refuse (an update checked is refused)
        )
        with pytest.raises(HandError) as refused:
            SemanticMap.read(kb)
    finally:
        kb.store.close()
    assert refused.value.hand == WORLD + "CytonDualArm01LeftHand" and refused.value.value == "-0.08"
