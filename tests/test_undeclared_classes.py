"""A write that states a thing to be of a class nothing in the store declares is named, with the declared
class it reads as a slip of (kb/undeclared_classes.py; docs/tasks.md, "Add an object")."""

from __future__ import annotations

import pyoxigraph as ox
from click.testing import CliRunner

from cbrs.cli import cli
from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import PREFIXES, GraphName
from cbrs.kb.undeclared_classes import written_undeclared_classes

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
    graph, or by a pattern (whose quads are not known for certain), nothing is said."""

    def run(update: str) -> list[str]:
        result = CliRunner().invoke(cli, ["--store", ":memory:", "update", update])
        assert result.exit_code == 0, result.output
        return [line for line in result.stderr.splitlines() if line.startswith("warning:")]

    (line,) = run("INSERT DATA { GRAPH graph:map { world:Mug8 a home:Cpu } }")
    assert line.startswith(f"warning: Mug8 ({WORLD}Mug8) is stated to be of class Cpu ({HOME}Cpu)")
    assert "(did you mean Cup," in line
    assert run("INSERT DATA { GRAPH graph:requirements { world:Mug8 a home:Cpu } }") == []
    assert run("INSERT { GRAPH graph:map { world:Mug8 a home:Cpu } } WHERE {}") == []
