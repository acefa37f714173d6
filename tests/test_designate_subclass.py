"""A second cup of a lab's own class beside the bundled one (docs/examples/green_cup.ttl, lab:GreenCup below
home:Cup) made every bundled task about "the cup" ambiguous; a class now means the things stated to be of
it and of no narrower class first (kb.semantic_map.designate, Reading.DIRECT_FIRST; docs/tasks.md). With
that, RobotArmServeACup carried the red cup past the green one, 20 cm behind its way, and the forearm behind
the side grasp knocked the green cup off the table: the carry's floor now keeps the arm behind a side grasp
over what stands under it (sim/transit.py; the bands of the arm are the hand's home:sideGraspBand in the store,
kb/arm_bands.py; docs/simulation.md)."""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass, replace
from pathlib import Path

import pybullet as p
import pytest

from cbrs.actions.composer import Composer
from cbrs.actions.runner import run_task
from cbrs.kb import KnowledgeBase
from cbrs.kb.arm_bands import PANDA_SIDE_ARM
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.semantic_map import AmbiguousDesignatorError, Reading, SemanticMap, designate
from cbrs.sim import transit
from cbrs.sim.arms import ARM_JOINTS, FINGER_JOINTS, ArmSide
from cbrs.sim.components import SimEnvironment
from cbrs.sim.geometry import Region
from cbrs.sim.grasping import GraspKind, ObjectModel, side_orientation
from cbrs.sim.world import HomeWorld, open_world

EXAMPLES = Path(__file__).parent.parent / "docs" / "examples"
HOME, WORLD, LAB = PREFIXES["home"], PREFIXES["world"], "https://example.org/lab#"


def _with_green_cup() -> KnowledgeBase:
    kb = KnowledgeBase.open(":memory:")
    kb.load([EXAMPLES / "green_cup.ttl"], graph="ontology")
    kb.load([EXAMPLES / "green_cup.ttl"], graph="map")
    return kb


@pytest.fixture(scope="module")
def kb() -> KnowledgeBase:
    return _with_green_cup()


# -- which thing a class designates --------------------------------------------------------------------


def test_a_class_means_the_thing_stated_to_be_of_it_before_one_of_a_narrower_class(kb: KnowledgeBase) -> None:
    assert designate(kb, HOME + "Cup") == WORLD + "Cup"
    assert designate(kb, LAB + "GreenCup") == LAB + "Cup2"
    with pytest.raises(AmbiguousDesignatorError) as every_cup:
        designate(kb, HOME + "Cup", reading=Reading.ANY)  # the other reading: every cup alike
    assert every_cup.value.candidates == [LAB + "Cup2", WORLD + "Cup"] and every_cup.value.stated is None


def test_no_thing_stated_of_the_class_itself_is_still_ambiguous_and_says_what_to_name(kb: KnowledgeBase) -> None:
    with pytest.raises(AmbiguousDesignatorError) as refused:
        designate(kb, HOME + "Drinkware")  # a home:Cup and a lab:GreenCup, neither a plain Drinkware
    assert refused.value.candidates == [LAB + "Cup2", WORLD + "Cup"] and refused.value.stated is False
    said = str(refused.value)
    assert "none stated to be a Drinkware" in said and "name in the task (its input's cbrs:parameterType" in said


def test_two_things_stated_of_the_class_are_ambiguous_until_one_has_a_class_of_its_own() -> None:
    kb = KnowledgeBase.open(":memory:")
    kb.update("INSERT DATA { GRAPH graph:map { world:Cup3 a home:Cup ; home:x 7.3 ; home:y 3.6 } }")
    with pytest.raises(AmbiguousDesignatorError) as refused:
        designate(kb, HOME + "Cup")
    assert refused.value.candidates == [WORLD + "Cup", WORLD + "Cup3"] and refused.value.stated is True
    said = str(refused.value)
    assert "are each stated to be a Cup" in said
    assert "world:Cup a world:MyCup . world:MyCup rdfs:subClassOf home:Cup" in said
    # the advice followed for Cup3, its home:Cup left stated: a class of its own names it, and home:Cup the other
    kb.update(
        f"INSERT DATA {{ GRAPH graph:map {{ <{LAB}MyCup> a owl:Class ; rdfs:subClassOf home:Cup . "
        f"world:Cup3 a <{LAB}MyCup> }} }}"
    )
    assert designate(kb, HOME + "Cup") == WORLD + "Cup"
    assert designate(kb, LAB + "MyCup") == WORLD + "Cup3"


def test_a_class_the_taxonomy_makes_the_same_counts_as_the_class_itself() -> None:
    """A subclass cycle (A below B below A, as an entailment may state) makes A and B one class: a thing
    stated an A is stated a B, and wins over a thing of a class only below them."""
    kb = KnowledgeBase.open(":memory:")
    kb.update(
        f"INSERT DATA {{ GRAPH graph:ontology {{ <{LAB}A> a owl:Class ; rdfs:subClassOf <{LAB}B> . "
        f"<{LAB}B> a owl:Class ; rdfs:subClassOf <{LAB}A> . <{LAB}C> a owl:Class ; rdfs:subClassOf <{LAB}A> }} "
        f"GRAPH graph:map {{ <{LAB}x> a <{LAB}A> ; home:x 1.0 . <{LAB}y> a <{LAB}C> ; home:x 2.0 }} }}"
    )
    assert designate(kb, LAB + "B") == LAB + "x"


# -- the carry past the green cup ------------------------------------------------------------------------


