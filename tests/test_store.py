from __future__ import annotations

from pathlib import Path

import pyoxigraph as ox
import pytest

from kb import KnowledgeBase, QuerySyntaxError, Store, StoreError
from kb.namespaces import GraphName

G = GraphName.WORLD.node


def _quad(s: str, o: str) -> ox.Quad:
    return ox.Quad(ox.NamedNode(f"http://e/{s}"), ox.NamedNode("http://e/p"), ox.Literal(o), G)


def test_replace_removes_and_adds_together(mini_kb: KnowledgeBase) -> None:
    mini_kb.store.add([_quad("a", "1")])
    mini_kb.store.replace([_quad("a", "1")], [_quad("a", '2 "quoted" } ; DROP ALL ; {')])
    values = [q.object.value for q in mini_kb.store.quads(ox.NamedNode("http://e/a"))]
    assert values == ['2 "quoted" } ; DROP ALL ; {']
    assert mini_kb.store.count(GraphName.ONTOLOGY) > 0


def test_replace_refuses_blank_nodes_and_writes_nothing(mini_kb: KnowledgeBase) -> None:
    before = mini_kb.store.dump()
    blank = ox.Quad(ox.BlankNode(), ox.NamedNode("http://e/p"), ox.Literal("x"), G)
    with pytest.raises(ValueError, match="blank node"):
        mini_kb.store.replace([], [_quad("b", "1"), blank])
    assert mini_kb.store.dump() == before


def test_query_syntax_error_is_typed(mini_kb: KnowledgeBase) -> None:
    with pytest.raises(QuerySyntaxError) as caught:
        mini_kb.query("SELECT ?x WHERE { ?x ")
    assert caught.value.query == "SELECT ?x WHERE { ?x "


def test_queries_see_every_graph_by_default(mini_kb: KnowledgeBase) -> None:
    result = mini_kb.query("ASK { ?s a cbrs:Requirement . ?c rdfs:subClassOf cbrs:ServiceDescription }")
    assert bool(result)


def test_store_path_that_is_a_file_is_refused(tmp_path: Path) -> None:
    path = tmp_path / "file"
    path.write_text("x")
    with pytest.raises(StoreError, match="not a directory"):
        Store.open(path)


def test_dump_is_byte_stable(mini_kb: KnowledgeBase) -> None:
    assert mini_kb.store.dump() == mini_kb.store.dump()
    assert mini_kb.store.dump().count(b"\n") == mini_kb.store.count()
