"""Room on a place judged by the arms that will be free to set each thing down (sim/packing.py: arms_free,
carry_spots, overfilled; docs/execution.md, "Room on a top: which arms count"). A task takes the cup and keeps
it while it puts the eraser and the pen on a mat at the table's front, which the left arm reaches whole and
the right arm only along its east part: the left arm, the nearer the cup (the one the run asks first), is busy
from the cup's take on. Before, the check before the run counted every arm of the robot, and the eraser's spot was
chosen leaving the pen room by arms free at the eraser's carry, the left among them. Asked of the map and
the plan alone: no world is built (a stand-in gives the map's arms and objects, both arms empty before the
run), and every spot in reach counts as one an arm can hold the thing over."""

from __future__ import annotations

import math
from dataclasses import replace
from types import SimpleNamespace
from typing import Any, cast

import pytest

from cbrs.actions.composer import Composer
from cbrs.actions.plan import Plan
from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.semantic_map import SemanticMap
from cbrs.sim import packing
from cbrs.sim.arms import ArmSide
from cbrs.sim.context import SimContext
from cbrs.sim.packing import (
    SET_DOWN_SLACK,
    PackingRule,
    PlaceOverfilledError,
    arms_free,
    carry_spots,
    overfilled,
    puts_down,
    radius_of,
)
from cbrs.sim.place_spots import RELAY_CLEARANCE, distance_to_extent, place_spots, reach_of
from cbrs.sim.run_checks import OutOfReachError, PlanChecks
from tests.helpers_examples import EXAMPLES

WORLD, LAB6 = PREFIXES["world"], "https://example.org/lab6#"
MAT, PEN, ERASER, CUP = LAB6 + "Mat1", WORLD + "Pen", LAB6 + "Eraser1", WORLD + "Cup"
LEFT, RIGHT = WORLD + "CytonDualArm01LeftArm", WORLD + "CytonDualArm01RightArm"
VALUES: dict[str, Any] = {"pen": {"@id": PEN}, "eraser": {"@id": ERASER}, "cup": {"@id": CUP}, "mat": {"@id": MAT}}
CIRCLE = PackingRule(footprint="circle")
Mats = tuple[SemanticMap, SemanticMap, Plan, Plan, Plan]

# A mat at the front of the kitchen table, 40 x 23 cm, and the cup moved to the table's front edge, where the
# Kinect sees it (the same task runs in the simulation and in the example sweep: docs/execution.md).
MAT_MAP = (EXAMPLES / "lab6_front_mat.ttl").read_text(encoding="utf-8")
CUP_WEST = (EXAMPLES / "lab6_cup_to_the_front.ru").read_text(encoding="utf-8")
# The mat 30 x 20 cm, 5 cm farther west (x 7.30-7.60, y 3.20-3.40): the right arm's part of it holds the
# eraser or the pen, not both, by circles or by boxes; the left arm's part holds both.
MAT_WEST = """
PREFIX home: <https://w3id.org/cbrs/home#>
PREFIX lab6: <https://example.org/lab6#>
DELETE { GRAPH <https://w3id.org/cbrs/graph/map> {
    lab6:Mat1 home:minX ?a ; home:maxX ?b ; home:minY ?c ; home:maxY ?d } }
INSERT { GRAPH <https://w3id.org/cbrs/graph/map> {
    lab6:Mat1 home:minX 7.30 ; home:maxX 7.60 ; home:minY 3.20 ; home:maxY 3.40 } }
WHERE { GRAPH <https://w3id.org/cbrs/graph/map> {
    lab6:Mat1 home:minX ?a ; home:maxX ?b ; home:minY ?c ; home:maxY ?d } }
"""


# EraserCupPen (the cup taken between the eraser's carry and the pen's), CupEraserPen (the cup first) and
# EraserThenPen (no cup): parts in order, each one thing (docs/tasks.md, "Several things in one task").
TASKS = (EXAMPLES / "lab6_eraser_cup_pen.ttl").read_text(encoding="utf-8")


