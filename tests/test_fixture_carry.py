"""A carry that would bring the arm within CARRY_CLEARANCE of a fixture its planning does not avoid (a tap's
lever, which a hand pushes to fill a cup) goes round it where a way pulled in towards the arm keeps clear
(skills.carry_object's ``around``), and a packing gives a later thing no spot where every posture holding it
there comes that near one (skills.set_down_meets). EraserCupPen (tests/test_room_by_free_arms.py's map, and
docs/execution.md): the right arm carries the pen west from (8.07, 3.30), under the lever; the straight way
brought its forearm into the lever and the carry stopped 0.16 m short. Nothing moves here: the dry runs plan
on the kinematics copies."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from cbrs.kb import KnowledgeBase
from cbrs.kb.semantic_map import MapObject, SemanticMap
from cbrs.sim import skills
from cbrs.sim.arm_choice import cannot_set_down, carry_check, lying_estimate
from cbrs.sim.arms import CARRY_CLEARANCE, ArmSide
from cbrs.sim.context import SimContext
from cbrs.sim.geometry import Region
from cbrs.sim.place_spots import place_spots, reach_of, spot_region
from cbrs.sim.values import Manipulation
from cbrs.sim.world import open_world
from tests.helpers_examples import EXAMPLES
from tests.test_room_by_free_arms import CUP_WEST, MAT_MAP

RIGHT = ArmSide.RIGHT
ERASER_ON_THE_MAT = """
PREFIX home: <https://w3id.org/cbrs/home#>
PREFIX lab6: <https://example.org/lab6#>
DELETE { GRAPH <https://w3id.org/cbrs/graph/map> { lab6:Eraser1 home:x ?x ; home:y ?y } }
INSERT { GRAPH <https://w3id.org/cbrs/graph/map> { lab6:Eraser1 home:x 7.51 ; home:y 3.336 } }
WHERE { GRAPH <https://w3id.org/cbrs/graph/map> { lab6:Eraser1 home:x ?x ; home:y ?y } }
"""
"""Where the runs set the eraser down before the pen's carry (the left arm, after a pass): off the pen's way
round, which passes within the hand's carry corridor of where the eraser lies at the start."""


@pytest.fixture(scope="module")
def mat(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[SimContext, MapObject, Region]]:
    """The world of EraserCupPen at seed 0 as the pen's carry finds it (the eraser on the mat; the cup, in
    the left hand by then, left where it lies: off the pen's ways), the pen, and the mat's surface."""
    directory: Path = tmp_path_factory.mktemp("fixture_carry")
    (directory / "mat.ttl").write_text(MAT_MAP, encoding="utf-8")
    kb = KnowledgeBase.open(":memory:")
    for graph in ("ontology", "map"):
        kb.load([EXAMPLES / "lab6_tidy_shelf.ttl", directory / "mat.ttl"], graph=graph)
    kb.update(CUP_WEST)
    kb.update(ERASER_ON_THE_MAT)
    smap = SemanticMap.read(kb)
    (pen,) = [o for o in smap.objects.values() if o.name == "Pen"]
    (place,) = [t for t in smap.things.values() if t.name == "Mat1"]
    right = reach_of(next(arm for iri, arm in smap.arms.items() if iri.endswith("RightArm")))
    surface, spots = place_spots(smap, place, pen.size, [right], [], [right])
    assert (7.61, 3.255) in [(round(x, 3), round(y, 3)) for x, y in spots]
    with open_world(seed=0, semantic_map=smap) as world:
        yield SimContext(world, kb), pen, surface
    kb.close()


def test_the_pens_carry_under_the_lever_goes_round_it_where_a_way_pulled_in_keeps_clear(
    mat: tuple[SimContext, MapObject, Region],
) -> None:
    ctx, pen, surface = mat
    lever = ctx.world.dispensers[0].lever.name
    seen, model = lying_estimate(ctx.world, None, pen), Manipulation.of(pen).model
    spot = spot_region(surface, 7.61, 3.255)
    refused, brushed = carry_check(ctx, RIGHT, spot, (seen, model))
    assert refused == ""  # the planning makes the straight carry, the forearm passing under the lever
    assert f"within {CARRY_CLEARANCE * 100:.0f} cm of the {lever}" in brushed
    assert carry_check(ctx, RIGHT, spot, (seen, model), around=True) == ("", "")


def test_a_way_round_over_ground_that_asks_the_object_higher_is_not_taken(
    mat: tuple[SimContext, MapObject, Region],
) -> None:
    """Something standing by the way round (a floor higher than the straight way's) keeps the carry straight:
    the way round passes ground the straight one does not."""
    ctx, pen, surface = mat
    seen, model = lying_estimate(ctx.world, None, pen), Manipulation.of(pen).model
    spot = spot_region(surface, 7.61, 3.255)
    mount = ctx.world.arm_specs[RIGHT].mount
    clear = skills.Round((mount[0], mount[1]), lambda a, b: None)
    crowded = skills.Round((mount[0], mount[1]), lambda a, b: 0.90)
    plan = skills.plan_carry
    assert plan(ctx.world, seen, RIGHT, model, spot, clearance=CARRY_CLEARANCE, around=clear).brushed == ""
    assert "Tap01" in plan(ctx.world, seen, RIGHT, model, spot, clearance=CARRY_CLEARANCE, around=crowded).brushed


def test_a_later_things_spot_under_the_spout_is_refused_where_no_posture_keeps_clear_of_it(
    mat: tuple[SimContext, MapObject, Region],
) -> None:
    """A packing asks each later thing's spots whether an arm can set it down there (cannot_set_down). The end
    poses' inverse kinematics let through spots below the tap that the right arm's planning has no way to,
    and the check before the run let EraserCupPen run with the eraser leaving the pen only those. A spot
    where every posture holding the pen there, or backed off from there, comes within CARRY_CLEARANCE of a
    fixture is refused, naming it; one west of the tap is not."""
    ctx, pen, surface = mat
    refused = cannot_set_down(ctx, pen, surface, (7.71, 3.235), {RIGHT})
    assert "the right arm holding the Pen by its top grasp over Mat1 at (7.71, 3.23)" in refused
    assert f"would come within {CARRY_CLEARANCE * 100:.0f} cm of the" in refused
    assert cannot_set_down(ctx, pen, surface, (7.61, 3.255), {RIGHT}) == ""
