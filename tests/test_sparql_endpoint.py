"""The SPARQL 1.1 Protocol endpoint: Flask's test client for the protocol, real clients over loopback."""

from __future__ import annotations

import json
import threading
import time
import urllib.error
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pyoxigraph as ox
import pytest
from flask.testing import FlaskClient
from waitress import wasyncore
from waitress.server import create_server

from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import GraphName, expand
from cbrs.sparql_service import (
    EndpointBusyError,
    EndpointConfig,
    QueryTimeoutError,
    ResultTooLargeError,
    SparqlService,
    negotiate,
)
from cbrs.web import create_app

TOKEN = "correct horse battery staple"
SELECT = "SELECT ?ad WHERE { ?ad a cbrs:DynamicPerceptionComponent } ORDER BY ?ad LIMIT 3"
CONSTRUCT = (
    "CONSTRUCT { ?ad a cbrs:DynamicPerceptionComponent } WHERE { ?ad a cbrs:DynamicPerceptionComponent } LIMIT 3"
)
INSERT = "INSERT DATA { GRAPH <urn:test:g> { <urn:test:s> <urn:test:p> 'added' } }"
ASK_ADDED = "ASK { <urn:test:s> <urn:test:p> 'added' }"
# Slow on purpose, but finite (about a second here): a count over a product of 2000 x 2000 solutions.
SLOW = (
    "SELECT (COUNT(*) AS ?n) WHERE { { SELECT ?a WHERE { ?a ?p ?x } LIMIT 2000 } "
    "{ SELECT ?b WHERE { ?b ?q ?y } LIMIT 2000 } FILTER (?a != ?b) }"
)


def make_client(kb: KnowledgeBase, **config: Any) -> FlaskClient:
    cors = config.pop("cors", ())
    return create_app(SparqlService(kb, EndpointConfig(**config)), cors).test_client()


@pytest.fixture
def client(bundled_kb: KnowledgeBase) -> FlaskClient:
    return make_client(bundled_kb)


@pytest.fixture
def writable(fresh_bundled_kb: KnowledgeBase) -> tuple[FlaskClient, KnowledgeBase]:
    return make_client(fresh_bundled_kb, update_token=TOKEN), fresh_bundled_kb


def test_select_by_get_answers_sparql_json_by_default(client: FlaskClient) -> None:
    response = client.get("/sparql", query_string={"query": SELECT})
    assert response.status_code == 200
    assert response.mimetype == "application/sparql-results+json"
    body = response.get_json()
    assert body["head"]["vars"] == ["ad"]
    assert len(body["results"]["bindings"]) == 3


@pytest.mark.parametrize(
    ("accept", "media_type", "format_"),
    [
        ("application/sparql-results+xml", "application/sparql-results+xml", ox.QueryResultsFormat.XML),
        ("text/csv", "text/csv", ox.QueryResultsFormat.CSV),
        ("text/tab-separated-values", "text/tab-separated-values", ox.QueryResultsFormat.TSV),
        ("application/json;q=0.5, application/sparql-results+xml;q=0.9", "application/sparql-results+xml", None),
    ],
)
def test_select_negotiates_each_results_format(
    client: FlaskClient, accept: str, media_type: str, format_: ox.QueryResultsFormat | None
) -> None:
    response = client.get("/sparql", query_string={"query": SELECT}, headers={"Accept": accept})
    assert response.status_code == 200
    assert response.mimetype == media_type
    if format_ is not None and format_ != ox.QueryResultsFormat.CSV:  # CSV loses term kinds, still parses
        solutions = ox.parse_query_results(response.data, format_)
        assert isinstance(solutions, ox.QuerySolutions)
        assert len(list(solutions)) == 3
    elif format_ is ox.QueryResultsFormat.CSV:
        assert response.data.decode().splitlines()[0] == "ad"


def test_post_form_and_direct_query_give_the_same_answer(client: FlaskClient) -> None:
    by_get = client.get("/sparql", query_string={"query": SELECT}).data
    by_form = client.post("/sparql", data={"query": SELECT})
    direct = client.post("/sparql", data=SELECT.encode(), content_type="application/sparql-query")
    assert by_form.status_code == direct.status_code == 200
    assert by_form.data == direct.data == by_get