@dataclass(frozen=True)
class _Served:
    succeeded: bool
    replans: int
    green_before: tuple[float, float, float]
    green_after: tuple[float, float, float]
    red_after: tuple[float, float, float]
    water: float
    floor_with_arm: float | None
    floor_without_arm: float | None


@pytest.fixture(scope="module")
def served(kb: KnowledgeBase) -> Iterator[tuple[HomeWorld, _Served]]:
    """RobotArmServeACup at seed 0 with the green cup at (7.62, 3.12), 20 cm behind the red cup's way from
    (7.45, 3.32) to below the tap (7.75, 3.31); and the floor of that carry, with and without the arm behind
    the side grasp (the left hand's bands, as the store states them, and none: the floor as it was)."""
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        env = SimEnvironment(world, kb)
        red = ObjectModel.of(world.map.objects[WORLD + "Cup"]).by(GraspKind.SIDE)
        below = world.map.things[WORLD + "BelowOfTap"].box
        spot = Region("BelowOfTap", below.min_x, below.max_x, below.min_y, below.max_y, below.min_z, below.max_z)
        start = world.pose("Cup").position
        with_arm = transit.floor_to(env.context, red, ArmSide.LEFT, start, spot)
        left = world.arm(ArmSide.LEFT)
        stated, left.hand = left.hand, replace(left.hand, side_arm=())
        try:
            without_arm = transit.floor_to(env.context, red, ArmSide.LEFT, start, spot)
        finally:
            left.hand = stated
        green_before = world.pose("Cup2").position
        result = run_task(kb, "RobotArmServeACup", env, composer=Composer(kb))
        yield (
            world,
            _Served(
                result.succeeded,
                len(result.replans),
                green_before,
                world.pose("Cup2").position,
                world.pose("Cup").position,
                world.water.get("Cup", 0.0),
                with_arm,
                without_arm,
            ),
        )


def test_the_red_cup_is_served_and_the_green_cup_stays_where_it_was(served: tuple[HomeWorld, _Served]) -> None:
    world, run = served
    assert run.succeeded and run.replans == 0
    assert math.dist(run.green_before, run.green_after) < 0.01  # knocked 0.84 m off the table before
    below = world.map.things[WORLD + "BelowOfTap"].box
    assert below.contains_xy(run.red_after[0], run.red_after[1]) and run.water > 0.0


def test_the_floor_keeps_the_forearm_over_the_green_cup(kb: KnowledgeBase, served: tuple[HomeWorld, _Served]) -> None:
    """The green cup's top is 0.84 m: the forearm, up to 3 cm below the grasp point, passes 2 cm over it."""
    world, run = served
    assert run.floor_with_arm is not None
    smap = SemanticMap.read(kb)
    green, table = smap.objects[LAB + "Cup2"], smap.things[WORLD + "KitchenTable"].box
    grasp_height = ObjectModel.of(smap.objects[WORLD + "Cup"]).grasp_height
    wrist = min(band.underside for band in world.arm(ArmSide.LEFT).hand.side_arm)
    top = table.max_z + green.size[2]
    assert run.floor_with_arm + grasp_height + wrist == pytest.approx(top + transit.TRANSIT_CLEARANCE)
    assert run.floor_without_arm is None or run.floor_without_arm < run.floor_with_arm - 0.02


def test_the_arm_behind_a_side_grasp_is_where_the_store_says(served: tuple[HomeWorld, _Served]) -> None:
    """The bands the store states of the bundled hands (ontologies/world.ttl) against the arms themselves, at
    a few side grasps over the table: straight up from the table under each band, the first link the ray
    meets (the fingers aside) is no lower than its underside."""
    world, _ = served
    assert all(world.arm(side).hand.side_arm == PANDA_SIDE_ARM for side in ArmSide)
    met = 0
    for side, grasp in (
        (ArmSide.LEFT, (7.45, 3.30, 0.86)),
        (ArmSide.LEFT, (7.6, 3.4, 0.80)),
        (ArmSide.RIGHT, (8.0, 3.3, 0.9)),
    ):
        arm, spec = world.arm(side), world.arm_specs[side]
        planned = arm.dry_run()
        assert planned.reach(grasp, side_orientation(spec.yaw, arm.hand.side_pitch)).reached
        for joint, angle in zip(ARM_JOINTS, planned.joint_positions(), strict=True):
            p.resetJointState(arm.body, joint, angle, physicsClientId=world.client)
        tip = arm.ee_pose().position
        back, aside = (-math.cos(spec.yaw), -math.sin(spec.yaw)), (-math.sin(spec.yaw), math.cos(spec.yaw))
        for band in arm.hand.side_arm:
            samples = [
                (tip[0] + b * back[0] + s * aside[0], tip[1] + b * back[1] + s * aside[1])
                for b in (band.near + 0.01, (band.near + band.far) / 2, band.far)
                for s in (-band.half_width, 0.0, band.half_width)
            ]
            hits = p.rayTestBatch(
                [(x, y, 0.751) for x, y in samples], [(x, y, 1.6) for x, y in samples], physicsClientId=world.client
            )
            for hit in hits:
                if hit[0] == arm.body and hit[1] not in FINGER_JOINTS:
                    met += 1
                    assert hit[3][2] >= tip[2] + band.underside - 1e-3, (side, grasp, band, hit[3])
    assert met >= 18, met  # of the 54 rays, 24 meet the arm (the others pass beside it or meet a cup)
