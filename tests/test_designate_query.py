"""The ``designate`` and ``map_types`` queries as the semantic map's reader and the executor use them:
one class bound, every class at once, and the map read asking once for every class."""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Iterator
from pathlib import Path

import pytest

from cbrs.kb import KnowledgeBase, Store
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.resources import ontology_dir
from cbrs.kb.semantic_map import SemanticMap

pytestmark = pytest.mark.both_stores

HOME, WORLD = PREFIXES["home"], PREFIXES["world"]
EX = "http://example.org/designate#"

# A taxonomy with a cycle (A below B below A, as an entailment may state), a thing of the map, a thing
# of the belief graph, and a thing typed in the ontology graph with no statement in map or belief.
ONTOLOGY = f"""
@prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> .
@prefix ex: <{EX}> .
ex:Mug rdfs:subClassOf ex:Drinkware .
ex:Drinkware rdfs:subClassOf ex:Container .
ex:Container rdfs:subClassOf ex:Vessel .
ex:Vessel rdfs:subClassOf ex:Container .
ex:Elsewhere a ex:Mug .
"""
MAP = f"""
@prefix ex: <{EX}> .
ex:Mug1 a ex:Mug ; ex:colour "red" .
ex:Table1 a ex:Table ; ex:height 0.7 .
"""
WORLD_BELIEF = f"""
@prefix ex: <{EX}> .
ex:Cup1 a ex:Drinkware ; ex:seen true .
"""


@pytest.fixture
def world_kb(store_location: str, tmp_path: Path) -> Iterator[KnowledgeBase]:
    kb = KnowledgeBase(Store.open(store_location))
    kb.load([ontology_dir() / "core.ttl"], graph="ontology")
    for name, text, graph in (("o.ttl", ONTOLOGY, "ontology"), ("m.ttl", MAP, "map"), ("w.ttl", WORLD_BELIEF, "world")):
        (tmp_path / name).write_text(text, encoding="utf-8")
        kb.load([tmp_path / name], graph=graph)
    yield kb
    kb.close()


def _things(kb: KnowledgeBase, concept: str) -> list[str]:
    return sorted(row["thing"].value for row in kb.select("designate", {"class": EX + concept}))


def test_designate_follows_subclasses_and_cycles_once(world_kb: KnowledgeBase) -> None:
    assert _things(world_kb, "Mug") == [EX + "Mug1"]
    assert _things(world_kb, "Drinkware") == [EX + "Cup1", EX + "Mug1"]
    # each thing once although the cycle reaches Container again through Vessel
    assert _things(world_kb, "Container") == [EX + "Cup1", EX + "Mug1"]
    assert _things(world_kb, "Vessel") == [EX + "Cup1", EX + "Mug1"]
    assert _things(world_kb, "Table") == [EX + "Table1"]
    assert _things(world_kb, "Chair") == []


def test_designate_keeps_the_class_the_thing_is_stated_to_be(world_kb: KnowledgeBase) -> None:
    rows = world_kb.select("designate", {"class": EX + "Container"})
    assert sorted((row["thing"].value, row["type"].value) for row in rows) == [
        (EX + "Cup1", EX + "Drinkware"),
        (EX + "Mug1", EX + "Mug"),
    ]
    own = world_kb.select("designate", {"class": EX + "Mug"})
    assert [(row["thing"].value, row["type"].value) for row in own] == [(EX + "Mug1", EX + "Mug")]


def test_designate_every_class_at_once_agrees_with_each_class(world_kb: KnowledgeBase) -> None:
    every: dict[str, set[str]] = defaultdict(set)
    for row in world_kb.queries.select_every(world_kb.store, "designate"):
        every[row["class"].value].add(row["thing"].value)
    classes = ("Mug", "Drinkware", "Container", "Vessel", "Table")
    assert {c: sorted(every[EX + c]) for c in classes} == {c: _things(world_kb, c) for c in classes}
    assert EX + "Elsewhere" not in set().union(*every.values())  # in no map or belief graph


def test_map_types_lists_only_the_map_things_stated_classes(world_kb: KnowledgeBase) -> None:
    rows = world_kb.select("map_types")
    assert sorted((row["thing"].value, row["type"].value) for row in rows) == [
        (EX + "Mug1", EX + "Mug"),
        (EX + "Table1", EX + "Table"),
    ]
    assert [row["type"].value for row in world_kb.select("map_types", {"thing": EX + "Table1"})] == [EX + "Table"]


def test_the_map_read_asks_designate_once_for_every_class(bundled_kb: KnowledgeBase) -> None:
    # one query for the seven classes the reader sorts things by (rooms, furniture, ...), not one each:
    # a query costs a round trip on a remote store
    text = bundled_kb.queries.get("designate").text
    asked: list[object] = []
    store = bundled_kb.store
    original = store.query

    def counting(query: str, bindings: object = None) -> object:
        if query == text:
            asked.append(bindings)
        return original(query, bindings)  # type: ignore[arg-type]

    store.query = counting  # type: ignore[method-assign,assignment]
    try:
        read = SemanticMap.read(bundled_kb)
    finally:
        del store.query
    assert len(asked) == 1
    assert read.rooms and read.furniture and read.containers
    assert read.rooms == frozenset(
        row["thing"].value for row in bundled_kb.select("designate", {"class": HOME + "Room"})
    )
