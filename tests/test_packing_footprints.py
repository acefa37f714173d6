"""The packing's footprints and the arms' say over its spots (sim/packing.py; docs/simulation.md,
"Footprints"): two 14 cm writing things fit side by side on a 34 x 20 cm shelf by their boxes, not by the
circles about their diagonals; a spot no arm can hold a later thing over is passed over, and a place with
no arrangement the arms can hold is refused naming the thing and why; the choice of approach aims where the
carry will. Asked of the map and the plan alone: no world is built (a stand-in gives the map's arms and
objects), and the arms' answer is a stand-in where it decides."""

from __future__ import annotations

import math
from types import SimpleNamespace
from typing import Any, cast

import pytest

from cbrs.actions.composer import Composer
from cbrs.actions.plan import Plan
from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.semantic_map import MapObject, SemanticMap, Thing
from cbrs.sim import packing
from cbrs.sim.arm_choice import TAKING, hold_end
from cbrs.sim.arms import ArmSide
from cbrs.sim.context import SimContext
from cbrs.sim.geometry import Region
from cbrs.sim.packing import (
    Footprint,
    PackingRule,
    PlaceOverfilledError,
    arrange,
    box_spots,
    carry_spots,
    footprint_of,
    gap,
    overfilled,
    radius_of,
)
from cbrs.sim.place_spots import RELAY_CLEARANCE, place_spots
from tests.helpers_examples import EXAMPLES

WORLD, LAB6P = PREFIXES["world"], "https://example.org/lab6p#"
SHELF, PEN, PENCIL = LAB6P + "NarrowShelf1", WORLD + "Pen", LAB6P + "Pencil1"
VALUES: dict[str, Any] = {"pen": {"@id": PEN}, "pencil": {"@id": PENCIL}, "shelf": {"@id": SHELF}}
CIRCLE, BOX = PackingRule(footprint="circle"), PackingRule(footprint="box")


@pytest.fixture(scope="module")
def narrow() -> tuple[SemanticMap, Plan]:
    """The map with the narrow shelf and the pencil (lab6p_narrow_shelf.ttl), and TidyPenAndPencil's plan."""
    kb = KnowledgeBase.open(":memory:")
    for graph in ("ontology", "map"):
        kb.load([EXAMPLES / "lab6p_narrow_shelf.ttl"], graph=graph)
    kb.load([EXAMPLES / "lab6p_tidy_pen_and_pencil.ttl"], graph="requirements")
    plan = Composer(kb).compose("TidyPenAndPencil").plan
    assert plan is not None
    return SemanticMap.read(kb), plan


def _mounts(smap: SemanticMap) -> list[tuple[float, float, float]]:
    return [(arm.mount[0], arm.mount[1], arm.reach) for arm in smap.arms.values()]


def _where(smap: SemanticMap) -> dict[str, tuple[float, float, float]]:
    """The objects the plan does not carry, where the map puts them (x, y, radius)."""
    return {
        iri: (o.start.x, o.start.y, radius_of(o.size)) for iri, o in smap.objects.items() if iri not in (PEN, PENCIL)
    }


def test_a_footprint_is_the_box_turned_as_the_thing_lies() -> None:
    across = Footprint.lying((0.016, 0.14, 0.016), 0.0)  # its long side along y
    assert across.axis == pytest.approx(math.pi / 2) and across.length == pytest.approx(0.14)
    assert across.half_extent() == pytest.approx((0.008, 0.07))
    pen = Footprint.lying((0.14, 0.016, 0.016), 0.0)
    beside = pen.corners(0.0, 0.074)  # side by side, 7.4 cm between the centres
    assert gap(pen.corners(0.0, 0.0), beside) == pytest.approx(0.074 - 0.016)
    assert gap(pen.corners(0.0, 0.0), across.corners(0.0, 0.0)) == 0.0  # crossed: they meet
    assert gap(pen.corners(0.0, 0.0), [(0.05, 0.0)]) == 0.0  # a point on it
    turned = Footprint(0.14, 0.016, math.pi / 4)
    assert gap(turned.corners(0.0, 0.0), [(0.07, -0.07)]) == pytest.approx(0.07 * math.sqrt(2) - 0.008)
    with pytest.raises(ValueError, match="'disc'"):
        PackingRule(footprint="disc")


def test_the_narrow_shelf_holds_the_pen_and_the_pencil_by_their_boxes_not_their_circles(
    narrow: tuple[SemanticMap, Plan],
) -> None:
    smap, plan = narrow
    shelf, mounts = smap.things[SHELF], _mounts(smap)
    refused = overfilled(smap, plan, VALUES, _where(smap), CIRCLE)
    assert isinstance(refused, PlaceOverfilledError) and refused.footprint == "circle"
    assert sorted(iri for iri, _ in refused.objects) == sorted([PEN, PENCIL])
    assert "circles about their diagonals" in str(refused)
    assert overfilled(smap, plan, VALUES, _where(smap)) is None
    things = [smap.objects[PEN], smap.objects[PENCIL]]
    feet = [footprint_of(thing) for thing in things]
    spots = arrange(smap, shelf, [t.size for t in things], mounts, [], BOX, feet=feet)
    assert spots is not None
    for thing, foot, at in zip(things, feet, spots, strict=True):
        assert at in box_spots(smap, shelf, foot, thing.size[2], mounts, [])[1]
    (ax, ay), (bx, by) = spots
    assert gap(feet[0].corners(ax, ay), feet[1].corners(bx, by)) >= RELAY_CLEARANCE - 1e-9
    assert math.hypot(ax - bx, ay - by) < feet[0].radius + feet[1].radius + RELAY_CLEARANCE  # closer than circles


