"""A class-level statement's two sides never stand for one thing (sim/components.py ``_judge``): a
piece of furniture that is also a place (a cupboard typed home:Cupboard and home:ObjectPlace) given to a
carry as its target grounds the statement's place, not the object carried above it too. Before, it
grounded both sides of (PhysicalObject, isAbove, Place): the belief held the cupboard above itself, and a
re-plan after a failed carry put down nothing."""

from __future__ import annotations

from pathlib import Path

from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.semantic_map import SemanticMap
from cbrs.sim.components import SimEnvironment
from cbrs.sim.relations import Grounded
from cbrs.sim.world import open_world

HOME = PREFIXES["home"]
CUPBOARD = "https://example.org/lab#LowCupboard1"
LOW_CUPBOARD = Path(__file__).parent.parent / "docs" / "examples" / "low_cupboard.ttl"


def test_a_furniture_place_grounds_the_place_and_not_the_object_above_it() -> None:
    kb = KnowledgeBase.open(":memory:")
    kb.load([LOW_CUPBOARD], graph="ontology")
    kb.load([LOW_CUPBOARD], graph="map")
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        environment = SimEnvironment(world, kb)
        inputs = {"targetPlace": {"@id": CUPBOARD}}
        place = environment._ground(HOME + "Place", inputs)
        assert place == Grounded("thing", CUPBOARD)
        # taken alone, the cupboard is a physical object as well: the side needs the other to tell
        assert environment._ground(HOME + "PhysicalObject", inputs) == Grounded("thing", CUPBOARD)
        above = environment._ground(HOME + "PhysicalObject", inputs, besides=place)
        assert above != place  # nothing held: no thing to judge rather than the cupboard over itself
        assert above is None