@pytest.mark.parametrize(
    ("accept", "rdf_format"),
    [
        ("text/turtle", ox.RdfFormat.TURTLE),
        ("application/n-triples", ox.RdfFormat.N_TRIPLES),
        ("application/ld+json", ox.RdfFormat.JSON_LD),
        ("application/rdf+xml", ox.RdfFormat.RDF_XML),
    ],
)
def test_construct_negotiates_each_rdf_format(client: FlaskClient, accept: str, rdf_format: ox.RdfFormat) -> None:
    response = client.get("/sparql", query_string={"query": CONSTRUCT}, headers={"Accept": accept})
    assert response.status_code == 200
    assert response.mimetype == accept
    triples = list(ox.parse(response.data, format=rdf_format))
    assert len(triples) == 3
    assert {t.object.value for t in triples} == {"https://w3id.org/cbrs/core#DynamicPerceptionComponent"}


def test_format_parameter_as_sparqlwrapper_sends_it(client: FlaskClient) -> None:
    response = client.get("/sparql", query_string={"query": SELECT, "format": "xml"})
    assert response.mimetype == "application/sparql-results+xml"
    graph = client.get("/sparql", query_string={"query": CONSTRUCT, "format": "json"})
    assert graph.mimetype == "application/ld+json"


def test_unacceptable_media_type_is_406(client: FlaskClient) -> None:
    response = client.get("/sparql", query_string={"query": SELECT}, headers={"Accept": "image/png"})
    assert response.status_code == 406
    assert "application/sparql-results+json" in response.get_json()["message"]


def test_malformed_query_is_400_with_the_parser_message(client: FlaskClient) -> None:
    response = client.get("/sparql", query_string={"query": "SELECT ?x WHERE { ?x ?y }"})
    assert response.status_code == 400
    body = response.get_json()
    assert body["error"] == "QuerySyntaxError"
    assert "1:" in body["message"]  # the parser's line:column


def test_update_on_a_read_only_server_is_403_and_changes_nothing(bundled_kb: KnowledgeBase) -> None:
    client = make_client(bundled_kb)
    before = bundled_kb.store.dump()
    response = client.post("/sparql", data={"update": INSERT}, headers={"Authorization": f"Bearer {TOKEN}"})
    assert response.status_code == 403
    assert "read-only" in response.get_json()["message"]
    assert bundled_kb.store.dump() == before


@pytest.mark.parametrize("authorization", [None, "Bearer wrong", f"Basic {TOKEN}", "Bearer"])
def test_update_without_the_token_is_403_and_changes_nothing(
    writable: tuple[FlaskClient, KnowledgeBase], authorization: str | None
) -> None:
    client, kb = writable
    before = kb.store.dump()
    headers = {"Authorization": authorization} if authorization else {}
    response = client.post("/update", data=INSERT.encode(), content_type="application/sparql-update", headers=headers)
    assert response.status_code == 403
    assert kb.store.dump() == before
    sent_wrong = authorization == "Bearer wrong"
    assert ("not this server's update token" in response.get_data(as_text=True)) is sent_wrong
    assert ("Authorization: Bearer <token>" in response.get_data(as_text=True)) is not sent_wrong


@pytest.mark.parametrize("how", ["form-sparql", "direct-sparql", "direct-update"])
def test_update_with_the_token_succeeds(writable: tuple[FlaskClient, KnowledgeBase], how: str) -> None:
    client, kb = writable
    headers = {"Authorization": f"Bearer {TOKEN}"}
    if how == "form-sparql":
        response = client.post("/sparql", data={"update": INSERT}, headers=headers)
    else:
        path = "/sparql" if how == "direct-sparql" else "/update"
        response = client.post(path, data=INSERT.encode(), content_type="application/sparql-update", headers=headers)
    assert response.status_code == 204
    assert bool(kb.query(ASK_ADDED))


def test_an_update_that_fails_midway_changes_nothing(writable: tuple[FlaskClient, KnowledgeBase]) -> None:
    client, kb = writable
    before = kb.store.dump()
    failing = INSERT + f" ; CREATE GRAPH <{GraphName.ONTOLOGY.iri}>"  # that graph exists
    response = client.post("/sparql", data={"update": failing}, headers={"Authorization": f"Bearer {TOKEN}"})
    assert response.status_code == 400
    assert "already exists" in response.get_json()["message"]
    assert kb.store.dump() == before


