"""CarryObject aims at a spot of its target place that an arm reaches (the reachable spot of the place
nearest its centre, the object's footprint on the surface and clear of the other objects and the
fixtures), and the check before a run refuses a place only when no such spot exists (sim/place_spots.py,
sim/run_checks.py)."""

from __future__ import annotations

import math
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest

from cbrs.actions.composer import Composer
from cbrs.actions.runner import run_task
from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.semantic_map import SemanticMap
from cbrs.sim.components import OutOfReachError, SimEnvironment
from cbrs.sim.grasping import ObjectModel
from cbrs.sim.perception import ObjectEstimate
from cbrs.sim.place_spots import RELAY_CLEARANCE, RELAY_MARGIN, place_spots
from cbrs.sim.relations import Grounded
from cbrs.sim.services import approach, carry, pick_up, put_down
from cbrs.sim.values import GraspPlan, designator, to_json
from cbrs.sim.world import HomeWorld, open_world

HOME, WORLD = PREFIXES["home"], PREFIXES["world"]
DEVICE = "CytonDualArm01"
MORE = Path(__file__).parent / "data" / "turtle_tasks_more"

# A pen rest on the table's west edge: its corner nearest the left arm is 0.82 m from the arm's mount
# (the arm reaches 0.85 m), so part of it is in reach by the map, but no spot of it is 5 cm inside the
# reach with the pen's footprint on the table.
PEN_REST_AT_THE_EDGE = """
@prefix home:  <https://w3id.org/cbrs/home#> .
@prefix world: <https://w3id.org/cbrs/world#> .
@prefix owl:   <http://www.w3.org/2002/07/owl#> .
@prefix rdfs:  <http://www.w3.org/2000/01/rdf-schema#> .
home:PenRest a owl:Class ; rdfs:subClassOf home:ObjectPlace ; rdfs:label "pen rest"@en .
world:PenRestAtTheEdge a home:PenRest ;
    home:minX 7.00 ; home:maxX 7.14 ; home:minY 3.25 ; home:maxY 3.40 ; home:minZ 0.75 ; home:maxZ 0.75 .
"""


@contextmanager
def holding_the_cup() -> Iterator[tuple[HomeWorld, SimEnvironment]]:
    """The home, the cup taken from where it stands by the arm the approach chooses."""
    kb = KnowledgeBase.open(":memory:")
    with open_world(seed=0) as world:
        environment = SimEnvironment(world, kb)
        environment.perceive()
        cup = world.map.objects[world.objects["Cup"].iri]
        x, y, z = world.pose("Cup").position
        estimate = ObjectEstimate(x, y, z, None, cup.size, cup.colour, "Kinect01", world.time, 0)
        plan = GraspPlan(cup.iri, ObjectModel.of(cup))
        context = environment.context
        approach(context, {"graspPose": to_json(plan), "objectPosition": to_json(estimate)}, DEVICE)
        pick_up(context, {}, DEVICE)
        assert world.arm(context.arm).held == world.body("Cup")
        yield world, environment


def _rests_on_the_table(world: HomeWorld) -> tuple[float, float]:
    table = world.map.things[WORLD + "KitchenTable"].box
    x, y, z = world.pose("Cup").position
    assert table.min_x < x < table.max_x and table.min_y < y < table.max_y
    assert z - world.objects["Cup"].size[2] / 2 == pytest.approx(table.max_z, abs=0.01)
    return x, y