def test_a_spot_no_arm_can_hold_is_passed_over_and_a_place_with_none_is_refused_saying_why(
    narrow: tuple[SemanticMap, Plan], monkeypatch: pytest.MonkeyPatch
) -> None:
    smap, plan = narrow
    shelf, mounts = smap.things[SHELF], _mounts(smap)
    things = [smap.objects[PEN], smap.objects[PENCIL]]
    feet = [footprint_of(thing) for thing in things]
    sizes = [t.size for t in things]
    free = arrange(smap, shelf, sizes, mounts, [], BOX, feet=feet)
    assert free is not None
    asked: list[tuple[int, tuple[float, float]]] = []

    def not_there(n: int, at: tuple[float, float]) -> bool:  # the pencil not where the free packing put it
        asked.append((n, at))
        return not (n == 1 and at == free[1])

    held = arrange(smap, shelf, sizes, mounts, [], BOX, feet=feet, holds=not_there)
    assert held is not None and held[1] != free[1] and (1, free[1]) in asked
    why = "the right arm cannot hold the Pencil1 by its top grasp over NarrowShelf1 at (8.55, 2.66)"

    def refusing(ctx: Any, obj: MapObject, surface: Region, at: tuple[float, float], sides: Any = None) -> str:
        return why if obj.iri == PENCIL else ""

    monkeypatch.setattr(packing, "cannot_set_down", refusing)
    refused = overfilled(smap, plan, VALUES, _where(smap), PackingRule(), cast(SimContext, object()))
    assert isinstance(refused, PlaceOverfilledError)
    assert [iri for iri, *_ in refused.unheld] == [PENCIL]
    _, no, asked_there, first = refused.unheld[0]
    assert no == asked_there > 0 and first == why
    assert f"the arms cannot hold the Pencil1 over {no} of the {asked_there} spots asked ({why})" in str(refused)


def _context(smap: SemanticMap, plan: Plan, step_index: int) -> SimContext:
    """A context over a stand-in world of the map's arms and objects, running the plan's step."""
    world = SimpleNamespace(
        map=smap,
        objects={obj.name: obj for obj in smap.objects.values()},
        arm_specs={ArmSide(arm.side): arm for arm in smap.arms.values()},
        arm=lambda side: SimpleNamespace(held=None),  # both arms free (place_spots.able_mounts)
    )
    step = next(s for s in plan.steps if s.index == step_index)
    return SimContext(
        cast(Any, world), cast(Any, None), plan=plan, given=VALUES, component=step.candidates[0], step=step
    )


def test_the_choice_of_approach_aims_where_the_carry_will(
    narrow: tuple[SemanticMap, Plan], monkeypatch: pytest.MonkeyPatch
) -> None:
    """The pen, carried first, is aimed at a spot that leaves the pencil room, not at the shelf's centre,
    which place_spots puts first and hold_end gave before."""
    smap, plan = narrow
    monkeypatch.setattr(packing, "cannot_set_down", lambda *_: "")  # every arm holds every spot
    downs = packing.puts_down(plan, smap, VALUES)
    assert [down.obj for down in downs] == [PEN, PENCIL]
    order = [step.index for step in plan.steps]
    carry = downs[0].step
    taking = [s.index for s in plan.steps if s.action in TAKING and order.index(s.index) < order.index(carry)]
    ctx = _context(smap, plan, taking[-1])
    shelf: Thing = smap.things[SHELF]
    end = hold_end(ctx, "Pen", ArmSide.RIGHT)
    assert end is not None
    place, _, spots = end
    assert place.iri == SHELF
    carry_step = next(s for s in plan.steps if s.index == carry)
    assert spots == carry_spots(ctx, shelf, "Pen", ArmSide.RIGHT, carry_step)[1]
    right = next(arm for arm in smap.arms.values() if arm.side == "right")
    centre = place_spots(smap, shelf, smap.objects[PEN].size, [(right.mount[0], right.mount[1], right.reach)], [])[1][0]
    assert spots[0] != centre
    assert carry_spots(ctx, shelf, "Pen", ArmSide.RIGHT, None)[1][0] == centre  # no step known: as one thing alone
    pencil = footprint_of(smap.objects[PENCIL])
    room = box_spots(smap, shelf, pencil, 0.012, _mounts(smap), [], [(*spots[0], footprint_of(smap.objects[PEN]))])
    assert room[1]