def test_an_update_refreshes_what_the_knowledge_base_has_read(writable: tuple[FlaskClient, KnowledgeBase]) -> None:
    client, kb = writable
    iri = expand("svc:LocateMobileRobot_CeilingCamera01")
    assert kb.description(iri).label
    drop = f"DELETE WHERE {{ GRAPH ?g {{ <{iri}> <http://www.w3.org/2000/01/rdf-schema#label> ?label }} }}"
    response = client.post("/update", data=drop.encode(), content_type="application/sparql-update",
                           headers={"Authorization": f"Bearer {TOKEN}"})  # fmt: skip
    assert response.status_code == 204
    assert not kb.description(iri).label


def test_oversized_request_is_413(bundled_kb: KnowledgeBase) -> None:
    client = make_client(bundled_kb, max_query_bytes=1000)
    padded = SELECT + " #" + "x" * 2000
    assert client.post("/sparql", data=padded.encode(), content_type="application/sparql-query").status_code == 413
    huge = client.post("/sparql", data=b"x" * 10_000, content_type="application/sparql-query")
    assert huge.status_code == 413
    assert huge.get_json()["error"]


def test_result_over_the_size_limit_is_422(bundled_kb: KnowledgeBase) -> None:
    client = make_client(bundled_kb, max_result_bytes=10_000)
    response = client.get("/sparql", query_string={"query": "SELECT * WHERE { ?s ?p ?o }"})
    assert response.status_code == 422
    assert "LIMIT" in response.get_json()["message"]
    assert client.get("/sparql", query_string={"query": SELECT}).status_code == 200


def test_query_past_the_timeout_is_503(bundled_kb: KnowledgeBase) -> None:
    client = make_client(bundled_kb, timeout=0.2, workers=1)
    start = time.monotonic()
    response = client.get("/sparql", query_string={"query": SLOW})
    assert response.status_code == 503
    assert response.get_json()["error"] == "timeout"
    assert time.monotonic() - start < 5
    # The abandoned query still holds the only worker, so the next query is refused at once as busy.
    busy = client.get("/sparql", query_string={"query": SELECT})
    assert busy.status_code == 503
    assert busy.get_json()["error"] == "busy"


def test_protocol_misuse_gets_a_clear_4xx(client: FlaskClient) -> None:
    both = client.post("/sparql", data={"query": SELECT, "update": INSERT})
    assert both.status_code == 400 and "not both" in both.get_json()["message"]
    assert client.get("/sparql", query_string={"update": INSERT}).status_code == 400
    wrong_type = client.post("/sparql", data=b"{}", content_type="application/json")
    assert wrong_type.status_code == 415
    dataset = client.get("/sparql", query_string={"query": SELECT, "default-graph-uri": "not an iri"})
    assert dataset.status_code == 400 and "default-graph-uri" in dataset.get_json()["message"]
    assert client.put("/sparql").status_code == 405
    assert client.post("/update", data={"query": SELECT}).status_code == 400


def test_cors_is_off_unless_an_origin_is_allowed(bundled_kb: KnowledgeBase) -> None:
    closed = make_client(bundled_kb)
    response = closed.get("/sparql", query_string={"query": SELECT}, headers={"Origin": "http://page.example"})
    assert "Access-Control-Allow-Origin" not in response.headers
    open_ = make_client(bundled_kb, cors=["http://page.example"])
    allowed = open_.get("/sparql", query_string={"query": SELECT}, headers={"Origin": "http://page.example"})
    assert allowed.headers["Access-Control-Allow-Origin"] == "http://page.example"
    other = open_.get("/sparql", query_string={"query": SELECT}, headers={"Origin": "http://evil.example"})
    assert "Access-Control-Allow-Origin" not in other.headers
    preflight = open_.options("/sparql", headers={"Origin": "http://page.example"})
    assert preflight.status_code == 204
    assert "Authorization" in preflight.headers["Access-Control-Allow-Headers"]


def test_get_without_a_query_describes_the_service(client: FlaskClient) -> None:
    response = client.get("/sparql")
    assert response.status_code == 200
    triples = list(ox.parse(response.data, format=ox.RdfFormat.TURTLE))
    sd = "http://www.w3.org/ns/sparql-service-description#"
    assert any(t.predicate.value == sd + "endpoint" and t.object.value.endswith("/sparql") for t in triples)
    assert not any(t.object.value == sd + "SPARQL11Update" for t in triples)  # read-only


