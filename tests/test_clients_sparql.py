"""SPARQL clients other than the ones cbrs was written against, over loopback on a served knowledge base.

What they send that the endpoint once got wrong: media-type parameters in ``Accept``
(``application/sparql-results+json; charset=utf-8`` was a 406), other spellings of the formats
(``application/x-turtle``, ``text/tsv``), q-values on the Graph Store protocol (it took the first type
named), and Oxigraph's layout, where ``/query`` is the query endpoint (cbrs answered with the editor's
HTML). And what a person sends by mistake: an update as a query, a query as an update, a prefix
nobody declared, each answered with a 400 that says so rather than the parser's list of tokens.
"""

from __future__ import annotations

import http.client
import json
import os
import subprocess
import sys
import urllib.parse
import warnings
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest
from websockets.sync.client import connect

from cbrs.kb import KnowledgeBase
from cbrs.server import ServeConfig, Server
from cbrs.sparql_service import EndpointConfig
from tests.conftest import OxigraphServer

TOKEN = "clients-sparql-token"
WAIT = 10.0
SELECT = "SELECT ?c WHERE { ?c rdfs:subClassOf home:Position } ORDER BY ?c"
CONSTRUCT = "CONSTRUCT { ?c rdfs:subClassOf home:Position } WHERE { ?c rdfs:subClassOf home:Position }"
ONTOLOGY = "https://w3id.org/cbrs/graph/ontology"
BROWSER = "text/html,application/xhtml+xml,application/xml;q=0.9,*/*;q=0.8"


@pytest.fixture(scope="module")
def server() -> Iterator[Server]:
    served = Server(
        KnowledgeBase.open(":memory:"),
        ServeConfig(port=0, bridge_port=0, endpoint=EndpointConfig(update_token=TOKEN)),
    )
    served.start()
    yield served
    served.stop(timeout=WAIT)


def ask(
    server: Server, method: str, path: str, body: bytes | None = None, headers: dict[str, str] | None = None
) -> tuple[int, dict[str, str], bytes]:
    connection = http.client.HTTPConnection("127.0.0.1", server.http_port, timeout=WAIT)
    try:
        connection.request(method, path, body=body, headers=headers or {})
        response = connection.getresponse()
        return response.status, {k.lower(): v for k, v in response.getheaders()}, response.read()
    finally:
        connection.close()


def get(server: Server, path: str, query: str, accept: str | None = None) -> tuple[int, dict[str, str], bytes]:
    headers = {"Accept": accept} if accept is not None else {}
    return ask(server, "GET", f"{path}?{urllib.parse.urlencode({'query': query})}", headers=headers)


def media(headers: dict[str, str]) -> str:
    return headers.get("content-type", "").partition(";")[0]


@pytest.mark.parametrize(
    ("query", "accept", "expected"),
    [
        (SELECT, "application/sparql-results+json; charset=utf-8", "application/sparql-results+json"),
        (SELECT, "application/sparql-results+json;charset=UTF-8", "application/sparql-results+json"),
        (SELECT, "text/csv; header=present", "text/csv"),
        (
            SELECT,
            "text/csv;charset=utf-8;q=0.2, application/sparql-results+xml; charset=utf-8;q=0.9",
            "application/sparql-results+xml",
        ),
        (SELECT, "application/x-sparql-results+json", "application/sparql-results+json"),
        (SELECT, "text/tsv", "text/tab-separated-values"),
        (SELECT, "text/csv;q=abc", "text/csv"),  # a q that is not a number counts as 1
        (SELECT, ",,,", "application/sparql-results+json"),  # nothing readable: as if no Accept
        (CONSTRUCT, "text/turtle; charset=utf-8", "text/turtle"),
        (CONSTRUCT, "application/x-turtle", "text/turtle"),
        (CONSTRUCT, "text/turtle;q=0.1, application/n-triples", "application/n-triples"),
    ],
)
@pytest.mark.parametrize("how", ["get", "post-form", "post-direct"])
def test_accept_with_parameters_aliases_and_q_values(
    server: Server, query: str, accept: str, expected: str, how: str
) -> None:
    if how == "get":  # the ASGI front's own path for a plain query
        status, headers, body = get(server, "/sparql", query, accept)
    elif how == "post-form":  # Flask's
        form = urllib.parse.urlencode({"query": query}).encode()
        content = {"Content-Type": "application/x-www-form-urlencoded", "Accept": accept}
        status, headers, body = ask(server, "POST", "/sparql", form, content)
    else:
        content = {"Content-Type": "application/sparql-query", "Accept": accept}
        status, headers, body = ask(server, "POST", "/sparql", query.encode(), content)
    assert status == 200, body
    assert media(headers) == expected
    assert b"Position2D" in body


