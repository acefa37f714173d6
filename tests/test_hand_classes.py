"""A gripper has the values stated on it, else those of the nearest of its classes that states them
(kb/hands.py, the named query robot_hands): a lab describes a gripper model once, on its class, and each
gripper of that model is an individual of it."""

from __future__ import annotations

from pathlib import Path

import pytest

from cbrs.kb.hands import PREGRASP_DISTANCE, Hand, HandError
from cbrs.kb.namespaces import PREFIXES
from tests.helpers_hands import LAB, read_lab_hands

HOME = PREFIXES["home"]

MODELS = """
lab:ParallelGripper rdfs:subClassOf home:Gripper ; home:pregraspDistance 0.12 .
lab:Robotiq2F85 rdfs:subClassOf lab:ParallelGripper ;
    home:jawOpening 0.085 ; home:palmDepth 0.04 ; home:fingerLength 0.05 ; home:pregraspDistance 0.15 .
"""
"""A lab's catalogue of gripper models (the ontology graph): the 2F-85 states its geometry once, and a
pre-grasp distance that overrides its superclass's."""

ROBOT = """
lab:Robot home:hasArm lab:Left , lab:Right .
lab:Left home:armSide "left" ; home:hasGripper lab:LeftHand .
lab:Right home:armSide "right" ; home:hasGripper lab:RightHand .
lab:LeftHand a lab:Robotiq2F85 .
lab:RightHand a lab:Robotiq2F85 ; home:jawOpening 0.05 .
"""
"""Two grippers of that model (the map graph); the right one's jaws are limited to 5 cm."""


def read(tmp_path: Path, models: str, robot: str = ROBOT) -> dict[str, Hand]:
    return read_lab_hands(tmp_path, models, robot)


def test_each_gripper_of_a_model_has_the_models_values_and_its_own_win(tmp_path: Path) -> None:
    hands = read(tmp_path, MODELS)
    left, right = hands[LAB + "Left"], hands[LAB + "Right"]
    assert (left.jaw_opening, left.palm_depth, left.finger_length) == (0.085, 0.04, 0.05)
    assert (right.jaw_opening, right.palm_depth, right.finger_length) == (0.05, 0.04, 0.05)  # its own jaws
    assert left.pregrasp_distance == right.pregrasp_distance == 0.15  # the nearer class's, not 0.12
    assert (left.iri, right.iri) == (LAB + "LeftHand", LAB + "RightHand")


def test_a_policy_only_a_farther_class_states_is_inherited_and_else_the_default(tmp_path: Path) -> None:
    farther = MODELS.replace("; home:pregraspDistance 0.15 .", ".")
    assert read(tmp_path, farther)[LAB + "Left"].pregrasp_distance == 0.12
    none = farther.replace(" ; home:pregraspDistance 0.12 .", " .")
    assert read(tmp_path, none)[LAB + "Left"].pregrasp_distance == PREGRASP_DISTANCE


def test_two_classes_equally_near_that_disagree_are_refused_naming_both(tmp_path: Path) -> None:
    models = MODELS + "lab:Narrow rdfs:subClassOf home:Gripper ; home:jawOpening 0.04 .\n"
    robot = ROBOT.replace("lab:LeftHand a lab:Robotiq2F85 .", "lab:LeftHand a lab:Robotiq2F85 , lab:Narrow .")
    with pytest.raises(HandError) as refused:
        read(tmp_path, models, robot)
    error = refused.value
    assert (error.hand, error.arm, error.property, error.value) == (
        LAB + "LeftHand",
        LAB + "Left",
        "jawOpening",
        "0.04 and 0.085",
    )
    assert "its classes Narrow (0.04) and Robotiq2F85 (0.085), equally near it, disagree" in str(error)
    # a gripper of both that states its own jaw opening has it: the classes' disagreement is overridden
    robot = ROBOT.replace("lab:RightHand a lab:Robotiq2F85 ;", "lab:RightHand a lab:Robotiq2F85 , lab:Narrow ;")
    assert read(tmp_path, models, robot)[LAB + "Right"].jaw_opening == 0.05


def test_a_bad_value_from_a_class_names_the_class(tmp_path: Path) -> None:
    with pytest.raises(HandError) as refused:
        read(tmp_path, MODELS.replace("home:jawOpening 0.085", "home:jawOpening -0.085"))
    error = refused.value
    assert (error.property, error.value, error.source) == ("jawOpening", "-0.085", LAB + "Robotiq2F85")
    assert "has home:jawOpening '-0.085' from its class Robotiq2F85: a length in metres, more than 0" in str(error)


def test_a_misspelt_value_on_a_class_gets_a_did_you_mean(tmp_path: Path) -> None:
    with pytest.raises(HandError) as refused:
        read(tmp_path, MODELS.replace("home:fingerLength 0.05", "home:fingerLenght 0.05"))
    assert refused.value.property == "fingerLength" and refused.value.value is None
    assert "did you mean home:fingerLength for its class Robotiq2F85's home:fingerLenght '0.05'?" in str(refused.value)
