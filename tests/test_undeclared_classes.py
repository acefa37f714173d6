"""A write that states a thing to be of a class nothing in the store declares is named, with the declared
class it reads as a slip of (kb/undeclared_classes.py; docs/tasks.md, "Add an object")."""

from __future__ import annotations

from typing import cast

import pyoxigraph as ox
from click.testing import CliRunner

from cbrs.cli import cli
from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import PREFIXES, GraphName
from cbrs.kb.store import Store
from cbrs.kb.undeclared_classes import MapTypes, written_undeclared_classes

HOME, WORLD, OWL = PREFIXES["home"], PREFIXES["world"], PREFIXES["owl"]
TYPE = ox.NamedNode(PREFIXES["rdf"] + "type")


def _typed(thing: str, concept: str) -> ox.Quad:
    return ox.Quad(ox.NamedNode(WORLD + thing), TYPE, ox.NamedNode(concept), GraphName.MAP.node)


def test_only_a_class_declared_nowhere_is_named_once_with_its_slip() -> None:
    kb = KnowledgeBase.open(":memory:")
    quads = [
        _typed("Mug9", HOME + "Cup"),  # declared in home.ttl
        _typed("Mug9", OWL + "NamedIndividual"),  # OWL's own, declared by no file
        _typed("Mug8", HOME + "Cpu"),
        _typed("Mug7", HOME + "Cpu"),  # the same class again: said once
    ]
    (found,) = written_undeclared_classes(kb.store, quads)
    assert (found.thing, found.concept, found.meant) == (WORLD + "Mug8", HOME + "Cpu", HOME + "Cup")
    assert found.text().startswith(
        f"Mug8 ({WORLD}Mug8) is stated to be of class Cpu ({HOME}Cpu), which nothing in the store declares"
        f" (did you mean Cup, {HOME}Cup?)"
    )
    kb.close()


def test_a_class_the_store_declares_in_any_graph_is_not_named() -> None:
    kb = KnowledgeBase.open(":memory:")
    kb.update("INSERT DATA { GRAPH graph:ontology { home:Trolley a owl:Class } }")
    assert written_undeclared_classes(kb.store, [_typed("Trolley1", HOME + "Trolley")]) == []
    kb.close()


def test_cbrs_update_warns_of_a_thing_inserted_into_the_map_as_cbrs_load_does() -> None:
    """INSERT DATA into graph:map is read quad by quad, so its classes are checked as a load's are; into another
    graph nothing is said. An update by a pattern is read by what it added to the map's types (next test)."""

    def run(update: str) -> list[str]:
        result = CliRunner().invoke(cli, ["--store", ":memory:", "update", update])
        assert result.exit_code == 0, result.output
        return [line for line in result.stderr.splitlines() if line.startswith("warning:")]

    (line,) = run("INSERT DATA { GRAPH graph:map { world:Mug8 a home:Cpu } }")
    assert line.startswith(f"warning: Mug8 ({WORLD}Mug8) is stated to be of class Cpu ({HOME}Cpu)")
    assert "(did you mean Cup," in line
    assert run("INSERT DATA { GRAPH graph:requirements { world:Mug8 a home:Cpu } }") == []
    (line,) = run("INSERT { GRAPH graph:map { world:Mug8 a home:Cpu } } WHERE {}")  # said nothing before
    assert line.startswith(f"warning: Mug8 ({WORLD}Mug8) is stated to be of class Cpu ({HOME}Cpu)")


def test_an_update_by_a_pattern_is_read_by_what_it_added_to_the_map() -> None:
    """A pattern's quads are known once it has run: the map's types after it that were not there before. One it
    re-states, or one into another graph, is not what it added; an update that cannot write the map has its
    statements not read at all."""
    kb = KnowledgeBase.open(":memory:")
    moved = (  # every cup gets a second, misspelt class, by a pattern; one thing already of a class is re-stated
        "DELETE { GRAPH graph:map { ?cup rdfs:label ?l } } INSERT { GRAPH graph:map { ?cup a home:Cpu, home:Cup ;"
        " rdfs:label ?l } } WHERE { GRAPH graph:map { ?cup a home:Cup ; rdfs:label ?l } }"
    )
    cups = {q.subject for q in kb.store.quads(None, TYPE, ox.NamedNode(HOME + "Cup"), GraphName.MAP.node)}
    typed = MapTypes(kb.store, moved)
    kb.update(moved)
    added = typed.added()
    assert cups and {q.subject for q in added} == cups and {q.object.value for q in added} == {HOME + "Cpu"}
    (found,) = typed.undeclared()
    assert (found.thing, found.concept, found.meant) == (min(c.value for c in cups), HOME + "Cpu", HOME + "Cup")
    again = MapTypes(kb.store, moved)  # the same again: nothing new
    kb.update(moved)
    assert again.added() == [] and again.undeclared() == []
    elsewhere = "INSERT { GRAPH graph:requirements { ?cup a home:Cpux } } WHERE { GRAPH graph:map { ?cup a home:Cup } }"
    typed = MapTypes(kb.store, elsewhere)
    kb.update(elsewhere)
    assert typed.added() == []

    class Unread:
        def quads(self, *pattern: object) -> None:
            raise AssertionError("read the map for an update that cannot write it")

    other = "INSERT { GRAPH graph:requirements { req:X a req:Y } } WHERE {}"
    assert MapTypes(cast(Store, Unread()), other).added() == []
    kb.close()
