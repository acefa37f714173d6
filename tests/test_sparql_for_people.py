"""``/sparql`` opened in a browser: the person gets the query editor, a SPARQL client the description.

A browser's GET of ``/sparql`` with no query used to be answered with the endpoint's service description
as RDF/XML (its ``Accept`` names ``application/xml`` after HTML); it is now sent to ``/query``.
"""

from __future__ import annotations

import pyoxigraph as ox
import pytest
from flask.testing import FlaskClient

from cbrs.kb import KnowledgeBase
from cbrs.sparql_service import EndpointConfig, SparqlService
from cbrs.web import create_app

BROWSER = "text/html,application/xhtml+xml,application/xml;q=0.9,image/avif,image/webp,*/*;q=0.8"
SD = "http://www.w3.org/ns/sparql-service-description#"


@pytest.fixture(scope="module")
def client(bundled_kb: KnowledgeBase) -> FlaskClient:
    return create_app(SparqlService(bundled_kb, EndpointConfig())).test_client()


@pytest.mark.parametrize("accept", [BROWSER, "text/html", "application/xhtml+xml,*/*;q=0.5"])
def test_a_browser_opening_sparql_is_sent_to_the_editor(client: FlaskClient, accept: str) -> None:
    answer = client.get("/sparql", headers={"Accept": accept})
    assert answer.status_code == 303
    assert answer.headers["Location"].endswith("/query")
    assert "Accept" in answer.headers["Vary"]  # caches must not hand the redirect to a SPARQL client
    page = client.get(answer.headers["Location"], headers={"Accept": accept})
    assert page.status_code == 200 and page.mimetype == "text/html"
    assert b"<textarea" in page.data  # the editor


@pytest.mark.parametrize(
    ("accept", "expected"),
    [
        pytest.param(None, ox.RdfFormat.TURTLE, id="no-accept"),
        pytest.param("*/*", ox.RdfFormat.TURTLE, id="anything"),
        pytest.param("text/turtle", ox.RdfFormat.TURTLE, id="turtle"),
        pytest.param("application/rdf+xml, text/html;q=0.5", ox.RdfFormat.RDF_XML, id="rdf-xml-over-html"),
        pytest.param("application/ld+json", ox.RdfFormat.JSON_LD, id="json-ld"),
    ],
)
def test_a_sparql_client_keeps_getting_the_service_description(
    client: FlaskClient, accept: str | None, expected: ox.RdfFormat
) -> None:
    answer = client.get("/sparql", headers={"Accept": accept} if accept else {})
    assert answer.status_code == 200
    triples = list(ox.parse(answer.data, format=expected))
    assert any(t.predicate.value == SD + "endpoint" for t in triples)


def test_a_format_parameter_or_a_query_keeps_the_protocol_even_for_a_browser(client: FlaskClient) -> None:
    described = client.get("/sparql", query_string={"format": "turtle"}, headers={"Accept": BROWSER})
    assert described.status_code == 200 and described.mimetype == "text/turtle"
    answered = client.get("/sparql", query_string={"query": "ASK {}"}, headers={"Accept": BROWSER})
    assert answered.status_code == 200 and answered.mimetype != "text/html"
