"""A thing of the map that loses part of its extent is refused when the map is read, and an update that
takes it away is undone whole: deleting the kitchen table's ``home:maxZ`` was accepted, and the reader
stood its top at 0 m (``maxZ`` defaulted to 0.0 for anything built as a box). Every height the
simulation reads is given, or the thing refused naming it (``NoExtentError``); the two defaults left are
documented (docs/tasks.md): a room is a floor area at 0 m, and a piece of furniture's ``home:minZ`` is
its top. No world is built."""

from __future__ import annotations

from collections.abc import Iterator

import pyoxigraph as ox
import pytest
from click.testing import CliRunner

from cbrs.cli import cli
from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.semantic_map import NoExtentError, SemanticMap

WORLD = PREFIXES["world"]
DELETE = (
    "DELETE {{ GRAPH graph:map {{ world:{thing} home:{prop} ?v }} }} "
    "WHERE {{ GRAPH graph:map {{ world:{thing} home:{prop} ?v }} }}"
)


@pytest.fixture(scope="module")
def kb() -> Iterator[KnowledgeBase]:
    """One seeded store for the module: every update its tests send is refused and undone."""
    opened = KnowledgeBase.open(":memory:")
    yield opened
    opened.close()


@pytest.mark.parametrize(
    ("thing", "prop", "kind", "why"),
    [
        pytest.param("KitchenTable", "maxZ", "Table", "things stand on its top", id="a-table-its-top"),
        pytest.param("KitchenTableTop", "maxZ", "TableTop", "from home:minZ up to home:maxZ", id="a-region-its-top"),
        pytest.param("BelowOfTap", "minZ", "BelowOfTap", "from home:minZ up to home:maxZ", id="a-region-its-bottom"),
        pytest.param("WallEast", "minZ", "Wall", "from home:minZ up to home:maxZ", id="a-wall-its-bottom"),
        pytest.param("Spout01", "maxZ", "Spout", "from home:minZ up to home:maxZ", id="a-spout"),
        pytest.param("WallEast", "minX", "Wall", "no extent", id="a-wall-left-out"),
        pytest.param("Kitchen", "minX", "Kitchen", "a thing without home:minX", id="a-room-left-out"),
    ],
)
def test_an_update_that_takes_a_height_or_an_edge_away_is_refused_and_undone(
    kb: KnowledgeBase, thing: str, prop: str, kind: str, why: str
) -> None:
    before = kb.store.dump()
    with pytest.raises(NoExtentError) as refused:
        kb.update(DELETE.format(thing=thing, prop=prop))
    error = refused.value
    assert error.thing == WORLD + thing and error.missing == (f"home:{prop}",)
    said = str(error)
    assert said.startswith(f"semantic map: {thing} ({WORLD}{thing}) is a {kind} ") and why in said, said
    assert kb.store.dump() == before  # the store as it was


def test_the_reader_refuses_a_table_without_its_top_however_it_got_there(kb: KnowledgeBase) -> None:
    """Written past the checks, the map does not read: a run, ``cbrs home`` and the home page say so by
    name rather than build a table 0 m high."""
    top = ox.NamedNode(PREFIXES["home"] + "maxZ")
    (table,) = kb.store.quads(subject=ox.NamedNode(WORLD + "KitchenTable"), predicate=top)
    kb.store.replace([table], [])
    try:
        with pytest.raises(NoExtentError, match=r"KitchenTable .* lacks home:maxZ"):
            SemanticMap.read(kb)
    finally:
        kb.store.replace([], [table])
    assert SemanticMap.read(kb).things[WORLD + "KitchenTable"].box.max_z == float(table.object.value)


def test_the_documented_defaults_stand(kb: KnowledgeBase) -> None:
    """A room has no height (the floor's, 0 m); a piece of furniture's bottom defaults to its top."""
    built = SemanticMap.read(kb)
    kitchen = built.things[WORLD + "Kitchen"].box
    assert (kitchen.min_z, kitchen.max_z) == (0.0, 0.0)
    assert not list(
        kb.store.quads(subject=ox.NamedNode(WORLD + "Kitchen"), predicate=ox.NamedNode(PREFIXES["home"] + "maxZ"))
    )


def test_cbrs_update_says_which_thing_lacks_what() -> None:
    result = CliRunner().invoke(
        cli, ["--store", ":memory:", "update", DELETE.format(thing="KitchenTable", prop="maxZ")]
    )
    assert result.exit_code == 1, result.output
    (line,) = result.stderr.splitlines()
    assert line.startswith("Error: semantic map: KitchenTable") and "lacks home:maxZ" in line, line
