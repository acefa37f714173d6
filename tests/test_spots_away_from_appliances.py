"""Spots asked farther from the appliances once a carry came near one (sim/relay.py: clear_asked,
appliance_distance; sim/arm_choice.py: holdable_spot, _clear_spot).

The ninth round's notebook, lying on a storage box on the kitchen table, set down on the table's top
(docs/examples/lab9_book_on_box.ttl, BookOntoTheTable): the top's spots in the arms' reach are ordered
nearest its centre, which is behind the dispenser, so the first ones lie together in front of it, and the
carry to each of the first 40 came within 1 cm of the tap's lever. The carry took the first of them "as
before", and at seed 2 it met the lever, stopped 17 cm short and was re-planned (18.1 s). Now, once a spot's
carry comes near, the spots asked next are those farther from the appliances than every such spot first."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from cbrs.kb import KnowledgeBase
from cbrs.kb.semantic_map import SemanticMap
from cbrs.sim import relay
from cbrs.sim.arm_choice import carry_check, holdable_spot, lying_estimate
from cbrs.sim.arms import ArmSide
from cbrs.sim.components import SimEnvironment
from cbrs.sim.context import SimContext
from cbrs.sim.grasping import ObjectModel
from cbrs.sim.packing import carry_spots
from cbrs.sim.place_spots import spot_region
from cbrs.sim.services import approach, pick_up
from cbrs.sim.values import GraspPlan, to_json
from cbrs.sim.world import open_world
from tests.helpers_examples import EXAMPLES

LAB9, WORLD = "https://example.org/lab9#", "https://w3id.org/cbrs/world#"


@pytest.fixture(scope="module")
def holding() -> Iterator[SimContext]:
    """The world at seed 2, the right arm (the nearer) holding the notebook it took off the box."""
    kb = KnowledgeBase.open(":memory:")
    for graph in ("ontology", "map"):
        kb.load([EXAMPLES / "lab9_book_on_box.ttl"], graph=graph)
    with open_world(seed=2, semantic_map=SemanticMap.read(kb)) as world:
        context = SimEnvironment(world, kb).context
        book = world.map.objects[LAB9 + "Notebook1"]
        seen = lying_estimate(world, None, book)
        plan = GraspPlan(book.iri, ObjectModel.of(book))
        approach(context, {"graspPose": to_json(plan), "objectPosition": to_json(seen)}, "CytonDualArm01")
        pick_up(context, {}, "CytonDualArm01")
        assert world.arm("right").held == world.body("Notebook1")
        yield context


def test_the_notebook_is_carried_to_a_spot_away_from_the_tap_s_lever(holding: SimContext) -> None:
    """Before, the carry aimed at (7.65, 3.29), among the first spots, its carry near the lever as theirs."""
    context = holding
    top = context.map.things[WORLD + "KitchenTableTop"]
    surface, spots = carry_spots(context, top, "Notebook1", ArmSide.RIGHT, None)
    _, brushed = carry_check(context, ArmSide.RIGHT, spot_region(surface, *spots[0]))
    assert "would come within 1 cm of the Tap01" in brushed
    spot = holdable_spot(context, ArmSide.RIGHT, surface, spots)
    assert spot is not None and spots.index(spot) >= relay.RELAY_TRIES  # before, only the first 40 were asked
    assert carry_check(context, ArmSide.RIGHT, spot_region(surface, *spot)) == ("", "")
    away = relay.appliance_distance(context.world)
    assert away(spot) > max(away(at) for at in spots[: relay.RELAY_TRIES])


def test_the_spots_asked_after_one_that_came_near() -> None:
    spots = [(0.02 * i, 0.0) for i in range(8)]  # 2 cm apart along a line, an appliance at x 0.07

    def away(at: tuple[float, float]) -> float:
        return abs(at[0] - 0.07)

    near: list[tuple[float, float]] = []
    asked = relay.clear_asked(spots, near, lambda at: at, away)
    assert [next(asked), next(asked)] == spots[:2]  # in order until one comes near
    near.append(spots[1])  # 5 cm from the appliance
    assert next(asked) == spots[7]  # the first farther (7 cm), across it
    near.append(spots[7])
    assert list(asked) == spots[2:7]  # none farther than 7 cm: the rest in order
    assert list(relay.clear_asked(spots, [], lambda at: at, away, since=5)) == spots[5:]
