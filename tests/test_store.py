from __future__ import annotations

from pathlib import Path

import pyoxigraph as ox
import pytest

from cbrs.kb import KnowledgeBase, QuerySyntaxError, Store, StoreError
from cbrs.kb.namespaces import GraphName
from cbrs.kb.store import nesting_depth

pytestmark = pytest.mark.both_stores

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


@pytest.mark.parametrize(
    "text",
    [
        "SELECT * WHERE { FILTER(" + "(" * 300 + "1" + ")" * 300 + ") }",
        "SELECT * WHERE " + "{" * 300 + "?s ?p ?o" + "}" * 300,
        "INSERT { <http://e/a> <http://e/p> 1 } WHERE " + "{" * 300 + "}" * 300,
    ],
)
def test_deep_nesting_is_refused_before_parsing(mini_kb: KnowledgeBase, text: str) -> None:
    before = mini_kb.store.dump()
    with pytest.raises(QuerySyntaxError, match=r"nested 30[0-9] deep; at most 256"):
        if text.startswith("INSERT"):
            mini_kb.store.update(text)
        else:
            mini_kb.query(text)
    assert mini_kb.store.dump() == before


def test_brackets_in_strings_iris_and_comments_do_not_count(mini_kb: KnowledgeBase) -> None:
    brackets = "(" * 400
    long_string = '"' * 3 + brackets + "\n" + '"' * 3
    text = (
        f"SELECT ?x WHERE {{ # {brackets}\n"
        f"VALUES ?x {{ \"{brackets}\" '{brackets}' {long_string} <http://e/{brackets}> }} }}"
    )
    assert len(list(mini_kb.query(text))) == 4
    assert nesting_depth(text) == 2


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


# -- the same behaviour on both backends -----------------------------------------------------------

HOSTILE = [
    pytest.param('say "hi"', id="double-quotes"),
    pytest.param("it's '''long''' and \"\"\"longer\"\"\"", id="long-quotes"),
    pytest.param("} ; DROP ALL ; {", id="drop-all"),
    pytest.param("{ } ( ) < > ? $ . ;", id="punctuation"),
    pytest.param("line one\nline two\r\n\ttabbed", id="newlines"),
    pytest.param("# not a comment \\ nor an escape \\n", id="hash-backslash"),
    pytest.param("<http://e/> } INSERT DATA { <http://e/x> <http://e/p> 1 } #", id="insert"),
    pytest.param("naïve façade ✓ \U0001d518", id="unicode"),
]


@pytest.mark.parametrize("value", HOSTILE)
def test_a_hostile_bound_value_arrives_as_a_literal_and_changes_nothing(mini_kb: KnowledgeBase, value: str) -> None:
    before = mini_kb.store.dump()
    literal = ox.Literal(value)
    result = mini_kb.query('SELECT ?x ?same WHERE { BIND (?x = "unrelated" AS ?same) }', {"x": literal})
    assert isinstance(result, ox.QuerySolutions)
    assert [(row["x"], row["same"]) for row in result] == [(literal, ox.Literal(False))]
    assert mini_kb.store.dump() == before


def test_bindings_pre_bind_aggregates_and_limit(mini_kb: KnowledgeBase) -> None:
    # A VALUES clause after the query would join after GROUP BY and LIMIT; a binding must not.
    missing = {"s": ox.NamedNode("http://e/nothing")}
    counted = mini_kb.query("SELECT ?s (COUNT(?o) AS ?n) WHERE { OPTIONAL { ?s ?p ?o } } GROUP BY ?s", missing)
    assert isinstance(counted, ox.QuerySolutions)
    assert [row["n"].value for row in counted] == ["0"]
    last = sorted(
        q.subject for q in mini_kb.store.quads(None, ox.NamedNode("http://www.w3.org/2000/01/rdf-schema#label"))
    )[-1]
    limited = mini_kb.query("SELECT ?s ?label WHERE { ?s rdfs:label ?label } ORDER BY ?s LIMIT 1", {"s": last})
    assert isinstance(limited, ox.QuerySolutions)
    assert [row["s"] for row in limited] == [last]


def test_construct_ask_and_describe_give_oxigraph_results(mini_kb: KnowledgeBase) -> None:
    locate = ox.NamedNode("http://example.org/mini#Locate")
    triples = mini_kb.query("CONSTRUCT { ?s cbrs:deviceName ?n } WHERE { ?s cbrs:deviceName ?n }", {"s": locate})
    assert isinstance(triples, ox.QueryTriples)
    assert [(t.subject, t.object.value) for t in triples] == [(locate, "Camera1")]
    short = mini_kb.query("CONSTRUCT WHERE { ?s cbrs:serviceName ?n }", {"s": locate})
    assert isinstance(short, ox.QueryTriples) and [t.object.value for t in short] == ["LocateRobot"]
    described = mini_kb.query("DESCRIBE ?s", {"s": locate})
    assert isinstance(described, ox.QueryTriples)
    subjects = {t.subject for t in described if isinstance(t, ox.Triple)}
    assert locate in subjects
    asked = mini_kb.query("ASK { ?s a cbrs:DynamicPerceptionComponent }", {"s": locate})
    assert isinstance(asked, ox.QueryBoolean) and bool(asked)


def test_a_failed_update_leaves_the_store_as_it_was(mini_kb: KnowledgeBase) -> None:
    before = mini_kb.store.dump()
    with pytest.raises(StoreError, match="already exists"):
        mini_kb.store.update(
            "INSERT DATA { GRAPH graph:world { <http://e/a> <http://e/p> 1 } } ; CREATE GRAPH graph:ontology"
        )
    assert mini_kb.store.dump() == before


def test_update_syntax_error_is_typed(mini_kb: KnowledgeBase) -> None:
    with pytest.raises(QuerySyntaxError) as caught:
        mini_kb.store.update("INSERT DATA { <http://e/a> <http://e/p> }")
    assert caught.value.query == "INSERT DATA { <http://e/a> <http://e/p> }"
    assert "error at 1:" in caught.value.message


def test_quads_count_and_graphs(store_location: str) -> None:
    store = Store.open(store_location)
    a, p = ox.NamedNode("http://e/a"), ox.NamedNode("http://e/p")
    default = ox.Quad(a, p, ox.Literal("in the default graph"))
    named = [_quad("a", "1"), _quad("b", "2"), ox.Quad(a, p, ox.Literal("x", language="en"), GraphName.PLANS.node)]
    store.add([default, *named])
    assert sorted(map(str, store.quads())) == sorted(map(str, [default, *named]))
    assert list(store.quads(graph=ox.DefaultGraph())) == [default]
    assert sorted(map(str, store.quads(a))) == sorted(map(str, [default, named[0], named[2]]))
    assert list(store.quads(None, None, ox.Literal("2"), G)) == [named[1]]
    assert (store.count(), store.count(GraphName.WORLD), store.count(GraphName.PLANS.node)) == (4, 2, 1)
    assert store.graphs() == [GraphName.PLANS.iri, GraphName.WORLD.iri]
    assert not store.is_seeded()
    assert store.in_memory == (store_location == ":memory:") and store.location == store_location
    assert store.dump().count(b"\n") == 4
    store.close()


def test_a_closed_store_says_so(store_location: str) -> None:
    store = Store.open(store_location)
    store.close()
    store.close()
    with pytest.raises(StoreError, match="is closed"):
        store.count()
