"""An object painted in a colour something else of the map shows (a base's marker patch, a person's
shirt) is looked for only near where it is believed to be: searched for anywhere, that other thing's
patch would be taken for it (nu16 repro 01: a magenta remote believed on the base's rear patch). An
object of its own colour is still found anywhere (tests/test_perceived_belief.py)."""

from __future__ import annotations

import math
from pathlib import Path

from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.semantic_map import SemanticMap
from cbrs.sim.perceived import PerceivedWorld
from cbrs.sim.world import open_world

EXAMPLES = Path(__file__).parent.parent / "docs" / "examples"
WORLD = PREFIXES["world"]
RGBA = {"magenta": "0.80 0.10 0.80 1"}


def remote_of(colour: str, x: float = 7.95, y: float = 3.13) -> KnowledgeBase:
    """The example's remote control on the kitchen table at (x, y), painted ``colour``."""
    kb = KnowledgeBase.open(":memory:")
    kb.load([EXAMPLES / "remote_on_the_table.ttl"], graph="map")
    remote = f"<{WORLD}Remote1>"
    kb.update(  # one request: the remote without a pose in between is a map no task reads, and is refused
        f"DELETE WHERE {{ GRAPH graph:map {{ {remote} home:colourName ?c ; home:rgba ?r ; home:x ?x ; home:y ?y }} }};"
        f"INSERT DATA {{ GRAPH graph:map {{ {remote} home:colourName '{colour}' ; home:rgba '{RGBA[colour]}' ; "
        f"home:x {x} ; home:y {y} }} }}"
    )
    return kb


def test_the_colours_of_markers_and_shirts_are_not_an_objects_own() -> None:
    with open_world(seed=0, semantic_map=SemanticMap.read(remote_of("magenta"))) as world:
        owners = PerceivedWorld(world).colour_owners
        remote = WORLD + "Remote1"
        assert remote in owners["magenta"] and len(owners["magenta"]) > 1  # and the base's rear patch
        assert len(owners["yellow"]) >= 1 and remote not in owners["yellow"]  # the person's shirt
        assert owners["red"] == {WORLD + "Cup"}


def test_an_object_of_the_markers_colour_not_seen_where_it_is_is_not_found_on_the_base() -> None:
    """At the east edge of the Kinect's image (cut by its border, so not seen near its map pose), a magenta
    remote is not found; before, the wide search took the base's magenta rear patch for it."""
    with open_world(seed=0, semantic_map=SemanticMap.read(remote_of("magenta", 8.25, 3.15))) as world:
        belief = PerceivedWorld(world)
        belief.look(["Remote1"], people=False)
        seen = belief.position("Remote1")
        base = world.base_pose()
        assert seen is None or math.hypot(seen[0] - 8.25, seen[1] - 3.15) < 0.1, (seen, base)
