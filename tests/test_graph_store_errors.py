"""The Graph Store Protocol (/store) refuses a mistake as the SPARQL endpoint (/sparql, /update) refuses the
same kind of mistake: one status, one error name, one body form (docs/serving.md's table of errors).

A lab's integrator using curl found /store's own names: 406 ``NotAcceptableFormatError`` where /sparql says
``not-acceptable``, and 400 ``GraphStoreError`` for curl's default form type where /update answers 415."""

from __future__ import annotations

from collections.abc import Iterator

import pytest
from flask.testing import FlaskClient
from werkzeug.test import TestResponse

from cbrs.graph_store import Target
from cbrs.kb import KnowledgeBase
from cbrs.sparql_service import BadDatasetError, EndpointConfig, SparqlService
from cbrs.web import create_app

TOKEN = "graph-store-errors"
AUTH = {"Authorization": f"Bearer {TOKEN}"}
GRAPH = "urn:test:errors"
SERVICES = "https://w3id.org/cbrs/graph/services"
CBRS, HOME = "https://w3id.org/cbrs/core#", "https://w3id.org/cbrs/home#"
FORM = "application/x-www-form-urlencoded"
TRIPLE = "<urn:a> <urn:p> 1 ."
GRAPH_TYPES = ("text/turtle", "application/n-triples", "application/rdf+xml", "application/ld+json", "text/n3")


@pytest.fixture(scope="module")
def client() -> Iterator[FlaskClient]:
    kb = KnowledgeBase.open(":memory:")
    service = SparqlService(kb, EndpointConfig(update_token=TOKEN, isolate=False, max_query_bytes=4096))
    app = create_app(service)
    test_client = app.test_client()
    assert test_client.put(
        f"/store?graph={GRAPH}", data=TRIPLE, content_type="text/turtle", headers=AUTH
    ).status_code in (
        201,
        204,
    )
    yield test_client
    service.close()


def _said(answer: TestResponse) -> tuple[int, str, str]:
    body = answer.get_json()
    assert isinstance(body, dict) and set(body) <= {"error", "message", "notes"}, answer.get_data(as_text=True)
    return answer.status_code, body["error"], body["message"]


def test_a_format_it_cannot_write_is_not_acceptable_as_on_the_endpoint(client: FlaskClient) -> None:
    asked = {"Accept": "application/sparql-results+json"}
    endpoint = client.get("/sparql", query_string={"query": "CONSTRUCT WHERE { ?s ?p ?o } LIMIT 1"}, headers=asked)
    store = client.get(f"/store?graph={GRAPH}", headers=asked)
    (status, kind, message), (endpoint_status, endpoint_kind, endpoint_message) = _said(store), _said(endpoint)
    assert (status, kind) == (endpoint_status, endpoint_kind) == (406, "not-acceptable")
    assert message.startswith("cannot answer in 'application/sparql-results+json'; this result is available as ")
    assert endpoint_message.startswith(
        "cannot answer in 'application/sparql-results+json'; this result is available as "
    )
    assert all(media in message for media in GRAPH_TYPES)  # every type /store writes, not the endpoint's first four
    dataset = client.get("/store", headers={"Accept": "text/turtle"})  # the whole store: TriG or N-Quads only
    assert (
        _said(dataset)[:2] == (406, "not-acceptable") and "application/trig, application/n-quads" in _said(dataset)[2]
    )


@pytest.mark.parametrize(
    ("content_type", "shown"),
    [(FORM, FORM), (None, "(none)"), ("image/png", "image/png")],
    ids=["curl's form type", "none", "an image"],
)
def test_a_body_of_a_type_it_cannot_read_is_415_naming_the_type_and_the_types_taken(
    client: FlaskClient, content_type: str | None, shown: str
) -> None:
    endpoint = client.post(  # the endpoint takes a form, not Turtle: its 415
        "/update", data=TRIPLE, content_type=content_type if content_type != FORM else "text/turtle", headers=AUTH
    )
    assert _said(endpoint)[:2] == (415, "unsupported-media-type")
    for method in (client.post, client.put):
        answer = method(f"/store?graph={GRAPH}", data=TRIPLE, content_type=content_type, headers=AUTH)
        status, kind, message = _said(answer)
        assert (status, kind) == (415, "unsupported-media-type"), message
        assert f"not {shown!r}" in message and all(media in message for media in GRAPH_TYPES)
    if content_type == FORM:  # what curl --data-binary sends unless told: the refusal says how to tell it
        assert "-H 'Content-Type: text/turtle'" in message
    assert client.get(f"/store?graph={GRAPH}", headers={"Accept": "application/n-triples"}).data.count(b"\n") == 1


def test_triples_posted_to_the_whole_store_are_415_naming_the_dataset_types(client: FlaskClient) -> None:
    status, kind, message = _said(client.post("/store", data=TRIPLE, content_type="text/turtle", headers=AUTH))
    assert (status, kind) == (415, "unsupported-media-type")
    assert "application/trig or application/n-quads, not 'text/turtle'" in message and "?graph=IRI" in message


def test_a_wrong_type_without_the_token_is_refused_for_its_type_first_as_on_the_endpoint(client: FlaskClient) -> None:
    endpoint = client.post("/update", data="INSERT DATA { <urn:a> <urn:p> 1 }", content_type="image/png")
    store = client.post(f"/store?graph={GRAPH}", data=TRIPLE, content_type="image/png")
    assert _said(endpoint)[:2] == _said(store)[:2] == (415, "unsupported-media-type")


