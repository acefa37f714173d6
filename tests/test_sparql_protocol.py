"""The SPARQL 1.1 Protocol's finer points on ``/sparql``, in the manner of the W3C protocol tests.

Which graphs a query reads (SPARQL 1.1 Query §13.2, Protocol §2.1.4): the query's ``FROM`` / ``FROM NAMED``
and the protocol's ``default-graph-uri`` / ``named-graph-uri``, with cbrs's union default graph only when
neither names a dataset. The test dataset has graphs of 1, 2 and 4 triples, so every count says which
graphs were merged. Each case runs on an in-memory store (evaluated on a thread), an on-disk store
(evaluated in worker processes) and an Oxigraph server (a remote store): the three must agree.

Then HEAD, a repeated ``query=``, the graph formats, ``Vary``, and rdflib's ``SPARQLStore`` /
``SPARQLUpdateStore`` scoped to one named graph, over loopback with bounded waits.
"""

from __future__ import annotations

import socket
import threading
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pyoxigraph as ox
import pytest
from flask.testing import FlaskClient
from waitress import wasyncore
from waitress.server import create_server
from werkzeug.datastructures import MultiDict
from werkzeug.test import TestResponse

from cbrs.kb import KnowledgeBase
from cbrs.kb.remote_store import RemoteStore
from cbrs.kb.store import Store
from cbrs.sparql_service import EndpointConfig, SparqlService, has_dataset_clause
from cbrs.web import create_app
from tests.conftest import OxigraphServer, VirtuosoServer

TOKEN = "protocol-test-token"
WAIT = 10.0
G1, G2, G3, ABSENT = "urn:test:g1", "urn:test:g2", "urn:test:g3", "urn:test:absent"
SIZES = {G1: 1, G2: 2, G3: 4}
COUNT = "SELECT (COUNT(*) AS ?n) {} WHERE {{ ?s ?p ?o }}"
PER_GRAPH = "SELECT ?g (COUNT(*) AS ?n) {} WHERE {{ GRAPH ?g {{ ?s ?p ?o }} }} GROUP BY ?g ORDER BY ?g"
METHODS = ["get", "post-form", "post-direct"]


def quads() -> list[ox.Quad]:
    made = []
    for graph, size in SIZES.items():
        for index in range(size):
            made.append(
                ox.Quad(
                    ox.NamedNode(f"{graph}:s{index}"),
                    ox.NamedNode("urn:test:p"),
                    ox.Literal(index),
                    ox.NamedNode(graph),
                )
            )
    return made


@pytest.fixture(scope="module", params=["memory", "disk", "remote"])
def client(request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory) -> Iterator[FlaskClient]:
    """The endpoint (Flask's test client) on the test dataset, in each of the three stores."""
    if request.param == "remote":
        start: Callable[..., OxigraphServer] = request.getfixturevalue("oxigraph_servers")
        location = start(on_disk=False).url
    elif request.param == "disk":
        location = str(tmp_path_factory.mktemp("protocol") / "store")
    else:
        location = ":memory:"
    kb = KnowledgeBase(Store.open(location))
    kb.store.add(quads())
    service = SparqlService(kb, EndpointConfig(update_token=TOKEN))
    assert (service.processes is not None) == (request.param == "disk")
    yield create_app(service).test_client()
    service.close()
    kb.close()


def send(client: FlaskClient, query: str, params: list[tuple[str, str]], method: str, path: str = "/sparql") -> Any:
    """The query sent the way ``method`` says, with the protocol ``params``; the JSON answer."""
    if method == "get":
        response = client.get(path, query_string=MultiDict([("query", query), *params]))
    elif method == "post-form":
        response = client.post(path, data=MultiDict([("query", query), *params]))
    else:  # a direct POST carries the dataset parameters in the URL
        response = client.post(
            path, query_string=MultiDict(params), data=query.encode(), content_type="application/sparql-query"
        )
    assert response.status_code == 200, response.get_data(as_text=True)
    return response.get_json()


