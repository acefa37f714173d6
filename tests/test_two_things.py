"""Two or more things the plan puts on one place (sim/packing.py; docs/simulation.md, "Several things onto
one place"): the sixth round's TidyPenAndEraser put the eraser first at the middle of a 40 x 40 cm shelf and
then found no spot for the pen. The placement and the refusal are asked of the map and the plan alone; one
run in the simulation shows the trial succeeding."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import pytest

from cbrs.actions.composer import Composer
from cbrs.actions.plan import Plan
from cbrs.actions.runner import run_task
from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.semantic_map import SemanticMap, Thing
from cbrs.sim.components import SimEnvironment
from cbrs.sim.packing import (
    SET_DOWN_SLACK,
    PackingRule,
    PlaceOverfilledError,
    Undecided,
    arrange,
    later_sizes,
    overfilled,
    pack,
    puts_down,
    radius_of,
    set_down_spots,
)
from cbrs.sim.place_spots import RELAY_CLEARANCE, place_spots
from cbrs.sim.world import open_world
from tests.helpers_examples import EXAMPLES

WORLD, LAB6 = PREFIXES["world"], "https://example.org/lab6#"
SHELF, PEN, ERASER, CUP = LAB6 + "TidyShelf1", WORLD + "Pen", LAB6 + "Eraser1", WORLD + "Cup"
VALUES: dict[str, Any] = {"pen": {"@id": PEN}, "eraser": {"@id": ERASER}, "shelf": {"@id": SHELF}, "cup": {"@id": CUP}}
"""The task's inputs as the run grounds them in the lab's map (the one pen, eraser, cup and tidy shelf)."""
CIRCLE = PackingRule(footprint="circle")
"""The packing's first footprints, the circles about the things' diagonals (the boxes: test_packing_footprints)."""


def _three(directory: Path) -> Path:
    """TidyPenAndEraser with the bundled cup as a third thing for the shelf (TidyThree)."""
    text = (
        (EXAMPLES / "lab6_tidy_pen_and_eraser.ttl").read_text(encoding="utf-8").replace("TidyPenAndEraser", "TidyThree")
    )
    three = text.replace(
        "cbrs:parameterType lab6:TidyShelf ] ;",
        'cbrs:parameterType lab6:TidyShelf ] ;\n        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "cup" ;'
        " cbrs:parameterType home:Cup ] ;\n        cbrs:hasEffect [ a cbrs:Effect ; cbrs:conditionSubject home:Cup ;"
        " cbrs:conditionPredicate home:isLocatedOn ; cbrs:conditionObject lab6:TidyShelf ] ;",
    )
    assert three != text
    path = directory / "lab6_tidy_three.ttl"
    path.write_text(three, encoding="utf-8")
    return path


@pytest.fixture(scope="module")
def tidy(tmp_path_factory: pytest.TempPathFactory) -> tuple[KnowledgeBase, SemanticMap, Plan, Plan]:
    """The trial's store (the shelf into the ontology and the map, the task into the requirements), its
    map, and the plans of TidyPenAndEraser and of TidyThree."""
    kb = KnowledgeBase.open(":memory:")
    for graph in ("ontology", "map"):
        kb.load([EXAMPLES / "lab6_tidy_shelf.ttl"], graph=graph)
    kb.load([EXAMPLES / "lab6_tidy_pen_and_eraser.ttl", _three(tmp_path_factory.mktemp("three"))], graph="requirements")
    composer = Composer(kb)
    two, three = composer.compose("TidyPenAndEraser").plan, composer.compose("TidyThree").plan
    assert two is not None and three is not None
    return kb, SemanticMap.read(kb), two, three


def _mounts(smap: SemanticMap) -> list[tuple[float, float, float]]:
    return [(arm.mount[0], arm.mount[1], arm.reach) for arm in smap.arms.values()]


def _shelf(smap: SemanticMap) -> Thing:
    return smap.things[SHELF]


def test_the_plan_puts_the_eraser_then_the_pen_on_the_shelf_and_the_first_carry_knows_the_pen_comes(
    tidy: tuple[KnowledgeBase, SemanticMap, Plan, Plan],
) -> None:
    _, smap, plan, _ = tidy
    downs = puts_down(plan, smap, VALUES)
    assert [(down.place, down.obj) for down in downs] == [(SHELF, ERASER), (SHELF, PEN)]
    steps = {step.index: step for step in plan.steps}
    first, second = (steps[down.step] for down in downs)
    assert later_sizes(plan, first, smap, SHELF, VALUES) == [smap.objects[PEN].size]
    assert later_sizes(plan, second, smap, SHELF, VALUES) == []
    assert later_sizes(plan, first, smap, WORLD + "KitchenTable", VALUES) == []  # another place: nothing kept


def test_the_eraser_at_the_centre_left_no_spot_for_the_pen_and_its_packed_spot_leaves_one(
    tidy: tuple[KnowledgeBase, SemanticMap, Plan, Plan],
) -> None:
    _, smap, _, _ = tidy
    shelf, mounts = _shelf(smap), _mounts(smap)
    eraser, pen = smap.objects[ERASER].size, smap.objects[PEN].size
    _, alone = place_spots(smap, shelf, eraser, mounts, [])
    _, pen_after_centre = place_spots(smap, shelf, pen, mounts, [(*alone[0], radius_of(eraser))])
    assert pen_after_centre == []  # the trial's failure: nearest the centre first
    _, packed = set_down_spots(smap, shelf, eraser, mounts, [], [pen], CIRCLE)
    assert sorted(packed) == sorted(alone)  # the same spots, another order
    # the first spot, nearest the centre, where the pen still has one if the eraser comes to rest 2 cm off
    grown = radius_of(eraser) + SET_DOWN_SLACK
    assert place_spots(smap, shelf, pen, mounts, [(*packed[0], grown)])[1]
    for x, y in alone[: alone.index(packed[0])]:
        assert not place_spots(smap, shelf, pen, mounts, [(x, y, grown)])[1]
    # nothing after it: as one thing alone is set down
    assert set_down_spots(smap, shelf, pen, mounts, [], [], CIRCLE) == place_spots(smap, shelf, pen, mounts, [])


def test_the_search_goes_back_where_the_first_choice_leaves_no_room(
    tidy: tuple[KnowledgeBase, SemanticMap, Plan, Plan],
) -> None:
    """The pen toward the rim first leaves room for the cup and the eraser; at the centre (its first spot
    toward it) it does not, and the search moves the pen rather than giving up."""
    _, smap, _, _ = tidy
    shelf, mounts = _shelf(smap), _mounts(smap)
    sizes = [smap.objects[PEN].size, smap.objects[CUP].size, smap.objects[ERASER].size]
    for rule in (CIRCLE, PackingRule("plan", "centre", "circle")):
        spots = arrange(smap, shelf, sizes, mounts, [], rule)
        assert spots is not None
        radii = [radius_of(size) for size in sizes]
        for a in range(3):
            assert spots[a] in place_spots(smap, shelf, sizes[a], mounts, [])[1]
            for b in range(a):
                assert math.dist(spots[a], spots[b]) >= radii[a] + radii[b] + RELAY_CLEARANCE - 1e-9
        if rule.toward == "centre":
            assert spots[0] != place_spots(smap, shelf, sizes[0], mounts, [])[1][0]
    with pytest.raises(Undecided):  # the search bounded: undecided is no refusal
        arrange(smap, shelf, sizes, mounts, [], CIRCLE, budget=1)
    assert pack(smap, shelf, sizes, mounts, [], PackingRule()) is not None
    with pytest.raises(ValueError, match="'middle'"):
        PackingRule("largest", "middle")


def test_three_things_and_a_pill_box_on_the_small_shelf_are_refused_before_the_run(
    tidy: tuple[KnowledgeBase, SemanticMap, Plan, Plan],
) -> None:
    _, smap, _, plan = tidy
    where = {
        iri: (obj.start.x, obj.start.y, radius_of(obj.size))
        for iri, obj in smap.objects.items()
        if iri not in (PEN, ERASER, CUP)
    }
    assert overfilled(smap, plan, VALUES, where, CIRCLE) is None  # the three fit on the shelf as it is
    box = LAB6 + "PillBox1"
    refused = overfilled(smap, plan, VALUES, {**where, box: (8.63, 2.68, radius_of((0.04, 0.04, 0.04)))}, CIRCLE)
    assert isinstance(refused, PlaceOverfilledError) and refused.http_status == 422
    assert refused.place == SHELF
    assert sorted(iri for iri, _ in refused.objects) == sorted([PEN, ERASER, CUP])
    assert [iri for iri, *_ in refused.already] == [box]
    assert refused.top == pytest.approx((0.40, 0.40))
    assert 0.0 < refused.free < refused.reached < 0.16
    message = str(refused)
    for said in ("TidyShelf1", "Pen (14.0 x 1.6 cm, 14.1 cm across)", "Eraser1", "Cup", "PillBox1 at (8.63, 2.68)"):
        assert said in message
    assert f"{refused.free:.3f} m2 free" in message


def test_tidy_pen_and_eraser_puts_both_on_the_40_cm_shelf(tidy: tuple[KnowledgeBase, SemanticMap, Plan, Plan]) -> None:
    kb, smap, _, _ = tidy
    with open_world(seed=0, semantic_map=smap) as world:
        result = run_task(kb, "TidyPenAndEraser", SimEnvironment(world, kb), composer=Composer(kb))
    assert result.succeeded, result.report.reason if result.report else result.composition.unsatisfied
    assert len(result.goals) == 2 and all(goal.believed and goal.holds for goal in result.goals)
