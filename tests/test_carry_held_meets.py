"""A carry the stated arm bands make impossible is refused before the arm moves (sim/skills.py: held_meets,
appliances; sim/arm_choice.py: carry_check; sim/transit.py: floor_cause). The fifth round's trial
(docs/tasks.md, lab5_wide_carry_hands.ttl with green_cup.ttl, RobotArmServeACup at seeds 1 and 2): the
lab's forearm band, 6 cm below the grasp point, kept over the green cup, holds the red cup's top at 0.95 m
on its way below the spout, and the carry stopped 10 cm short against the lever and the spout; the dry run
of the arm's moves, which sees the arm alone, had passed it. Checked here on the kinematics copies and the
map's boxes only: nothing is stepped."""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator
from pathlib import Path

import pytest

from cbrs.kb import KnowledgeBase
from cbrs.kb.arm_bands import PANDA_SIDE_ARM
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.semantic_map import SemanticMap
from cbrs.sim import arm_choice, skills
from cbrs.sim.arms import ArmSide
from cbrs.sim.components import SimEnvironment
from cbrs.sim.context import SimContext
from cbrs.sim.geometry import Region
from cbrs.sim.grasping import GraspKind, GraspPose, ObjectModel
from cbrs.sim.grounding import thing_region
from cbrs.sim.perception import ObjectEstimate
from cbrs.sim.transit import floor_cause
from cbrs.sim.world import open_world

EXAMPLES = Path(__file__).parent.parent / "docs" / "examples"
WORLD = PREFIXES["world"]
LEFT = ArmSide.LEFT

SPOUT = Region("Spout01", 7.73, 7.77, 3.29, 3.42, 0.95, 0.98)
"""The bundled dispenser's spout (ontologies/world.ttl)."""


def _held(bottom_offset: float = 0.07) -> GraspPose:
    """The bundled 6 cm by 10 cm cup, held by its side 7 cm above its bottom, the hand facing north."""
    cup = ObjectModel("Cup", "red", 0.10, 0.06, GraspKind.SIDE, bottom_offset)
    return GraspPose(cup, (7.43, 3.31, 0.82), (0.0, 0.0, 0.0, 1.0), (0.0, 1.0, 0.0), bottom_offset, 0.06)


@pytest.mark.parametrize(
    ("bottom", "met"),
    [
        pytest.param(0.852, "Spout01", id="lab-bands-top-at-0.952"),
        pytest.param(0.822, "", id="panda-bands-top-at-0.922"),
        pytest.param(0.845, "Spout01", id="top-within-the-margin"),
    ],
)
def test_a_held_object_carried_into_the_spout_is_refused_naming_it(bottom: float, met: str) -> None:
    """The way from where the cup was lifted to below the spout: its top level with the spout, or within
    COLLISION_MARGIN below it, is refused; 2.8 cm below it (the Panda arm's floor), not."""
    grasp = _held()
    end = (7.75, 3.31, 0.78 + grasp.bottom_offset)
    why = skills.held_meets([SPOUT], grasp, (7.43, 3.31, bottom + 0.07), end, bottom)
    if not met:
        assert why == ""
        return
    assert f"of the {met} (0.950-0.980 m high)" in why
    assert f"carried with its bottom at {bottom:.3f} m (its top at {bottom + 0.10:.3f} m)" in why


def test_a_held_object_lowered_beside_the_spout_is_not_refused() -> None:
    """Below the spout's height all the way (the bundled carry's 0.92 m top), or far from it in plan."""
    grasp = _held()
    assert skills.held_meets([SPOUT], grasp, (7.43, 3.31, 0.892), (7.75, 3.31, 0.85), 0.822) == ""
    assert skills.held_meets([SPOUT], grasp, (7.43, 3.31, 0.98), (7.60, 3.31, 0.85), 0.91) == ""


Scene = tuple[SimContext, ObjectEstimate, ObjectModel, Region]


@pytest.fixture(scope="module")
def scene() -> Iterator[Scene]:
    """The trial's store (the lab's hands and the green cup), its world built at seed 1, not stepped; the red
    cup where it lies, by its side grasp, to go below the tap."""
    kb = KnowledgeBase.open(":memory:")
    kb.update((EXAMPLES / "lab5_unhand.ru").read_text())
    kb.load([EXAMPLES / "lab5_wide_carry_hands.ttl"], graph="map")
    for graph in ("ontology", "map"):
        kb.load([EXAMPLES / "green_cup.ttl"], graph=graph)
    with open_world(seed=1, semantic_map=SemanticMap.read(kb)) as world:
        ctx = SimEnvironment(world, kb).context
        x, y, z = world.pose("Cup").position
        seen = ObjectEstimate(x, y, z, None, (0.06, 0.06, 0.10), "red", "Kinect01", world.time, 500)
        cup = ObjectModel.of(world.map.objects[WORLD + "Cup"]).by(GraspKind.SIDE)
        yield ctx, seen, cup, thing_region(world.map.things[WORLD + "BelowOfTap"])


def test_the_lab_bands_carry_below_the_tap_is_refused_before_the_arm_moves(scene: Scene) -> None:
    """The take and carry's dry run (the arm choice's check) refuses it, naming the spout, the floor and the
    band it keeps over the green cup, as the store states it."""
    ctx, seen, cup, below = scene
    refused, _ = arm_choice.carry_check(ctx, LEFT, below, (seen, cup))
    assert "past carrying it to (7.75, 3.31)" in refused
    assert "would come within 1 cm of the Spout01" in refused
    assert "the carry keeps the Cup's bottom at 0.85" in refused
    assert "the arm's band 0.175-0.350 m back from the grasp point (12 cm to either side, 6.0 cm below" in refused
    assert "over the Cup2" in refused


def test_the_same_carry_with_the_panda_arm_bands_is_not_refused(scene: Scene, monkeypatch: pytest.MonkeyPatch) -> None:
    """The same hands with the Panda arm's bands (its forearm 3 cm below the grasp point): the floor is 3 cm
    lower, the cup's top passes 2.8 cm under the spout, and the dry run makes the carry."""
    ctx, seen, cup, below = scene
    arm = ctx.world.arm(LEFT)
    monkeypatch.setattr(arm, "hand", dataclasses.replace(arm.hand, side_arm=PANDA_SIDE_ARM))
    refused, _ = arm_choice.carry_check(ctx, LEFT, below, (seen, cup))
    assert refused == ""


def test_the_floor_says_which_band_over_what(scene: Scene) -> None:
    ctx, seen, cup, below = scene
    cx, cy, _ = below.center
    cause = floor_cause(ctx, cup, LEFT, (seen.x, seen.y), (cx, cy))
    assert cause.startswith("the arm's band 0.175-0.350 m back from the grasp point") and "over the Cup2" in cause