def count(client: FlaskClient, dataset: str, params: list[tuple[str, str]], method: str) -> int:
    rows = send(client, COUNT.format(dataset), params, method)["results"]["bindings"]
    return int(rows[0]["n"]["value"])


def per_graph(client: FlaskClient, dataset: str, params: list[tuple[str, str]], method: str) -> dict[str, int]:
    rows = send(client, PER_GRAPH.format(dataset), params, method)["results"]["bindings"]
    return {row["g"]["value"]: int(row["n"]["value"]) for row in rows}


# -- the default graph --------------------------------------------------------------------------------

DEFAULT_GRAPH_CASES = [
    pytest.param("", [], 7, id="no-dataset-union-of-all-graphs"),
    pytest.param(f"FROM <{G1}>", [], 1, id="from-one-graph"),
    pytest.param(f"FROM <{G1}> FROM <{G3}>", [], 5, id="from-two-graphs-merged"),
    pytest.param(f"FROM <{ABSENT}>", [], 0, id="from-an-absent-graph-is-empty"),
    pytest.param(f"FROM NAMED <{G1}>", [], 0, id="from-named-alone-leaves-the-default-graph-empty"),
    pytest.param("", [("default-graph-uri", G2)], 2, id="default-graph-uri"),
    pytest.param("", [("default-graph-uri", G2), ("default-graph-uri", G3)], 6, id="two-default-graph-uris"),
    pytest.param("", [("named-graph-uri", G2)], 0, id="named-graph-uri-alone-leaves-the-default-graph-empty"),
    pytest.param(f"FROM <{G1}>", [("default-graph-uri", G3)], 4, id="protocol-overrides-from"),
    pytest.param(f"FROM <{G1}>", [("named-graph-uri", G3)], 0, id="protocol-named-overrides-from"),
]


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize(("dataset", "params", "expected"), DEFAULT_GRAPH_CASES)
def test_the_default_graph_follows_the_dataset_rules(
    client: FlaskClient, dataset: str, params: list[tuple[str, str]], expected: int, method: str
) -> None:
    assert count(client, dataset, params, method) == expected


# -- the named graphs ---------------------------------------------------------------------------------

NAMED_GRAPH_CASES = [
    pytest.param("", [], SIZES, id="no-dataset-every-named-graph"),
    pytest.param(f"FROM NAMED <{G1}> FROM NAMED <{G3}>", [], {G1: 1, G3: 4}, id="from-named"),
    pytest.param(f"FROM <{G1}>", [], {}, id="from-alone-names-no-graph"),
    pytest.param("", [("named-graph-uri", G2)], {G2: 2}, id="named-graph-uri"),
    pytest.param("", [("default-graph-uri", G1)], {}, id="default-graph-uri-alone-names-no-graph"),
    pytest.param(f"FROM NAMED <{G1}>", [("named-graph-uri", G2)], {G2: 2}, id="protocol-overrides-from-named"),
    pytest.param(
        "", [("default-graph-uri", G1), ("named-graph-uri", G2), ("named-graph-uri", G3)], {G2: 2, G3: 4}, id="full"
    ),
]


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize(("dataset", "params", "expected"), NAMED_GRAPH_CASES)
def test_the_named_graphs_follow_the_dataset_rules(
    client: FlaskClient, dataset: str, params: list[tuple[str, str]], expected: dict[str, int], method: str
) -> None:
    assert per_graph(client, dataset, params, method) == expected


def test_the_full_dataset_separates_default_and_named_graphs(client: FlaskClient) -> None:
    # W3C protocol test query_dataset_full: the default graph and the named graphs are separate.
    query = "SELECT ?g ?s WHERE { { ?s ?p ?o } UNION { GRAPH ?g { ?s ?p ?o } } } ORDER BY ?g ?s"
    params = [("default-graph-uri", G1), ("named-graph-uri", G2)]
    rows = send(client, query, params, "get")["results"]["bindings"]
    seen = [(row.get("g", {}).get("value"), row["s"]["value"]) for row in rows]
    assert seen == [(None, f"{G1}:s0"), (G2, f"{G2}:s0"), (G2, f"{G2}:s1")]


