"""Map mistakes are refused when the map is read or the world is built, before anything moves, naming the
thing, the property and the value (nu16 repros 07 and 13): a misspelt colour property, a colour name
perception does not know, a support that names nothing, an object beyond its support's edge, two objects
in each other. What the simulation still moves (settling objects a seed put together) is said in the log."""

from __future__ import annotations

import logging
from pathlib import Path

import pytest

from cbrs.kb import KnowledgeBase
from cbrs.kb.loader import load_files
from cbrs.kb.semantic_map import MapError, SemanticMap
from cbrs.sim.world import Spread, open_world

PREFIXES = """@prefix home:  <https://w3id.org/cbrs/home#> .
@prefix world: <https://w3id.org/cbrs/world#> .
@prefix owl:   <http://www.w3.org/2002/07/owl#> .
home:Bottle home:graspApproach "side top" ; home:graspHeightRatio 0.5 .
"""
COLOUR = 'home:colourName "green" ; home:rgba "0.10 0.70 0.20 1"'


def bottle(
    name: str = "Bottle1", x: float = 7.95, y: float = 3.33, colour: str = COLOUR, on: str = "KitchenTable"
) -> str:
    return f"""world:{name} a home:Bottle , owl:NamedIndividual ;
    home:shapeKind "cylinder" ; home:sizeX 0.06 ; home:sizeY 0.06 ; home:sizeZ 0.18 ; home:massKg 0.2 ;
    {colour} ; home:isLocatedOn world:{on} ; home:x {x} ; home:y {y} ; home:yaw 0.0 .
"""


def store(tmp_path: Path, *things: str) -> KnowledgeBase:
    kb = KnowledgeBase.open(":memory:")
    (tmp_path / "map.ttl").write_text(PREFIXES + "".join(things), encoding="utf-8")
    # written past kb.load, which refuses a map the reader would refuse (tests/test_nu17cli_map_load.py):
    # these tests are of the reader's own checks
    load_files(kb.store, [tmp_path / "map.ttl"], graph="map")
    return kb


def refusal(kb: KnowledgeBase) -> MapError:
    with pytest.raises(MapError) as refused:
        SemanticMap.read(kb)
    return refused.value


def test_a_misspelt_colour_property_is_refused_with_the_property_it_may_mean(tmp_path: Path) -> None:
    error = refusal(store(tmp_path, bottle(colour='home:colorName "green"')))
    assert error.thing.endswith("#Bottle1")
    assert "has no home:colourName" in str(error)
    assert "did you mean home:colourName for its home:colorName 'green'?" in str(error)


def test_a_missing_size_proposes_no_declared_property_as_its_slip(tmp_path: Path) -> None:
    """home:sizeZ is declared: it is no slip of a missing home:sizeX ("did you mean home:sizeX for its
    home:sizeZ 0.18?" was said); an undeclared home:sizeXX still is."""
    error = refusal(store(tmp_path, bottle().replace("home:sizeX 0.06 ; ", "")))
    assert "has no home:sizeX" in str(error) and "did you mean" not in str(error), str(error)
    error = refusal(store(tmp_path, bottle().replace("home:sizeX 0.06", "home:sizeXX 0.06")))
    assert "did you mean home:sizeX for its home:sizeXX '0.06'?" in str(error), str(error)


def test_an_object_with_no_colour_at_all_is_taken_as_before(tmp_path: Path) -> None:
    """No property of its own reads as a slip of home:colourName: it is built, and not looked for
    (tests/test_knowledge_driven.py builds such a book)."""
    assert SemanticMap.read(store(tmp_path, bottle(colour='home:rgba "0.1 0.7 0.2 1"'))).objects


def test_a_colour_perception_does_not_know_is_refused_as_the_world_is_built(tmp_path: Path) -> None:
    kb = store(tmp_path, bottle(colour='home:colourName "Green"'))
    with pytest.raises(MapError) as refused, open_world(0, semantic_map=SemanticMap.read(kb)):
        pass
    assert refused.value.thing.endswith("#Bottle1")
    assert "home:colourName 'Green', a colour perception cannot find (did you mean 'green'?)" in str(refused.value)


def test_a_support_that_names_nothing_is_refused_with_the_thing_it_may_mean(tmp_path: Path) -> None:
    error = refusal(store(tmp_path, bottle(on="KitchenTabel")))
    assert "home:isLocatedOn https://w3id.org/cbrs/world#KitchenTabel, which is nothing in the map" in str(error)
    assert "did you mean KitchenTable" in str(error)


def test_an_object_beyond_its_supports_edge_is_refused(tmp_path: Path) -> None:
    error = refusal(store(tmp_path, bottle(x=9.2)))
    assert error.thing.endswith("#Bottle1")
    assert "home:x 9.2, home:y 3.33, not over its support KitchenTable" in str(error)
    assert "x 7 .. 8.5, y 3 .. 4.5" in str(error)


@pytest.mark.parametrize(("x", "y"), [(7.47, 3.32), (8.05, 3.31)])  # in the cup; the pen in it
def test_objects_one_in_the_other_are_refused(tmp_path: Path, x: float, y: float) -> None:
    error = refusal(store(tmp_path, bottle(x=x, y=y)))
    assert error.thing.endswith(("#Bottle1", "#Cup", "#Pen"))
    assert " is in " in str(error) and "move one of them" in str(error)


def test_objects_close_but_apart_are_taken(tmp_path: Path) -> None:
    """The bottle 1 mm from the cup (both 3 cm in radius, centres 6.1 cm apart)."""
    SemanticMap.read(store(tmp_path, bottle(x=7.45, y=3.381)))


def test_objects_that_touch_in_the_map_are_said_to_be_pushed_apart(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    """The bottle 1 cm into the cup's side: built, and the log says they overlap and what settling moved."""
    kb = store(tmp_path, bottle(x=7.45, y=3.37))
    with (
        caplog.at_level(logging.WARNING, logger="cbrs.sim"),
        open_world(0, semantic_map=SemanticMap.read(kb), spread=Spread(object=0.0, yaw=0.0)) as world,
    ):
        moved = dict(world.settled)
    assert "Bottle1 and Cup overlap by 1.0 cm where the semantic map puts them" in caplog.text
    assert moved and all(f"{name} was built at" in caplog.text for name in moved)


def test_an_object_at_its_supports_edge_is_built_where_the_map_puts_it(tmp_path: Path) -> None:
    """Its centre over the table and its side 1 cm beyond the edge: the map's pose is kept (the seed's
    jitter alone is kept on the support), where it was moved onto the table before."""
    kb = store(tmp_path, bottle(x=8.49, y=3.6))
    with open_world(0, semantic_map=SemanticMap.read(kb), spread=Spread(object=0.0, yaw=0.0)) as world:
        x, y, _ = world.pose("Bottle1").position
    assert x == pytest.approx(8.49, abs=0.005) and y == pytest.approx(3.6, abs=0.005)


def test_objects_a_seed_puts_in_each_other_are_said_to_be_moved_by_settling(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    """Two bottles 2 mm apart; a seed moving objects up to 3 cm puts some pair in each other."""
    kb = store(tmp_path, bottle(x=7.9, y=3.6), bottle("Bottle2", x=7.962, y=3.6))
    said = []
    for seed in range(6):
        caplog.clear()
        with (
            caplog.at_level(logging.WARNING, logger="cbrs.sim"),
            open_world(seed, semantic_map=SemanticMap.read(kb), spread=Spread(object=0.03)) as world,
        ):
            for name, (start, rest) in world.settled.items():
                assert name in caplog.text and "settling moved it" in caplog.text
                said.append((seed, name, start, rest))
    assert said