@pytest.fixture(scope="module")
def mat(tmp_path_factory: pytest.TempPathFactory) -> Mats:
    """The map with the mat at the table's front, the map with it 5 cm farther west, and the plans of
    EraserCupPen (the cup taken between the eraser's carry and the pen's), CupEraserPen (first) and
    EraserThenPen (no cup)."""
    directory = tmp_path_factory.mktemp("mat")
    (directory / "mat.ttl").write_text(MAT_MAP, encoding="utf-8")
    (directory / "tasks.ttl").write_text(TASKS, encoding="utf-8")
    kb = KnowledgeBase.open(":memory:")
    for graph in ("ontology", "map"):
        kb.load([EXAMPLES / "lab6_tidy_shelf.ttl", directory / "mat.ttl"], graph=graph)
    kb.load([directory / "tasks.ttl"], graph="requirements")
    kb.update(CUP_WEST)
    composer = Composer(kb)
    between, first = composer.compose("EraserCupPen").plan, composer.compose("CupEraserPen").plan
    plain = composer.compose("EraserThenPen").plan
    assert between is not None and first is not None and plain is not None
    front = SemanticMap.read(kb)
    kb.update(MAT_WEST)
    return front, SemanticMap.read(kb), between, first, plain


def _where(smap: SemanticMap) -> dict[str, tuple[float, float, float]]:
    return {iri: (o.start.x, o.start.y, radius_of(o.size)) for iri, o in smap.objects.items()}


def test_the_plan_keeps_the_cup_in_the_left_hand_through_the_pens_carry(
    mat: Mats,
) -> None:
    smap, _, between, first, _ = mat
    downs = puts_down(between, smap, VALUES)
    assert [(down.place, down.obj) for down in downs] == [(MAT, ERASER), (MAT, PEN)]
    free = arms_free(between, smap, VALUES, _where(smap))
    assert [[arm.iri for arm in free[down.step].free] for down in downs] == [[LEFT, RIGHT], [RIGHT]]
    assert [free[down.step].busy for down in downs] == [{}, {LEFT: CUP}]
    free = arms_free(first, smap, VALUES, _where(smap))  # the cup taken first: busy at both carries
    assert [[arm.iri for arm in at.free] for at in free.values()] == [[RIGHT], [RIGHT]]
    # what an arm holds before the run and the plan never sets down keeps it busy too
    held = arms_free(between, smap, VALUES, _where(smap), {LEFT: LAB6 + "Keys"})
    assert [[arm.iri for arm in held[down.step].free] for down in downs] == [[RIGHT], []]
    assert held[downs[1].step].busy == {LEFT: LAB6 + "Keys", RIGHT: CUP}  # the right arm takes the cup then


def test_the_check_before_the_run_counts_only_the_arms_free_at_each_carry(
    mat: Mats,
) -> None:
    """On the mat 30 x 20 cm 5 cm farther west the right arm's part holds the eraser or the pen, not both. With the
    cup kept from the start, the left arm is busy at both carries: refused (before, every arm of the robot
    counted, and the left arm's part held both). With the cup taken between the carries, the eraser goes
    where the left arm reaches, and the pen fits the right arm's part beside it: not refused."""
    _, west, between, first, _ = mat
    where = _where(west)
    refused = overfilled(west, first, VALUES, where, CIRCLE)
    assert isinstance(refused, PlaceOverfilledError) and refused.place == MAT
    assert sorted(iri for iri, _ in refused.objects) == sorted([ERASER, PEN])
    assert refused.busy == (("left", CUP),)
    assert (
        "of its 30 x 20 cm top (0.060 m2) the arms free to set them down reach (when the left arm holds the Cup)"
        in str(refused)
    )
    assert overfilled(west, first, VALUES, where) is not None  # nor by boxes
    assert overfilled(west, between, VALUES, where, CIRCLE) is None


def _context(smap: SemanticMap, plan: Plan, step_index: int) -> SimContext:
    """A context over a stand-in world of the map's arms and objects, both arms empty, running the step."""
    world = SimpleNamespace(
        map=smap,
        objects={obj.name: obj for obj in smap.objects.values()},
        arm_specs={ArmSide(arm.side): arm for arm in smap.arms.values()},
        arm=lambda side: SimpleNamespace(held=None),
    )
    step = next(s for s in plan.steps if s.index == step_index)
    return SimContext(
        cast(Any, world), cast(Any, None), plan=plan, given=VALUES, component=step.candidates[0], step=step
    )