def test_negotiation_prefers_the_format_parameter_then_accept() -> None:
    assert negotiate(False, None) == "application/sparql-results+json"
    assert negotiate(True, None) == "text/turtle"
    assert negotiate(False, "text/csv", "json") == "application/sparql-results+json"
    assert negotiate(True, "*/*") == "text/turtle"


# -- real clients over loopback ------------------------------------------------------------------


@pytest.fixture
def live(fresh_bundled_kb: KnowledgeBase) -> Iterator[tuple[str, KnowledgeBase]]:
    """The endpoint on waitress at a free loopback port, stopped (bounded) after the test."""
    service = SparqlService(fresh_bundled_kb, EndpointConfig(update_token=TOKEN))
    sockets: dict[int, Any] = {}
    server = create_server(create_app(service), host="127.0.0.1", port=0, map=sockets, threads=4)
    thread = threading.Thread(target=server.run, daemon=True)
    thread.start()
    yield f"http://127.0.0.1:{server.effective_port}", fresh_bundled_kb
    server.task_dispatcher.shutdown(timeout=5)
    server.trigger.pull_trigger(lambda: wasyncore.close_all(sockets))
    thread.join(5)
    assert not thread.is_alive()


@pytest.mark.parametrize("return_format", ["json", "xml"])
def test_sparqlwrapper_selects_in_json_and_xml(live: tuple[str, KnowledgeBase], return_format: str) -> None:
    from SPARQLWrapper import SPARQLWrapper

    url, _ = live
    client = SPARQLWrapper(url + "/sparql")
    client.setTimeout(10)
    client.setQuery("PREFIX cbrs: <https://w3id.org/cbrs/core#>\n" + SELECT)
    client.setReturnFormat(return_format)
    converted = client.query().convert()
    if return_format == "json":
        rows = [b["ad"]["value"] for b in converted["results"]["bindings"]]
    else:
        rows = [node.firstChild.data for node in converted.getElementsByTagName("uri")]
    assert len(rows) == 3
    assert all(r.startswith(expand("svc:")) for r in rows)


def test_sparqlwrapper_update_needs_the_token(live: tuple[str, KnowledgeBase]) -> None:
    from SPARQLWrapper import POST, SPARQLWrapper

    url, kb = live
    client = SPARQLWrapper(url + "/sparql", updateEndpoint=url + "/update")
    client.setTimeout(10)
    client.setMethod(POST)
    client.setQuery(INSERT)
    before = kb.store.dump()
    with pytest.raises(urllib.error.HTTPError) as refused:
        client.query()
    assert refused.value.code == 403
    assert json.loads(refused.value.read())["error"] == "forbidden"
    assert kb.store.dump() == before
    client.addCustomHttpHeader("Authorization", f"Bearer {TOKEN}")
    client.query()
    assert bool(kb.query(ASK_ADDED))


def test_rdflib_sparqlstore_reads_select_and_construct(live: tuple[str, KnowledgeBase]) -> None:
    from rdflib import Graph, URIRef
    from rdflib.plugins.stores.sparqlstore import SPARQLStore

    url, _ = live
    graph = Graph(store=SPARQLStore(url + "/sparql", timeout=10))
    prefix = "PREFIX cbrs: <https://w3id.org/cbrs/core#>\n"
    rows = list(graph.query(prefix + SELECT))
    assert len(rows) == 3
    constructed = graph.query(prefix + CONSTRUCT).graph
    assert constructed is not None
    assert len(constructed) == 3
    kind = URIRef("https://w3id.org/cbrs/core#DynamicPerceptionComponent")
    assert set(constructed.objects()) == {kind}


# -- single scans and the hot path (cbrs.scan_queries, cbrs.web.sparql_wsgi) ----------------------------

LOOKUP = "SELECT ?p ?o WHERE { home:Cup ?p ?o }"