def test_a_type_the_result_cannot_take_is_still_406(server: Server) -> None:
    status, _, body = get(server, "/sparql", SELECT, "image/png; charset=utf-8")
    assert status == 406 and json.loads(body)["error"] == "not-acceptable"


@pytest.mark.parametrize(
    ("accept", "expected"),
    [
        ("text/turtle;q=0.1, application/n-triples", "application/n-triples"),
        ("application/n-triples; charset=utf-8", "application/n-triples"),
        ("text/turtle;q=0, */*;q=0.5", "application/n-triples"),
        ("application/x-turtle", "text/turtle"),
    ],
)
def test_the_graph_store_reads_accept_as_the_endpoint_does(server: Server, accept: str, expected: str) -> None:
    status, headers, body = ask(
        server, "GET", f"/store?graph={urllib.parse.quote(ONTOLOGY)}", headers={"Accept": accept}
    )
    assert status == 200, body
    assert media(headers) == expected


@pytest.mark.parametrize(
    ("accept", "expected"),
    [
        ("application/sparql-results+json", "application/sparql-results+json"),
        ("application/sparql-results+xml", "application/sparql-results+xml"),
        (
            "application/sparql-results+json,application/json,text/javascript,application/javascript",
            "application/sparql-results+json",
        ),  # SPARQLWrapper
        ("text/csv", "text/csv"),
        ("*/*", "application/sparql-results+json"),  # curl
    ],
)
def test_a_sparql_client_at_query_gets_the_endpoint(server: Server, accept: str, expected: str) -> None:
    status, headers, body = get(server, "/query", SELECT, accept)
    assert status == 200, body
    assert media(headers) == expected
    assert "Accept" in headers.get("vary", "")
    assert b"Position2D" in body


def test_a_browser_at_query_gets_the_editor(server: Server) -> None:
    for accept in (BROWSER, None):
        status, headers, body = get(server, "/query", SELECT, accept)
        assert status == 200 and media(headers) == "text/html"
        assert b"<html" in body


def test_query_takes_post_bodies_and_updates_as_oxigraph_does(server: Server) -> None:
    direct = {"Content-Type": "application/sparql-query", "Accept": BROWSER}  # the body says it: a query
    status, headers, body = ask(server, "POST", "/query", b"ASK { home:Position2D ?p ?o }", direct)
    assert status == 200 and media(headers) == "application/xml", body  # application/xml;q=0.9 in BROWSER
    assert b"<boolean>true</boolean>" in body
    wrong = ask(server, "POST", "/query", b"SELEC ?x", {"Content-Type": "application/sparql-query"})
    assert wrong[0] == 400 and json.loads(wrong[2])["error"] == "QuerySyntaxError"  # JSON, not a page
    insert = b"INSERT DATA { GRAPH <urn:test:clients> { <urn:test:q> <urn:test:p> 1 } }"
    update = {"Content-Type": "application/sparql-update"}
    assert ask(server, "POST", "/query", insert, update)[0] == 403
    assert ask(server, "POST", "/query", insert, {**update, "Authorization": f"Bearer {TOKEN}"})[0] == 204
    asked = get(server, "/query", "ASK { <urn:test:q> <urn:test:p> 1 }", "application/sparql-results+json")
    assert json.loads(asked[2])["boolean"] is True