def test_a_from_clause_may_use_prefixed_names(client: FlaskClient) -> None:
    query = "PREFIX t: <urn:test:> SELECT (COUNT(*) AS ?n) FROM t:g2 FROM NAMED t:g3 WHERE { ?s ?p ?o }"
    assert send(client, query, [], "get")["results"]["bindings"][0]["n"]["value"] == "2"


def test_ask_and_construct_read_the_dataset_too(client: FlaskClient) -> None:
    ask = client.get("/sparql", query_string={"query": f"ASK FROM <{G1}> {{ <{G2}:s0> ?p ?o }}"})
    assert ask.get_json()["boolean"] is False
    construct = client.get(
        "/sparql",
        query_string={"query": "CONSTRUCT WHERE { ?s ?p ?o }", "default-graph-uri": G2},
        headers={"Accept": "application/n-triples"},
    )
    assert len(list(ox.parse(construct.data, ox.RdfFormat.N_TRIPLES))) == 2


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        pytest.param("SELECT * FROM <urn:x> { ?s ?p ?o }", True, id="from"),
        pytest.param("select * from named <urn:x> { graph ?g { ?s ?p ?o } }", True, id="lower-case"),
        pytest.param("SELECT * FROM<urn:x>{?s ?p ?o}", True, id="no-spaces"),
        pytest.param("SELECT ?from WHERE { ?from ?p ?o }", False, id="variable"),
        pytest.param("PREFIX from: <urn:f#> SELECT * { ?s from:x ?o }", False, id="prefixed-name"),
        pytest.param('SELECT * { ?s ?p "FROM" } # FROM', False, id="string-and-comment"),
        pytest.param("SELECT * { ?s <urn:FROM> ?o }", False, id="iri"),
    ],
)
def test_a_dataset_clause_is_told_from_the_word_elsewhere(text: str, expected: bool) -> None:
    assert has_dataset_clause(text) is expected


# -- refusals -----------------------------------------------------------------------------------------


def refusal(response: TestResponse, status: int = 400) -> str:
    assert response.status_code == status, response.get_data(as_text=True)
    message: str = response.get_json()["message"]
    return message


def test_a_dataset_parameter_that_is_not_an_iri_is_refused_by_name(client: FlaskClient) -> None:
    for name in ("default-graph-uri", "named-graph-uri"):
        message = refusal(client.get("/sparql", query_string={"query": COUNT.format(""), name: "not an iri"}))
        assert name in message and "'not an iri'" in message


def test_two_queries_or_two_updates_in_one_request_are_refused(client: FlaskClient) -> None:
    two = MultiDict([("query", "ASK {}"), ("query", "ASK {}")])
    assert "2 query= parameters" in refusal(client.get("/sparql", query_string=two))
    assert "2 query= parameters" in refusal(client.post("/sparql", data=two))
    updates = MultiDict([("update", "CLEAR ALL"), ("update", "CLEAR ALL")])
    message = refusal(client.post("/sparql", data=updates, headers={"Authorization": f"Bearer {TOKEN}"}))
    assert "2 update= parameters" in message


def test_each_operation_refuses_the_others_dataset_parameters(client: FlaskClient) -> None:
    query = refusal(client.get("/sparql", query_string={"query": "ASK {}", "using-graph-uri": G1}))
    assert "using-graph-uri" in query and "default-graph-uri" in query
    update = client.post(
        "/update",
        data={"update": "CLEAR ALL", "default-graph-uri": G1},
        headers={"Authorization": f"Bearer {TOKEN}"},
    )
    assert "default-graph-uri" in refusal(update)
    assert count(client, "", [], "get") == 7  # nothing was cleared