@pytest.mark.parametrize(
    ("text", "scan"),
    [
        pytest.param("SELECT ?p ?o WHERE { <urn:x> ?p ?o }", True, id="subject-lookup"),
        pytest.param("PREFIX ex: <http://e/#>\nselect * { ex:x ?p ?o . } LIMIT 5", True, id="prologue-star-limit"),
        pytest.param("SELECT ?s WHERE { ?s a home:Cup }", True, id="a-and-pname"),
        pytest.param('ASK { ?s rdfs:label "cup"@en }', True, id="ask-literal"),
        pytest.param("SELECT ?o FROM <urn:g> WHERE { <urn:x> <urn:p> ?o }", True, id="from"),
        pytest.param("ASK {}", True, id="empty-group"),
        pytest.param("SELECT ?s ?p ?o WHERE { ?s ?p ?o }", False, id="whole-store"),
        pytest.param("SELECT ?x WHERE { ?x <urn:p> ?x }", False, id="repeated-variable"),
        pytest.param("SELECT ?p ?o WHERE { <urn:x> ?p ?o } OFFSET 10", False, id="offset"),
        pytest.param("SELECT DISTINCT ?p WHERE { <urn:x> ?p ?o }", False, id="distinct"),
        pytest.param("SELECT ?p ?o WHERE { <urn:x> ?p ?o } ORDER BY ?o", False, id="order"),
        pytest.param("SELECT ?o WHERE { <urn:x> <urn:p>* ?o }", False, id="path"),
        pytest.param("SELECT ?o WHERE { <urn:x> ?p ?o FILTER(?o > 1) }", False, id="filter"),
        pytest.param("SELECT ?o WHERE { <urn:x> ?p ?o . ?o ?q ?r }", False, id="join"),
        pytest.param("SELECT ?o WHERE { <urn:x> ?p ?o } # comment", False, id="comment"),
        pytest.param("SELECT ?o WHERE { _:b ?p ?o }", False, id="blank-node"),
        pytest.param("SELECT (COUNT(*) AS ?n) WHERE { <urn:x> ?p ?o }", False, id="aggregate"),
        pytest.param("SELECT ?o WHERE { SERVICE <http://e/> { <urn:x> ?p ?o } }", False, id="service"),
        pytest.param("DESCRIBE <urn:x>", False, id="describe"),
    ],
)
def test_single_scans_are_recognised_strictly(text: str, scan: bool) -> None:
    from cbrs.scan_queries import is_single_scan

    assert is_single_scan(text) is scan


@pytest.mark.parametrize(
    ("method", "path", "headers", "data"),
    [
        pytest.param("GET", f"/sparql?query={LOOKUP}", {}, None, id="get-lookup"),
        pytest.param("HEAD", f"/sparql?query={LOOKUP}", {}, None, id="head-lookup"),
        pytest.param("GET", f"/sparql?query={SELECT}&format=xml", {}, None, id="get-format-worker"),
        pytest.param("GET", f"/sparql?query={LOOKUP}", {"Accept": "text/csv"}, None, id="accept-csv"),
        pytest.param("GET", f"/sparql?query={LOOKUP}", {"Accept": "text/nope"}, None, id="not-acceptable"),
        pytest.param("GET", "/sparql?query=SELECT%20%3Fx%20WHERE%20%7B", {}, None, id="syntax-error"),
        pytest.param("GET", f"/sparql?query={LOOKUP}&output=tsv", {}, None, id="output"),
        pytest.param("GET", f"/sparql?query={LOOKUP}&query=ASK{{}}", {}, None, id="two-queries"),
        pytest.param("GET", f"/sparql?query={LOOKUP}", {"Origin": "http://other.example"}, None, id="origin"),
        pytest.param("POST", "/sparql", {"Content-Type": "application/sparql-query"}, LOOKUP, id="post-direct"),
        pytest.param("POST", "/sparql", {"Content-Type": "application/sparql-query"}, b"\xff", id="post-not-utf8"),
        pytest.param("POST", "/sparql", {"Content-Type": "text/plain"}, LOOKUP, id="post-wrong-type"),
        pytest.param("GET", "/sparql", {}, None, id="service-description"),
    ],
)
def test_the_hot_path_answers_as_the_flask_view_does(
    bundled_kb: KnowledgeBase, method: str, path: str, headers: dict[str, str], data: str | bytes | None
) -> None:
    from werkzeug.test import Client

    app = create_app(SparqlService(bundled_kb, EndpointConfig()), own_origins=lambda: {"http://127.0.0.1:8080"})
    hot, flask_only = Client(app.wsgi_app), Client(app.wsgi_app.app)  # type: ignore[attr-defined]
    headers = {"Host": "127.0.0.1:8080", **headers}
    answers = [c.open(path, method=method, headers=headers, data=data) for c in (hot, flask_only)]
    assert answers[0].status == answers[1].status
    assert answers[0].headers == answers[1].headers
    assert answers[0].data == answers[1].data