@pytest.mark.parametrize("path", ["/sparql", "/query"])
def test_sparqlwrapper_with_every_return_format_it_has(server: Server, path: str) -> None:
    """SPARQLWrapper sends its return format as format= and output= besides an Accept header; its RDF
    format (format=rdf) was a 406."""
    sparqlwrapper = pytest.importorskip("SPARQLWrapper")
    names = {"SELECT": ("JSON", "XML", "CSV", "TSV"), "CONSTRUCT": ("TURTLE", "N3", "RDFXML", "JSONLD", "XML", "RDF")}
    for form, query in (("SELECT", SELECT), ("CONSTRUCT", CONSTRUCT)):
        for name in names[form]:
            for method in (sparqlwrapper.GET, sparqlwrapper.POST):
                client = sparqlwrapper.SPARQLWrapper(f"http://127.0.0.1:{server.http_port}{path}")
                client.setTimeout(int(WAIT))
                client.setQuery(query)
                client.setReturnFormat(getattr(sparqlwrapper, name))
                client.setMethod(method)
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")  # SPARQLWrapper's own about formats and rdflib's deprecations
                    result = client.query()
                    answered = result.info()["content-type"].partition(";")[0]
                    converted = result.convert()
                assert answered != "text/html" and converted, (form, name, method, answered)


def test_sparqlwrapper_at_the_query_path() -> None:
    sparqlwrapper = pytest.importorskip("SPARQLWrapper")
    served = Server(KnowledgeBase.open(":memory:"), ServeConfig(port=0, bridge_port=0))
    served.start()
    try:
        client = sparqlwrapper.SPARQLWrapper(f"http://127.0.0.1:{served.http_port}/query")
        client.setTimeout(int(WAIT))
        client.setQuery(SELECT)
        client.setReturnFormat(sparqlwrapper.JSON)
        rows = client.query().convert()["results"]["bindings"]
        assert "https://w3id.org/cbrs/home#Position2D" in {row["c"]["value"] for row in rows}
        client.setMethod(sparqlwrapper.POST)
        client.setQuery(CONSTRUCT)
        client.setReturnFormat(sparqlwrapper.TURTLE)
        assert b"Position2D" in client.query().convert()
    finally:
        served.stop(timeout=WAIT)


@pytest.mark.parametrize(
    ("method", "path", "text", "said"),
    [
        (
            "GET",
            "/sparql",
            "INSERT DATA { GRAPH <urn:g> { <urn:a> <urn:b> <urn:c> } }",
            "this is a SPARQL update, not a query",
        ),
        (
            "POST-query",
            "/sparql",
            "PREFIX x: <urn:x#> DELETE WHERE { GRAPH ?g { ?s x:p ?o } }",
            "this is a SPARQL update, not a query",
        ),
        ("POST-update", "/update", "SELECT * WHERE { ?s ?p ?o }", "this is a SPARQL query, not an update"),
        ("GET", "/sparql", "SELECT ?x WHERE { ?x hme:partOf ?y }", "the prefix 'hme:' is not declared"),
        ("GET", "/sparql", "SELECT ?p ?o WHERE { hme:Cup ?p ?o }", "did you mean 'home:'?"),  # a lookup's path
        (
            "POST-update",
            "/update",
            "INSERT DATA { GRAPH <urn:g> { <urn:a> zzq:b <urn:c> } }",
            "the prefix 'zzq:' is not declared",
        ),
        ("GET", "/sparql", "selct ?s WHERE { ?s ?p ?o }", "'selct' begins no SPARQL query: did you mean SELECT?"),
        ("POST-update", "/update", "INSRT DATA { GRAPH <urn:g> { <urn:a> <urn:b> <urn:c> } }", "did you mean INSERT?"),
        ("GET", "/sparql", "SELECT ?s WHERE { ?s <http://x.org/a space> ?o }", "1:44: expected IRI parsing failed"),
        ("GET", "/sparql", "SELECT ?s WHERE { ?s ?p ?o", "the text ends with 1 '{' not closed"),
        (
            "POST-update",
            "/update",
            'INSERT DATA { GRAPH <urn:g> { <urn:a> <urn:b> "}" }',
            "the text ends with 1 '{' not closed",
        ),
    ],
)
def test_a_mistaken_text_is_a_400_that_says_what_is_wrong(
    server: Server, method: str, path: str, text: str, said: str
) -> None:
    auth = {"Authorization": f"Bearer {TOKEN}"}
    if method == "GET":
        status, _, body = get(server, path, text)
    elif method == "POST-query":
        status, _, body = ask(server, "POST", path, text.encode(), {"Content-Type": "application/sparql-query"})
    else:
        status, _, body = ask(
            server, "POST", path, text.encode(), {"Content-Type": "application/sparql-update", **auth}
        )
    answer = json.loads(body)
    assert status == 400 and answer["error"] == "QuerySyntaxError", answer
    assert said in answer["message"] and "error at 1:" in answer["message"]


