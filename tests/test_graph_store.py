"""The Graph Store HTTP Protocol on /store: read, replace, add to and drop graphs, as the recommendation says."""

from __future__ import annotations

import pyoxigraph as ox
import pytest
from flask.testing import FlaskClient
from werkzeug.test import TestResponse

from cbrs.kb import KnowledgeBase
from cbrs.kb.store import Store
from cbrs.sparql_service import EndpointConfig, SparqlService
from cbrs.web import create_app
from tests.conftest import OxigraphServer
from tests.helpers_seeded import put_quads, seeded_quads

TOKEN = "graph-store-token"
GRAPH = "urn:test:notes"
AUTH = {"Authorization": f"Bearer {TOKEN}"}
TURTLE = "text/turtle"


@pytest.fixture
def client() -> FlaskClient:
    kb = KnowledgeBase.open(":memory:")
    return create_app(SparqlService(kb, EndpointConfig(update_token=TOKEN, isolate=False))).test_client()


def triples(data: bytes, fmt: ox.RdfFormat = ox.RdfFormat.TURTLE) -> set[tuple[str, str, str]]:
    return {(str(t.subject), str(t.predicate), str(t.object)) for t in ox.parse(data, format=fmt)}


def test_put_creates_then_replaces_a_graph_and_get_reads_it_back(client: FlaskClient) -> None:
    first = client.put(f"/store?graph={GRAPH}", data="<urn:a> <urn:p> 1 .", content_type=TURTLE, headers=AUTH)
    assert first.status_code == 201
    again = client.put(f"/store?graph={GRAPH}", data="<urn:b> <urn:p> 2 .", content_type=TURTLE, headers=AUTH)
    assert again.status_code == 204
    got = client.get(f"/store?graph={GRAPH}")
    assert got.status_code == 200 and got.mimetype == "text/turtle"
    assert {s for s, _, _ in triples(got.data)} == {"<urn:b>"}  # replaced, not merged
    as_nt = client.get(f"/store?graph={GRAPH}", headers={"Accept": "application/n-triples"})
    assert as_nt.mimetype == "application/n-triples" and triples(as_nt.data, ox.RdfFormat.N_TRIPLES) == triples(
        got.data
    )
    head = client.head(f"/store?graph={GRAPH}")
    assert head.status_code == 200 and head.data == b""


def test_post_adds_to_a_graph_and_delete_drops_it(client: FlaskClient) -> None:
    for n in (1, 2):
        posted = client.post(
            f"/store?graph={GRAPH}", data=f"<urn:s{n}> <urn:p> {n} .", content_type=TURTLE, headers=AUTH
        )
        assert posted.status_code == 204
    assert {s for s, _, _ in triples(client.get(f"/store?graph={GRAPH}").data)} == {"<urn:s1>", "<urn:s2>"}
    assert client.delete(f"/store?graph={GRAPH}", headers=AUTH).status_code == 204
    assert client.get(f"/store?graph={GRAPH}").status_code == 404
    assert client.delete(f"/store?graph={GRAPH}", headers=AUTH).status_code == 404


def test_the_whole_store_reads_as_a_dataset_and_takes_quads(client: FlaskClient) -> None:
    trig = client.get("/store", headers={"Accept": "application/trig"})
    assert trig.status_code == 200 and trig.mimetype == "application/trig"
    graphs = {str(q.graph_name) for q in ox.parse(trig.data, format=ox.RdfFormat.TRIG)}
    assert "<https://w3id.org/cbrs/graph/ontology>" in graphs
    body = f"<{GRAPH}> {{ <urn:x> <urn:p> <urn:y> . }}"
    assert client.post("/store", data=body, content_type="application/trig", headers=AUTH).status_code == 204
    assert triples(client.get(f"/store?graph={GRAPH}").data) == {("<urn:x>", "<urn:p>", "<urn:y>")}


def test_writes_need_the_token_and_bad_requests_change_nothing(client: FlaskClient) -> None:
    put = client.put(f"/store?graph={GRAPH}", data="<urn:a> <urn:p> 1 .", content_type=TURTLE)
    assert put.status_code == 403
    assert client.get(f"/store?graph={GRAPH}").status_code == 404
    broken = client.put(f"/store?graph={GRAPH}", data="<urn:a> <urn:p> ", content_type=TURTLE, headers=AUTH)
    assert broken.status_code == 400 and client.get(f"/store?graph={GRAPH}").status_code == 404
    whole = client.put("/store", data="<urn:a> <urn:p> 1 .", content_type=TURTLE, headers=AUTH)
    assert whole.status_code == 400 and "?graph=IRI or ?default" in whole.get_json()["message"]
    wrong_type = client.put(f"/store?graph={GRAPH}", data="x", content_type="image/png", headers=AUTH)
    assert wrong_type.status_code == 415 and "text/turtle" in wrong_type.get_json()["message"]  # as /update's
    assert client.get("/store?graph=notes").status_code == 400  # not an absolute IRI
    assert client.get(f"/store?graph={GRAPH}&default").status_code == 400
    refused = client.get("/store?graph=https://w3id.org/cbrs/graph/services", headers={"Accept": "image/png"})
    assert refused.status_code == 406


def test_a_description_written_through_the_graph_store_passes_the_shapes(client: FlaskClient) -> None:
    typo = """@prefix cbrs: <https://w3id.org/cbrs/core#> . @prefix home: <https://w3id.org/cbrs/home#> .
    <urn:x:Locate> a cbrs:DynamicPerceptionComponent ; cbrs:deviceName "C" ; cbrs:serviceName "Locate" ;
      cbrs:hasOWLSModel [ a cbrs:OWLSModel ; cbrs:hasOutput [ a cbrs:Parameter ; cbrs:parameterName "l" ;
      cbrs:parameterType home:RobotLocaton ] ] ."""
    before = client.get("/store?graph=https://w3id.org/cbrs/graph/services").data
    posted = client.post(
        "/store?graph=https://w3id.org/cbrs/graph/services", data=typo, content_type=TURTLE, headers=AUTH
    )
    assert posted.status_code == 400 and "RobotLocation" in posted.get_json()["message"]  # its did-you-mean
    assert client.get("/store?graph=https://w3id.org/cbrs/graph/services").data == before