def test_the_hot_path_leaves_a_foreign_host_to_the_rebinding_check(bundled_kb: KnowledgeBase) -> None:
    app = create_app(SparqlService(bundled_kb, EndpointConfig()), own_origins=lambda: {"http://127.0.0.1:8080"})
    response = app.test_client().get("/sparql", query_string={"query": LOOKUP}, headers={"Host": "evil.example"})
    assert response.status_code == 421


def test_a_single_scan_takes_no_query_worker_but_counts_against_the_client_share(bundled_kb: KnowledgeBase) -> None:
    service = SparqlService(bundled_kb, EndpointConfig(workers=1, workers_per_client=1))
    release = service._admit("127.0.0.2")  # another client holds the only worker
    try:
        answer = service.query(LOOKUP, client="127.0.0.3")
        assert json.loads(answer.body)["results"]["bindings"]
        held = service._admit("127.0.0.3", slot=False)  # this client is at its share of one
        try:
            with pytest.raises(EndpointBusyError, match=r"127\.0\.0\.3 already runs 1"):
                service.query(LOOKUP, client="127.0.0.3")
        finally:
            held()
    finally:
        release()


def test_a_single_scan_stops_at_the_byte_limit_and_the_deadline(
    bundled_kb: KnowledgeBase, monkeypatch: pytest.MonkeyPatch
) -> None:
    scan_all_types = "SELECT ?s ?t WHERE { ?s a ?t }"  # one scan, every typed node of the bundled data
    small = SparqlService(bundled_kb, EndpointConfig(max_result_bytes=2000))
    with pytest.raises(ResultTooLargeError):
        small.query(scan_all_types)
    clock = iter(float(second) for second in range(10**6))  # each look at the clock: one second later
    monkeypatch.setattr("cbrs.sparql_service.time.monotonic", lambda: next(clock))
    with pytest.raises(QueryTimeoutError):
        SparqlService(bundled_kb, EndpointConfig(timeout=5.0)).query(scan_all_types)


def test_an_idle_query_worker_is_stopped_and_a_later_query_starts_another(tmp_path: Path) -> None:
    kb = KnowledgeBase.open(tmp_path / "store")
    service = SparqlService(kb, EndpointConfig(worker_idle=0.2))
    try:
        assert service.processes is not None
        assert json.loads(service.query(SELECT).body)["results"]["bindings"]  # not a single scan: a worker
        assert len(service.processes._idle) == 1
        worker = service.processes._idle[0]
        deadline = time.monotonic() + 20
        while service.processes._idle and time.monotonic() < deadline:
            time.sleep(0.05)
        assert service.processes._idle == []
        assert worker.popen.wait(timeout=10) is not None  # the process has ended
        assert json.loads(service.query(SELECT).body)["results"]["bindings"]
    finally:
        service.close()
        kb.close()


def test_an_in_memory_store_served_isolated_stops_a_query_at_its_deadline(fresh_bundled_kb: KnowledgeBase) -> None:
    if not fresh_bundled_kb.store.in_memory:
        pytest.skip("the in-memory store's case")
    service = SparqlService(fresh_bundled_kb, EndpointConfig(isolate_memory=True, timeout=0.5, workers=1))
    try:
        assert service.processes is not None
        with pytest.raises(QueryTimeoutError, match="it was stopped"):
            service.query(SLOW)
        assert service.processes.killed == 1
        answer = service.query("SELECT (COUNT(*) AS ?n) WHERE { ?s ?p ?o }")  # the one slot is free again
        assert int(json.loads(answer.body)["results"]["bindings"][0]["n"]["value"]) > 1000
        fresh_bundled_kb.update(INSERT)  # a write reaches the next snapshot, copied afresh (a filter: a worker's)
        assert json.loads(service.query("ASK { <urn:test:s> ?p 'added' FILTER(?p != <urn:x>) }").body)["boolean"]
    finally:
        service.close()