# -- HEAD, formats, Vary ------------------------------------------------------------------------------


@pytest.mark.parametrize("path", ["/sparql"])
def test_head_answers_like_get_without_a_body(client: FlaskClient, path: str) -> None:
    asked = {"query": COUNT.format("")}
    got = client.get(path, query_string=asked)
    head = client.head(path, query_string=asked)
    assert head.status_code == 200 and head.data == b""
    assert head.headers["Content-Type"] == got.headers["Content-Type"]
    assert head.headers["Content-Length"] == str(len(got.data))
    described = client.head(path)
    assert described.status_code == 200 and described.mimetype == "text/turtle" and described.data == b""


GRAPH_FORMATS = [
    pytest.param("application/n-triples", ox.RdfFormat.N_TRIPLES, id="n-triples"),
    pytest.param("application/n-quads", ox.RdfFormat.N_QUADS, id="n-quads"),
    pytest.param("application/trig", ox.RdfFormat.TRIG, id="trig"),
    pytest.param("text/n3", ox.RdfFormat.N3, id="n3"),
    pytest.param("text/turtle", ox.RdfFormat.TURTLE, id="turtle"),
]


@pytest.mark.parametrize(("media_type", "rdf_format"), GRAPH_FORMATS)
@pytest.mark.parametrize("form", ["CONSTRUCT WHERE { ?s ?p ?o }", f"DESCRIBE <{G3}:s2>"])
def test_construct_and_describe_answer_in_the_format_asked(
    client: FlaskClient, form: str, media_type: str, rdf_format: ox.RdfFormat
) -> None:
    response = client.get(
        "/sparql", query_string={"query": form, "default-graph-uri": G3}, headers={"Accept": media_type}
    )
    assert response.status_code == 200, response.get_data(as_text=True)
    assert response.mimetype == media_type
    triples = {(q.subject, q.predicate, q.object) for q in ox.parse(response.data, rdf_format)}
    expected = 4 if form.startswith("CONSTRUCT") else 1
    assert len(triples) == expected
    assert all(q.graph_name == ox.DefaultGraph() for q in ox.parse(response.data, rdf_format))


def test_every_answer_varies_on_origin(client: FlaskClient) -> None:
    answers = [
        client.get("/sparql", query_string={"query": "ASK {}"}),
        client.get("/sparql", query_string={"query": "ASK {}"}, headers={"Origin": "http://elsewhere.example"}),
        client.post("/sparql", data="ASK {}", content_type="application/sparql-query"),
        client.get("/sparql", query_string={"query": "NOT SPARQL"}),
        client.get("/sparql"),
        client.post("/update", data={"update": "CLEAR ALL"}),
    ]
    for response in answers:
        assert "Origin" in response.vary, (response.status_code, response.headers)
    assert "Accept" in answers[0].vary


# -- rdflib's SPARQL stores over loopback -------------------------------------------------------------


@pytest.fixture
def live(tmp_path: Path) -> Iterator[str]:
    """The endpoint on waitress at a free loopback port on an in-memory copy of the test dataset."""
    kb = KnowledgeBase(Store.open(":memory:"))
    kb.store.add(quads())
    service = SparqlService(kb, EndpointConfig(update_token=TOKEN))
    sockets: dict[int, Any] = {}
    server = create_server(create_app(service), host="127.0.0.1", port=0, map=sockets, threads=2)
    thread = threading.Thread(target=server.run, daemon=True)
    thread.start()
    previous = socket.getdefaulttimeout()
    socket.setdefaulttimeout(WAIT)  # rdflib's urlopen calls take no timeout of their own
    try:
        yield f"http://127.0.0.1:{server.effective_port}"
    finally:
        socket.setdefaulttimeout(previous)
        server.task_dispatcher.shutdown(timeout=5)
        server.trigger.pull_trigger(lambda: wasyncore.close_all(sockets))
        thread.join(5)
        assert not thread.is_alive()
        kb.close()