def test_a_write_through_the_graph_store_reaches_the_standard_terms(client: FlaskClient) -> None:
    """graph:entailed follows /store writes as it follows /update: a camera put in a graph is a sosa:Sensor."""
    sensors = "SELECT ?s WHERE { GRAPH ?g { ?s a <http://www.w3.org/ns/sosa/Sensor> } }"
    camera = "<urn:test:camera9> a <https://w3id.org/cbrs/home#CeilingCamera> ."

    def found() -> set[str]:
        answer = client.post("/sparql", data={"query": sensors}, headers={"Accept": "application/sparql-results+json"})
        return {row["s"]["value"] for row in answer.get_json()["results"]["bindings"]}

    assert "urn:test:camera9" not in found()
    assert client.put(f"/store?graph={GRAPH}", data=camera, content_type=TURTLE, headers=AUTH).status_code == 201
    assert "urn:test:camera9" in found()
    assert client.delete(f"/store?graph={GRAPH}", headers=AUTH).status_code == 204
    assert "urn:test:camera9" not in found()


# A lab declares home:Fruit (in its graph, as a lab adds a term to home:); another's banana is under it.
FRUIT_PREFIXES = (
    "@prefix home: <https://w3id.org/cbrs/home#> . @prefix lab: <https://example.org/lab#> .\n"
    "@prefix owl: <http://www.w3.org/2002/07/owl#> . @prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> .\n"
)
FRUIT = FRUIT_PREFIXES + "home:Fruit a owl:Class ; rdfs:subClassOf home:PhysicalObject .\n"
BANANA = FRUIT_PREFIXES + "lab:Banana rdfs:subClassOf home:Fruit .\n"
EIGHT, NINE = "https://example.org/lab/eight", "https://example.org/lab/nine"


def _refused(answer: TestResponse, kind: str, *words: str) -> None:
    assert answer.status_code == 400, answer.data
    body = answer.get_json()
    assert body["error"] == kind and all(word in body["message"] for word in words), body
    assert body["message"].endswith("nothing was written")


def _superclasses_are_checked(client: FlaskClient, store: Store) -> None:
    """What the Graph Store Protocol's writes refuse, as INSERT DATA and DELETE DATA of the same statements
    are refused, on ``store``: a class under an undeclared term, and the last declaration of a term a class
    stays under; each leaves ``store`` as it was."""
    before = store.dump()
    banana = client.post(f"/store?graph={NINE}", data=BANANA, content_type=TURTLE, headers=AUTH)
    _refused(banana, "UndeclaredSuperclassError", f"the POST to graph <{NINE}>: ", "Banana")
    assert store.dump() == before
    assert client.put(f"/store?graph={EIGHT}", data=FRUIT, content_type=TURTLE, headers=AUTH).status_code == 201
    assert client.post(f"/store?graph={NINE}", data=BANANA, content_type=TURTLE, headers=AUTH).status_code == 204
    held = store.dump()
    renamed = FRUIT.replace("home:Fruit", "home:Fruits")  # the graph replaced by one without home:Fruit
    put = client.put(f"/store?graph={EIGHT}", data=renamed, content_type=TURTLE, headers=AUTH)
    _refused(
        put, "RemovedDeclarationError", "the PUT of graph <https://example.org/lab/eight>: ", "home:Fruit", "Banana"
    )
    dropped = client.delete(f"/store?graph={EIGHT}", headers=AUTH)
    _refused(dropped, "RemovedDeclarationError", f"the DELETE of graph <{EIGHT}>: ", "Banana")
    assert store.dump() == held
    # the way there in steps, each leaving every class under a declared term: the new term, the classes
    # re-pointed, the old term gone
    both = FRUIT + renamed.removeprefix(FRUIT_PREFIXES)
    assert client.put(f"/store?graph={EIGHT}", data=both, content_type=TURTLE, headers=AUTH).status_code == 204
    moved = BANANA.replace("home:Fruit", "home:Fruits")
    assert client.put(f"/store?graph={NINE}", data=moved, content_type=TURTLE, headers=AUTH).status_code == 204
    assert client.put(f"/store?graph={EIGHT}", data=renamed, content_type=TURTLE, headers=AUTH).status_code == 204
    assert client.delete(f"/store?graph={NINE}", headers=AUTH).status_code == 204
    assert client.delete(f"/store?graph={EIGHT}", headers=AUTH).status_code == 204


def test_a_write_leaving_a_class_under_an_undeclared_term_is_refused_as_an_update_is() -> None:
    kb = KnowledgeBase.open(":memory:")
    try:
        app = create_app(SparqlService(kb, EndpointConfig(update_token=TOKEN, isolate=False)))
        _superclasses_are_checked(app.test_client(), kb.store)
    finally:
        kb.close()


def test_a_remote_store_behind_the_graph_store_is_checked_as_well(
    remote_location: str, oxigraph_server: OxigraphServer
) -> None:
    put_quads(oxigraph_server, seeded_quads())
    kb = KnowledgeBase.open(remote_location)
    try:
        app = create_app(SparqlService(kb, EndpointConfig(update_token=TOKEN, isolate=False)))
        _superclasses_are_checked(app.test_client(), kb.store)
    finally:
        kb.close()
