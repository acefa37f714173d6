"""A take whose moves to the pre-grasp and grasp poses would touch a fixture the arms' planning does not avoid
(a tap's lever, which a hand pushes to fill a cup) is refused by its dry run (skills.plan_carry, MEET_MARGIN),
and so by the choice of arm and approach and the check before a run (docs/tasks.md, eleventh round, "Known
failure: a top grasp beside the tap's lever"). The flask of lab11_two_flasks.ttl moved to (7.74, 3.22): the
right hand met the lever and stopped 4.2 cm short, after the loading check's dry run had passed it. The
flask is round: its top grasp turned a quarter round (arm_choice.turned) touches nothing, and is chosen; a
thing with no such way is refused naming the lever. Nothing moves here: the dry runs plan on the kinematics
copies."""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import replace

import pytest

from cbrs.kb import KnowledgeBase
from cbrs.kb.semantic_map import SemanticMap
from cbrs.sim import skills
from cbrs.sim.arm_choice import TURN, lying_estimate, who_loads
from cbrs.sim.arms import ArmSide
from cbrs.sim.context import SimContext, SkillFailed
from cbrs.sim.errors import MovesRefusedError
from cbrs.sim.grounding import docking_pose
from cbrs.sim.perception import ObjectEstimate
from cbrs.sim.values import Manipulation
from cbrs.sim.world import HomeWorld, open_world
from tests.helpers_examples import EXAMPLES

BY_THE_LEVER = (7.74, 3.22)
"""Where the known failure's update put the flask (lab11_full_flask_moved.ru, its x and y changed)."""
CLEAR = (7.55, 3.10)
"""Where the update as written puts it: the take meets nothing there, and the runs bring it."""


@pytest.fixture(scope="module")
def flask() -> Iterator[tuple[SimContext, ObjectEstimate]]:
    kb = KnowledgeBase.open(":memory:")
    for name in ("lab11_two_flasks.ttl", "lab11_full_flask.ttl"):
        kb.load([EXAMPLES / name], graph="ontology")
        kb.load([EXAMPLES / name], graph="map")
    update = (EXAMPLES / "lab11_full_flask_moved.ru").read_text(encoding="utf-8")
    moved = update.replace("home:x 7.55 ; home:y 3.10", f"home:x {BY_THE_LEVER[0]} ; home:y {BY_THE_LEVER[1]}")
    assert moved != update
    kb.update(moved)
    smap = SemanticMap.read(kb)
    with open_world(seed=0, semantic_map=smap) as world:
        (obj,) = [o for o in smap.objects.values() if o.name == "Flask1"]
        yield SimContext(world, kb), lying_estimate(world, None, obj)


def _at(seen: ObjectEstimate, x: float, y: float) -> ObjectEstimate:
    return replace(seen, x=x, y=y)


def _model(world: HomeWorld) -> Manipulation:
    (obj,) = [o for o in world.map.objects.values() if o.name == "Flask1"]
    return Manipulation.of(obj)


@pytest.mark.parametrize("side", list(ArmSide))
def test_a_take_whose_fingers_touch_the_lever_is_refused_by_its_dry_run(
    flask: tuple[SimContext, ObjectEstimate], side: ArmSide
) -> None:
    ctx, seen = flask
    lever = ctx.world.dispensers[0].lever.name
    model = _model(ctx.world).model
    assert seen.position[:2] == pytest.approx(BY_THE_LEVER)
    refused = skills.plan_carry(ctx.world, seen, side, model).refused
    assert f"the {side.value} arm would not get the Flask1 by its top grasp past" in refused
    assert f"fingers included, would touch the {lever}" in refused
    # where the take meets no fixture, its dry run passes as before
    assert skills.plan_carry(ctx.world, _at(seen, *CLEAR), side, model).refused == ""


def test_the_loading_choice_turns_the_round_flasks_top_grasp_clear_of_the_lever(
    flask: tuple[SimContext, ObjectEstimate],
) -> None:
    """The choice the hand-over and the check before the run make (who_loads, the base at the table's docking
    pose): the flask is round, so its top grasp may close the other way, along the lever, and that take
    touches nothing: it is chosen, the turn carried in the choice's model to the moves. Where it meets no
    fixture, the flask is taken as before (no turn)."""
    ctx, seen = flask
    (obj,) = [o for o in ctx.world.map.objects.values() if o.name == "Flask1"]
    model, dock = _model(ctx.world).model, docking_pose(ctx.world.map.things[obj.support or ""])
    loading = who_loads(ctx, seen, model, dock)
    assert loading.giver is None and loading.loader.model.turn == pytest.approx(TURN)
    assert skills.plan_carry(ctx.world, seen, loading.loader.arm, loading.loader.model).refused == ""
    assert who_loads(ctx, _at(seen, *CLEAR), model, dock).loader.model.turn == 0.0


def test_with_no_way_clear_of_the_lever_the_refusal_names_it(flask: tuple[SimContext, ObjectEstimate]) -> None:
    """A box of the flask's size (a footprint: its top grasp closes across it one way, not turned) has no take
    clear of the lever, by either arm alone or passed: the refusal, before anything moves, says the lever."""
    ctx, seen = flask
    lever = ctx.world.dispensers[0].lever.name
    (obj,) = [o for o in ctx.world.map.objects.values() if o.name == "Flask1"]
    box = replace(_model(ctx.world).model, footprint=(seen.size[0], seen.size[1]))
    dock = docking_pose(ctx.world.map.things[obj.support or ""])
    with pytest.raises((SkillFailed, MovesRefusedError)) as refused:
        who_loads(ctx, seen, box, dock)
    message = str(refused.value)
    assert "the right arm would not get the Flask1" in message and "the left arm would not get the Flask1" in message
    assert message.count(f"would touch the {lever}") == 2