@pytest.mark.parametrize("headers", [{}, {"Authorization": "Bearer not-the-token"}], ids=["none", "wrong"])
def test_a_missing_or_wrong_token_is_refused_alike(client: FlaskClient, headers: dict[str, str]) -> None:
    endpoint = client.post(
        "/update", data="INSERT DATA { <urn:a> <urn:p> 1 }", content_type="application/sparql-update", headers=headers
    )
    for answer in (
        client.put(f"/store?graph={GRAPH}", data=TRIPLE, content_type="text/turtle", headers=headers),
        client.post(f"/store?graph={GRAPH}", data=TRIPLE, content_type="text/turtle", headers=headers),
        client.delete(f"/store?graph={GRAPH}", headers=headers),
    ):
        assert _said(answer) == _said(endpoint)
        assert _said(answer)[:2] == (403, "forbidden")


def test_a_body_past_the_request_limit_is_refused_alike(client: FlaskClient) -> None:
    too_big = "x" * (3 * 4096 + 4096 + 1)  # past Flask's limit, 3 x max_query_bytes and 4 KiB
    endpoint = client.post(
        "/update", data=f'INSERT DATA {{ <urn:a> <urn:p> "{too_big}" }}', content_type="application/sparql-update"
    )
    store = client.post(f"/store?graph={GRAPH}", data=f'<urn:a> <urn:p> "{too_big}" .', content_type="text/turtle")
    assert _said(store) == _said(endpoint) and _said(store)[0] == 413


def test_a_graph_that_is_no_iri_is_named_as_the_endpoint_names_a_dataset_parameter(client: FlaskClient) -> None:
    endpoint = client.get("/sparql", query_string={"query": "ASK {}", "default-graph-uri": "http://a b"})
    endpoint_status, endpoint_kind, endpoint_message = _said(endpoint)
    with pytest.raises(BadDatasetError) as refused:
        Target.from_parameters(["http://a b"], False)
    assert (refused.value.http_status, refused.value.kind) == (endpoint_status, endpoint_kind) == (400, "bad-dataset")
    assert str(refused.value) == endpoint_message.replace("default-graph-uri=", "graph=")
    with pytest.raises(BadDatasetError, match=r"graph='graph:map' .*https://w3id.org/cbrs/graph/NAME"):
        Target.from_parameters(["graph:map"], False)  # cbrs's prefix, not a scheme
    assert Target.from_parameters(["tag:lab.example,2026:notes"], False).graph == "tag:lab.example,2026:notes"


def test_a_refused_description_says_nothing_was_written_as_the_update_does(client: FlaskClient) -> None:
    statements = """<urn:x:Locate> a cbrs:DynamicPerceptionComponent ; cbrs:deviceName "C" ;
      cbrs:serviceName "Locate" ; cbrs:hasOWLSModel <urn:x:Locate#m> .
    <urn:x:Locate#m> a cbrs:OWLSModel ; cbrs:hasOutput <urn:x:Locate#o> .
    <urn:x:Locate#o> a cbrs:Parameter ; cbrs:parameterName "l" ; cbrs:parameterType home:RobotLocaton ."""
    typo = f"@prefix cbrs: <{CBRS}> . @prefix home: <{HOME}> .\n{statements}"
    update = f"PREFIX cbrs: <{CBRS}> PREFIX home: <{HOME}> INSERT DATA {{ GRAPH <{SERVICES}> {{ {statements} }} }}"
    endpoint = client.post("/update", data=update, content_type="application/sparql-update", headers=AUTH)
    store = client.post(f"/store?graph={SERVICES}", data=typo, content_type="text/turtle", headers=AUTH)
    assert _said(store)[:2] == _said(endpoint)[:2] == (400, "DescriptionShapeError")
    assert endpoint.get_json()["notes"] == ["nothing was changed"]
    assert store.get_json()["notes"] == ["nothing was written"]


def test_the_graph_stores_own_refusals_are_named_as_the_servers_others(client: FlaskClient) -> None:
    whole = _said(client.put("/store", data=TRIPLE, content_type="text/turtle", headers=AUTH))
    assert whole[:2] == (400, "bad-request") and "?graph=IRI or ?default" in whole[2]
    for answer in (client.get("/store?graph=urn:test:none"), client.delete("/store?graph=urn:test:none", headers=AUTH)):
        assert _said(answer) == (404, "not-found", "the store has no graph <urn:test:none>")
    assert _said(client.get("/no-such-path"))[:2] == (404, "not-found")


@pytest.mark.parametrize("graph", ["http://a b", "notes", "graph:map"])
def test_a_graph_parameter_that_is_no_iri_is_a_bad_dataset_on_store_as_on_the_endpoint(
    client: FlaskClient, graph: str
) -> None:
    endpoint = _said(client.get("/sparql", query_string={"query": "ASK {}", "default-graph-uri": "http://a b"}))
    for answer in (
        client.get("/store", query_string={"graph": graph}),
        client.put("/store", query_string={"graph": graph}, data=TRIPLE, content_type="text/turtle", headers=AUTH),
    ):
        status, kind, message = _said(answer)
        assert (status, kind) == endpoint[:2] == (400, "bad-dataset")
        assert message.startswith(f"graph={graph!r} is not an absolute IRI (") and "give a graph's full IRI" in message