def test_the_cup_is_carried_to_the_spot_of_the_table_nearest_its_centre_an_arm_reaches() -> None:
    """The table's centre (7.75, 3.75) is 1.2 m from both mounts: the carry used to aim at it and fail
    after the pick-up ("no arm reaches KitchenTable")."""
    with holding_the_cup() as (world, environment):
        table = world.map.things[WORLD + "KitchenTable"]
        start = world.pose("Cup").position
        context = environment.context
        carry(context, {"targetPlace": designator(table.iri, HOME + "Furniture")}, DEVICE)
        put_down(context, {}, DEVICE)
        x, y = _rests_on_the_table(world)
        spec = world.arm_specs[context.arm]
        assert math.hypot(x - spec.mount[0], y - spec.mount[1]) <= spec.reach - RELAY_MARGIN + 0.02
        centre = ((table.box.min_x + table.box.max_x) / 2, (table.box.min_y + table.box.max_y) / 2)
        assert math.dist((x, y), centre) < math.dist(start[:2], centre) - 0.05  # moved towards the centre
        dispenser = world.map.things[WORLD + "WaterDispenser01"].box
        assert not (dispenser.min_x - 0.03 < x < dispenser.max_x + 0.03 and dispenser.min_y - 0.03 < y)
        # (Cup, isLocatedOn, KitchenTable): on the table's top, for the robots and for the referee
        on_table = ("on", Grounded("object", "Cup"), Grounded("thing", table.iri), context.arm)
        assert environment.referee.decide(*on_table)
        environment.belief.look(["Cup"], people=False)
        assert environment.belief.decide(*on_table)


def test_the_spot_keeps_clear_of_an_object_where_the_nearest_spot_was() -> None:
    with open_world(seed=0) as world:
        smap = world.map
        table = smap.things[WORLD + "KitchenTable"]
        cup = world.objects["Cup"]
        mounts = [(spec.mount[0], spec.mount[1], spec.reach) for spec in world.arm_specs.values()]
        _, free = place_spots(smap, table, cup.size, mounts, [])
        x, y = free[0]
        pen = world.objects["Pen"]
        pen_radius = math.hypot(pen.size[0], pen.size[1]) / 2
        _, spots = place_spots(smap, table, cup.size, mounts, [(x, y, pen_radius)])
        assert spots and spots[0] != (x, y)
        cup_radius = math.hypot(cup.size[0], cup.size[1]) / 2
        assert math.dist(spots[0], (x, y)) >= cup_radius + pen_radius + RELAY_CLEARANCE
        assert math.dist(spots[0], (7.75, 3.75)) >= math.dist((x, y), (7.75, 3.75))  # the next nearest


def test_a_place_whose_centre_an_arm_reaches_is_aimed_at_its_centre() -> None:
    """Where the centre will do (the place below the tap, the pen rest), the spot is the centre, as before."""
    kb = KnowledgeBase.open(":memory:")
    kb.load([MORE / "pen_rest_west.ttl"], graph="map")
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        smap = world.map
        mounts = [(spec.mount[0], spec.mount[1], spec.reach) for spec in world.arm_specs.values()]
        for place, thing in (("BelowOfTap", "Cup"), ("PenRest1", "Pen")):
            region = smap.things[WORLD + place]
            surface, spots = place_spots(smap, region, world.objects[thing].size, mounts, [])
            assert spots[0] == pytest.approx(surface.center[:2])
            assert surface.zmin == pytest.approx(0.75)


def test_a_place_in_reach_only_within_the_margin_is_refused_before_anything_moves(tmp_path: Path) -> None:
    """By the map the left arm reaches a corner of the pen rest, so the check used to let the run go on,
    and the carry then failed with the pen in hand."""
    path = tmp_path / "pen_rest_at_the_edge.ttl"
    path.write_text(PEN_REST_AT_THE_EDGE, encoding="utf-8")
    kb = KnowledgeBase.open(":memory:")
    kb.load([path], graph="ontology")
    kb.load([path], graph="map")
    kb.load([MORE / "put_pen_on_pen_rest.ttl"], graph="requirements")
    before = set(kb.store.quads())
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        pen = world.pose("Pen").position
        start = world.base_pose()
        with pytest.raises(OutOfReachError) as refused:
            run_task(kb, "PutPenOnPenRest", SimEnvironment(world, kb), composer=Composer(kb))
        assert world.pose("Pen").position == pytest.approx(pen, abs=1e-3)
        assert world.base_pose().distance_to(start.x, start.y) < 0.01
    assert refused.value.thing == WORLD + "PenRestAtTheEdge"
    assert any(distance <= reach for *_, reach, distance in refused.value.arms)  # part of it is in reach
    assert "no spot of it" in refused.value.why and "Pen's centre 5 mm inside the place" in refused.value.why
    assert set(kb.store.quads()) == before