def test_the_erasers_spot_leaves_the_pen_room_where_the_arm_free_at_its_carry_reaches(
    mat: Mats, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The eraser, carried by the right arm (the only one that reaches it), first: the left arm is free
    then, and it reaches the whole pen over the mat, so by circles the right arm's spots for the pen were
    none where the left arm has one (place_spots), no eraser spot was found leaving room, and the eraser
    went to the first, nearest the centre, where the pen has no spot left by the right arm, the one free at
    its carry. Now the pen's room is judged by the right arm alone. By the default rule the carry went to
    boxes, circles not seeming to hold the two; now circles hold them and are packed by, the safer
    (docs/simulation.md, "Circles first")."""
    smap, _, between, _, _ = mat
    monkeypatch.setattr(packing, "cannot_set_down", lambda *_: "")  # every arm holds every spot
    eraser_carry = puts_down(between, smap, VALUES)[0].step
    step = next(s for s in between.steps if s.index == eraser_carry)
    ctx = _context(smap, between, eraser_carry)
    place = smap.things[MAT]
    _, spots = carry_spots(ctx, place, "Eraser1", ArmSide.RIGHT, step, CIRCLE)
    assert carry_spots(ctx, place, "Eraser1", ArmSide.RIGHT, step)[1] == spots
    right = reach_of(smap.arms[RIGHT])
    eraser, pen = smap.objects[ERASER].size, smap.objects[PEN].size
    around = [(o.start.x, o.start.y, radius_of(o.size)) for iri, o in smap.objects.items() if iri not in (ERASER, PEN)]
    lying = (*spots[0], radius_of(eraser) + SET_DOWN_SLACK)
    assert place_spots(smap, place, pen, [right], [*around, lying], [right])[1]
    centre_first = place_spots(smap, place, eraser, [right], around, [right])[1][0]
    assert spots[0] != centre_first
    gone = (*centre_first, radius_of(eraser))
    assert place_spots(smap, place, pen, [right], [*around, gone], [right])[1] == []  # where it went before


def test_where_the_carrying_arm_leaves_no_room_the_arms_free_then_are_asked(
    mat: Mats, monkeypatch: pytest.MonkeyPatch
) -> None:
    """EraserThenPen on the west mat, nothing kept: the right arm's part holds the eraser or the pen, not
    both, so no spot of the eraser's leaves the pen room within the right arm's reach, and the eraser went to
    its spot nearest the centre as for one thing alone, though the check before the run, counting both
    arms, let the task run. The pen may go to the left arm, free at its carry: the eraser's first spot now
    leaves the pen a spot the left arm reaches, which the spot nearest the centre does not."""
    _, west, _, _, plain = mat
    monkeypatch.setattr(packing, "cannot_set_down", lambda *_: "")
    eraser_carry = puts_down(plain, west, VALUES)[0].step
    step = next(s for s in plain.steps if s.index == eraser_carry)
    ctx = _context(west, plain, eraser_carry)
    place = west.things[MAT]
    both = [reach_of(arm) for arm in west.arms.values()]
    right = reach_of(west.arms[RIGHT])
    eraser, pen = west.objects[ERASER].size, west.objects[PEN].size
    around = [(o.start.x, o.start.y, radius_of(o.size)) for iri, o in west.objects.items() if iri not in (ERASER, PEN)]
    assert overfilled(west, plain, VALUES, _where(west)) is None
    _, spots = carry_spots(ctx, place, "Eraser1", ArmSide.RIGHT, step, CIRCLE)
    alone = place_spots(west, place, eraser, [right], around, both)[1]
    assert sorted(spots) == sorted(alone) and spots[0] != alone[0]
    apart = radius_of(pen) + radius_of(eraser) + RELAY_CLEARANCE  # no spot leaves room 2 cm off
    for at, room in ((spots[0], True), (alone[0], False)):
        for arms, left in ((both, room), ([right], False)):  # the pen's own spots, clear of the eraser
            pens = place_spots(west, place, pen, arms, around, arms)[1]
            assert any(math.dist(at, spot) >= apart for spot in pens) is left


def test_the_check_of_a_carrys_place_counts_only_the_arms_free_then(mat: Mats) -> None:
    """The check of each step (``run_checks.PlanChecks._check_spot``) counts the arms free at a carry too: the
    mat moved 30 cm west, which the left arm reaches and the right does not, has a spot for the pen, but
    not at CupEraserPen's carry of it, the left arm holding the cup then (before, every arm of the robot
    counted and the run went on to a carry the right arm cannot make). The mat where it is passes: the
    right arm reaches its east part."""
    smap, _, _, first, _ = mat
    mat_there = smap.things[MAT]
    box = replace(mat_there.box, min_x=mat_there.box.min_x - 0.30, max_x=mat_there.box.max_x - 0.30)
    west = replace(smap, things={**smap.things, MAT: replace(mat_there, box=box)})
    world = SimpleNamespace(map=west, objects={obj.name: obj for obj in west.objects.values()})
    belief = SimpleNamespace(position=lambda name: None)  # where the map puts each thing
    free = arms_free(first, west, VALUES, _where(west))
    pen_carry = puts_down(first, west, VALUES)[1].step
    step = next(s for s in first.steps if s.index == pen_carry)
    assert [arm.iri for arm in free[pen_carry].free] == [RIGHT]
    for place_map, refused in ((west, True), (smap, False)):
        world.map = place_map
        checks = PlanChecks(cast(Any, world), cast(Any, None), cast(Any, belief), cast(Any, None), lambda a, b: a == b)
        thing = place_map.things[MAT]
        report = [
            (
                arm.iri,
                arm.mount[0],
                arm.mount[1],
                arm.reach,
                distance_to_extent((thing.box.min_x, thing.box.max_x, thing.box.min_y, thing.box.max_y), arm.mount),
            )
            for arm in place_map.arms.values()
        ]
        checks._check_spot(step, MAT, [PEN], report)  # every arm counted: a spot
        if not refused:
            checks._check_spot(step, MAT, [PEN], report, free[pen_carry])
            continue
        with pytest.raises(OutOfReachError) as caught:
            checks._check_spot(step, MAT, [PEN], report, free[pen_carry])
        assert (
            "the arms that reach a spot of it for the Pen hold other things then (the left arm holds the Cup)"
            in str(caught.value)
        )


def test_the_carrying_arm_sets_down_only_where_it_can_and_else_passes_to_a_free_arm_that_can(
    mat: Mats, monkeypatch: pytest.MonkeyPatch
) -> None:
    """EraserCupPen on the front mat: the eraser's spots that leave the pen room in the right arm's part lie at
    the edge of its reach, where in the simulation it could not hold the eraser over them, and the carry took
    the first spot it could, which left the pen none (the run failed at the pen's carry). A spot is taken as
    leaving room only where the carrying arm can let the thing go over it; the right arm has none here, the
    left is free, and its spots leave the pen room: the right arm is given no spot, so the carry passes the
    eraser to the left. The arms here can hold every spot but the right arm the eraser's east of x 7.68."""
    smap, _, between, _, _ = mat

    def refusing(ctx: Any, obj: Any, surface: Any, at: tuple[float, float], sides: Any = None) -> str:
        return "too far" if obj.iri == ERASER and sides == {ArmSide.RIGHT} and at[0] > 7.68 else ""

    monkeypatch.setattr(packing, "cannot_set_down", refusing)
    eraser_carry = puts_down(between, smap, VALUES)[0].step
    step = next(s for s in between.steps if s.index == eraser_carry)
    ctx = _context(smap, between, eraser_carry)
    place = smap.things[MAT]
    assert carry_spots(ctx, place, "Eraser1", ArmSide.RIGHT, step, CIRCLE)[1] == []
    _, lefts = carry_spots(ctx, place, "Eraser1", ArmSide.LEFT, step, CIRCLE)
    right = reach_of(smap.arms[RIGHT])
    pen, eraser = smap.objects[PEN].size, smap.objects[ERASER].size
    around = [(o.start.x, o.start.y, radius_of(o.size)) for iri, o in smap.objects.items() if iri not in (ERASER, PEN)]
    lying = (*lefts[0], radius_of(eraser) + SET_DOWN_SLACK)
    assert place_spots(smap, place, pen, [right], [*around, lying], [right])[1]  # the pen fits the right arm's part
    monkeypatch.setattr(packing, "cannot_set_down", lambda *_: "")  # the right arm holds them all: its own spots
    assert carry_spots(ctx, place, "Eraser1", ArmSide.RIGHT, step, CIRCLE)[1][0][0] > 7.68