def test_the_bridge_query_service_explains_an_update_too(server: Server) -> None:
    with connect(f"ws://127.0.0.1:{server.bridge_port}", open_timeout=WAIT) as ws:
        text = "INSERT DATA { GRAPH <urn:g> { <urn:a> <urn:b> <urn:c> } }"
        ws.send(json.dumps({"op": "call_service", "service": "/cbrs/query", "id": "q1", "args": {"query": text}}))
        answer: dict[str, Any] = json.loads(ws.recv(timeout=WAIT))
    assert answer["id"] == "q1" and answer["result"] is False
    assert "this is a SPARQL update, not a query" in answer["values"]


def test_a_failed_update_changes_nothing_and_a_204_has_no_type(server: Server) -> None:
    auth = {"Content-Type": "application/sparql-update", "Authorization": f"Bearer {TOKEN}"}
    first = b"INSERT DATA { GRAPH <urn:test:atomic> { <urn:test:a> <urn:test:p> 1 } }"
    status, headers, _ = ask(server, "POST", "/update", first, auth)
    assert status == 204 and "content-type" not in headers
    both = b"INSERT DATA { GRAPH <urn:test:atomic> { <urn:test:b> <urn:test:p> 2 } } ; CREATE GRAPH <urn:test:atomic>"
    status, _, body = ask(server, "POST", "/update", both, auth)
    assert status == 400 and json.loads(body)["error"] == "StoreEvaluationError"
    asked = get(server, "/sparql", "ASK { <urn:test:b> ?p ?o }", "application/sparql-results+json")
    assert json.loads(asked[2])["boolean"] is False


@pytest.mark.parametrize(
    ("method", "path"),
    [("DELETE", "/sparql"), ("PUT", "/update"), ("GET", "/update"), ("PATCH", "/store"), ("GET", "/nothing.json")],
)
def test_protocol_paths_answer_errors_in_json_whatever_accept_says(server: Server, method: str, path: str) -> None:
    status, headers, body = ask(server, method, path, headers={"Accept": "*/*"})  # curl's default
    assert status in (404, 405) and media(headers) == "application/json", body
    assert json.loads(body)["error"] in ("not-found", "method-not-allowed")


def test_a_page_that_does_not_exist_is_still_a_page_for_a_browser(server: Server) -> None:
    status, headers, _ = ask(server, "GET", "/nothing", headers={"Accept": BROWSER})
    assert status == 404 and media(headers) == "text/html"


@pytest.mark.parametrize("charset", ["iso-8859-1", "utf-16", "UTF-8", '"utf-8"'])
def test_a_body_is_read_in_the_charset_it_declares(server: Server, charset: str) -> None:
    query = 'ASK { FILTER("café" = "caf\\u00e9") }'  # true only if the é arrived as an é
    content = {"Content-Type": f"application/sparql-query; charset={charset}", "Accept": "application/json"}
    status, _, body = ask(server, "POST", "/sparql", query.encode(charset.strip('"')), content)
    assert status == 200, body
    assert json.loads(body)["boolean"] is True