@pytest.mark.parametrize("method", ["GET", "POST", "POST_FORM"])
def test_rdflib_sparqlstore_reads_one_named_graph(live: str, method: str) -> None:
    from rdflib import Graph, Literal, URIRef
    from rdflib.plugins.stores.sparqlstore import SPARQLStore

    store = SPARQLStore(live + "/sparql", method=method)
    graph = Graph(store, identifier=URIRef(G2))
    assert len(graph) == 2
    assert sorted(o for _, _, o in graph.triples((None, URIRef("urn:test:p"), None))) == [Literal(0), Literal(1)]
    rows = list(graph.query("SELECT ?s WHERE { ?s ?p ?o } ORDER BY ?s"))
    assert [str(row[0]) for row in rows] == [f"{G2}:s0", f"{G2}:s1"]
    assert len(Graph(store, identifier=URIRef(G3))) == 4


def test_rdflib_sparqlupdatestore_writes_one_named_graph(live: str) -> None:
    from rdflib import Graph, Literal, URIRef
    from rdflib.plugins.stores.sparqlstore import SPARQLUpdateStore

    store = SPARQLUpdateStore(
        live + "/sparql", live + "/update", headers={"Authorization": f"Bearer {TOKEN}"}, autocommit=True
    )
    added = Graph(store, identifier=URIRef("urn:test:written"))
    triple = (URIRef("urn:test:new"), URIRef("urn:test:p"), Literal("written"))
    added.add(triple)
    assert len(added) == 1 and triple in added
    assert triple not in Graph(store, identifier=URIRef(G1))
    added.update('INSERT DATA { <urn:test:new> <urn:test:p> "again" }')  # rewritten into the graph by rdflib
    assert len(added) == 2
    added.remove(triple)
    assert list(added) == [(URIRef("urn:test:new"), URIRef("urn:test:p"), Literal("again"))]
    assert len(Graph(store, identifier=URIRef(G2))) == 2


# -- a remote store on another server than Oxigraph ---------------------------------------------------


@pytest.fixture
def virtuoso(virtuoso_server: VirtuosoServer) -> str:
    """The session's Virtuoso (tests/conftest.py), cleared: the URL of its endpoint."""
    virtuoso_server.clear()
    return virtuoso_server.url


def test_a_remote_store_on_virtuoso_reads_and_writes(virtuoso: str) -> None:
    # Virtuoso 7 never answers a query sent as an application/sparql-query body: a form POST it does.
    store = RemoteStore.open(f"{virtuoso} {virtuoso}", timeout=WAIT)
    try:
        store.add(quads())
        assert store.count(ox.NamedNode(G3)) == 4
        solutions = store.query(f"SELECT ?s WHERE {{ GRAPH <{G2}> {{ ?s ?p ?o }} }} ORDER BY ?s")
        assert isinstance(solutions, ox.QuerySolutions)
        assert [row["s"] for row in solutions] == [ox.NamedNode(f"{G2}:s0"), ox.NamedNode(f"{G2}:s1")]
        assert bool(store.query(f"ASK {{ <{G1}:s0> ?p 0 }}"))  # the default graph is the union
        scoped = store.query_dataset(COUNT.format(""), [G3], [])
        assert isinstance(scoped, ox.QuerySolutions)
        assert [row["n"] for row in scoped] == [ox.Literal(4)]
        built = store.query(f"CONSTRUCT WHERE {{ GRAPH <{G1}> {{ ?s ?p ?o }} }}")
        assert isinstance(built, ox.QueryTriples) and len(list(built)) == 1
    finally:
        store.update(f"DROP SILENT GRAPH <{G1}> ; DROP SILENT GRAPH <{G2}> ; DROP SILENT GRAPH <{G3}>")
        store.close()