def test_a_charset_nobody_knows_is_a_400_naming_it(server: Server) -> None:
    content = {"Content-Type": "application/sparql-query; charset=klingon"}
    status, _, body = ask(server, "POST", "/sparql", b"ASK {}", content)
    assert status == 400 and "klingon" in json.loads(body)["message"]


def test_serve_on_a_server_without_a_union_default_graph_stops_with_the_reason(
    tmp_path: Path, oxigraph_servers: Callable[..., OxigraphServer]
) -> None:
    """The README's ``cbrs --store http://127.0.0.1:7878 serve`` on an ``oxigraph serve`` started without
    ``--union-default-graph``: it seeded the store, then served an endpoint that failed every query."""
    oxigraph = oxigraph_servers(union_default_graph=False, on_disk=False)
    command = [sys.executable, "-m", "cbrs", "--store", oxigraph.url, "serve", "--port", "0", "--bridge-port", "0"]
    environment = {**os.environ, "CBRS_SEED_CACHE": str(tmp_path), "CBRS_LOG_LEVEL": "ERROR"}
    child = subprocess.run(command, capture_output=True, text=True, timeout=60, env=environment)
    assert child.returncode == 1, child.stdout
    assert "Error: " in child.stderr and "start Oxigraph with --union-default-graph" in child.stderr
    assert "cbrs serving" not in child.stdout


def test_a_text_starting_with_a_byte_order_mark_is_read_without_it(server: Server) -> None:
    """A query file saved by a Windows editor, posted as it is (curl --data-binary @query.rq)."""
    bom = "\ufeff".encode()
    direct = {"Content-Type": "application/sparql-query", "Accept": "application/json"}
    status, _, body = ask(server, "POST", "/sparql", bom + b"ASK { home:Position2D ?p ?o }", direct)
    assert status == 200 and json.loads(body)["boolean"] is True, body
    status, _, body = get(server, "/sparql", "\ufeffSELECT ?p WHERE { home:Position2D ?p ?o } LIMIT 1")  # a lookup
    assert status == 200, body
    update = {"Content-Type": "application/sparql-update", "Authorization": f"Bearer {TOKEN}"}
    insert = bom + b"INSERT DATA { GRAPH <urn:test:bom> { <urn:test:bom> <urn:test:p> 1 } }"
    assert ask(server, "POST", "/update", insert, update)[0] == 204


def test_cbrs_query_reads_a_file_with_a_byte_order_mark(tmp_path: Path) -> None:
    from click.testing import CliRunner

    from cbrs.cli import cli

    query = tmp_path / "ask.rq"
    query.write_bytes("\ufeffASK { home:Position2D ?p ?o }".encode())
    result = CliRunner().invoke(cli, ["--store", ":memory:", "query", "--file", str(query), "--format", "json"])
    assert result.exit_code == 0, result.output
    assert json.loads(result.output)["boolean"] is True


@pytest.mark.parametrize(
    ("given", "expected"),
    [
        ("JSON", "application/sparql-results+json"),
        ("Text/CSV", "text/csv"),
        ("application/sparql-results+xml; charset=utf-8", "application/sparql-results+xml"),
        ("text/tsv", "text/tab-separated-values"),
    ],
)
def test_a_format_parameter_is_read_as_leniently_as_accept(server: Server, given: str, expected: str) -> None:
    query = urllib.parse.urlencode({"query": SELECT, "format": given})
    status, headers, body = ask(server, "GET", f"/sparql?{query}")
    assert status == 200, body
    assert media(headers) == expected


def test_an_empty_dataset_parameter_names_no_graph(server: Server) -> None:
    """A query form with a blank graph field sends default-graph-uri= (Virtuoso's page does): the union
    default graph applies, as without the parameter."""
    query = urllib.parse.urlencode(
        {"query": "ASK { home:Position2D ?p ?o }", "default-graph-uri": "", "named-graph-uri": " "}
    )
    status, _, body = ask(server, "GET", f"/sparql?{query}", headers={"Accept": "application/json"})
    assert status == 200 and json.loads(body)["boolean"] is True, body
