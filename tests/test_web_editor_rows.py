"""The SPARQL editor reads no more rows than it shows (``CBRS_EDITOR_ROWS``, plus one to know there are
more): ``SELECT * WHERE { ?s ?p ?o }`` on OWLS-TC serialised all 178,000 solutions to show 1,000. A cut
result says so and offers the whole one from ``/sparql``, which runs the query as it was written."""

from __future__ import annotations

import json
from html import unescape
from typing import Any
from urllib.parse import parse_qs, urlsplit

import pyoxigraph as ox
import pytest
from flask.testing import FlaskClient

from cbrs.kb import KnowledgeBase
from cbrs.sparql_service import Answer, EndpointConfig, SparqlService
from cbrs.web import create_app
from cbrs.web.row_limit import bounded

ROWS = 10
EVERYTHING = "SELECT * WHERE { ?s ?p ?o }"
ORDERED = "SELECT ?s ?p ?o WHERE { ?s ?p ?o } ORDER BY ?s ?p ?o"


class CountingService(SparqlService):
    """Keeps how many rows each SELECT answer it gave held."""

    def __init__(self, kb: KnowledgeBase, config: EndpointConfig | None = None) -> None:
        super().__init__(kb, config)
        self.rows: list[int] = []

    def query(self, text: str, *args: Any, **kwargs: Any) -> Answer:  # type: ignore[override]
        answer = super().query(text, *args, **kwargs)
        if answer.media_type == "application/sparql-results+json":
            parsed = json.loads(answer.body)
            if "results" in parsed:
                self.rows.append(len(parsed["results"]["bindings"]))
        return answer


def _client(sparql: SparqlService) -> FlaskClient:
    app = create_app(sparql)
    app.config["CBRS_EDITOR_ROWS"] = ROWS
    return app.test_client()


@pytest.fixture(scope="module")
def counting(bundled_kb: KnowledgeBase) -> CountingService:
    return CountingService(bundled_kb)


@pytest.fixture(scope="module")
def client(counting: CountingService) -> FlaskClient:
    return _client(counting)


def _editor(client: FlaskClient, text: str, status: int = 200) -> Any:
    response = client.get("/query.json", query_string={"query": text})
    assert response.status_code == status, response.get_data(as_text=True)
    return response.get_json()


def _endpoint_rows(client: FlaskClient, text: str) -> list[dict[str, Any]]:
    response = client.get(
        "/sparql", query_string={"query": text}, headers={"Accept": "application/sparql-results+json"}
    )
    assert response.status_code == 200
    rows: list[dict[str, Any]] = response.get_json()["results"]["bindings"]
    return rows


def test_a_big_result_is_cut_and_the_engine_gave_one_row_more(client: FlaskClient, counting: CountingService) -> None:
    assert len(_endpoint_rows(client, EVERYTHING)) > 10 * ROWS  # the store has far more than the page shows
    counting.rows.clear()
    result = _editor(client, EVERYTHING)["result"]
    assert result["kind"] == "select" and result["truncated"] and result["count"] == len(result["rows"]) == ROWS
    assert counting.rows == [ROWS + 1]  # what the service serialised for the page: not the whole store


def test_the_bound_holds_where_the_whole_result_would_not_fit(bundled_kb: KnowledgeBase) -> None:
    """With a byte budget that 11 rows fit in and the whole result does not, the endpoint refuses the
    query as written and the editor still shows its first rows: it never asked for them all."""
    small = _client(SparqlService(bundled_kb, EndpointConfig(max_result_bytes=20_000)))
    assert small.get("/sparql", query_string={"query": EVERYTHING}).status_code == 422  # result too large
    result = _editor(small, EVERYTHING)["result"]
    assert result["truncated"] and result["count"] == ROWS


def test_the_rows_shown_are_the_first_rows_of_the_whole_result(client: FlaskClient) -> None:
    whole = _endpoint_rows(client, ORDERED)
    assert _editor(client, ORDERED)["result"]["rows"] == whole[:ROWS]
    offset = ORDERED + " OFFSET 7"
    assert _editor(client, offset)["result"]["rows"] == whole[7 : 7 + ROWS]


@pytest.mark.parametrize(
    ("limit", "count", "truncated"),
    [(3, 3, False), (ROWS, ROWS, False), (ROWS + 1, ROWS, True), (50, ROWS, True)],
)
def test_a_limit_of_the_query_is_kept_or_lowered(client: FlaskClient, limit: int, count: int, truncated: bool) -> None:
    text = f"{ORDERED} LIMIT {limit}"
    body = _editor(client, text)
    assert body["result"]["count"] == count and body["result"]["truncated"] is truncated
    assert body["result"]["rows"] == _endpoint_rows(client, text)[:ROWS]
    for download in body["downloads"]:  # the whole result: the query as written, its own LIMIT included
        assert parse_qs(urlsplit(download["href"]).query)["query"] == [text]


def test_a_result_that_fits_is_whole_and_not_called_cut(client: FlaskClient) -> None:
    text = "SELECT ?c WHERE { ?c rdfs:subClassOf home:Position }"
    body = _editor(client, text)
    assert not body["result"]["truncated"] and body["result"]["count"] == len(_endpoint_rows(client, text)) <= ROWS
    assert "cut-notice" not in client.get("/query", query_string={"query": text}).get_data(as_text=True)


@pytest.mark.parametrize(
    "text",
    [
        EVERYTHING + "  # a comment at the end, with no newline",
        "SELECT ?s ?o WHERE { ?s rdfs:label ?o } VALUES ?o { }",
        "PREFIX x: <http://example.org/LIMIT#> SELECT * WHERE { ?s ?p ?o FILTER(?o != 'LIMIT 1 }') }",
        "SELECT (COUNT(?o) AS ?n) ?s WHERE { { SELECT ?s ?o WHERE { ?s ?p ?o } LIMIT 500 } }"
        " GROUP BY ?s ORDER BY DESC(?n) ?s",
    ],
)
def test_comments_values_strings_and_subqueries_keep_their_meaning(client: FlaskClient, text: str) -> None:
    result = _editor(client, text)["result"]
    whole = _endpoint_rows(client, text)
    assert result["count"] == min(ROWS, len(whole)) and result["truncated"] is (len(whole) > ROWS)
    if "ORDER BY" in text:
        assert result["rows"] == whole[:ROWS]


def test_the_page_says_the_result_was_cut_and_offers_the_whole(client: FlaskClient) -> None:
    page = client.get("/query", query_string={"query": EVERYTHING}).get_data(as_text=True)
    assert f"The result was cut at {ROWS} rows." in page and f"the first {ROWS} rows" in page
    assert page.count('<td class="num muted">') == ROWS
    notice = page[page.index('id="cut-notice"') :]
    form = notice[: notice.index("</form>")]
    assert 'action="/sparql"' in form and 'method="get"' in form
    assert f'<input type="hidden" name="query" value="{EVERYTHING}">' in unescape(form)
    assert {f'value="{f}"' for f in ("csv", "json", "tsv", "xml")} <= {
        part.split(">")[0] for part in form.split("<option ")[1:]
    }
    assert 'id="full-format"' in form and '<label for="full-format">' in form


def test_the_full_result_form_escapes_the_query(client: FlaskClient) -> None:
    """A query is only ever a form or URL parameter: markup in it stays text."""
    text = 'SELECT * WHERE { ?s ?p ?o FILTER(?o != "\\"><script>alert(1)</script>") }'
    page = client.get("/query", query_string={"query": text}).get_data(as_text=True)
    assert "<script>alert(1)" not in page
    notice = page[page.index('id="cut-notice"') :]
    value = notice.split('name="query" value="')[1].split('"')[0]
    assert unescape(value) == text
    full = client.get("/sparql", query_string={"query": unescape(value), "format": "csv"})
    assert full.status_code == 200 and full.mimetype == "text/csv"
    assert len(full.get_data(as_text=True).splitlines()) > ROWS + 1


def test_ask_construct_and_syntax_errors_are_as_before(client: FlaskClient) -> None:
    assert _editor(client, "ASK { ?s ?p ?o }")["result"] == {"kind": "ask", "boolean": True}
    graph = _editor(client, "CONSTRUCT { ?c rdfs:subClassOf home:Position } WHERE { ?c rdfs:subClassOf home:Position }")
    assert graph["result"]["kind"] == "graph" and "RobotPosition" in graph["result"]["turtle"]
    broken = "SELECT * WHERE { ?s ?p ?o } ORDER"
    error = _editor(client, broken, 400)["fields"]["query"]
    endpoint = client.get("/sparql", query_string={"query": broken}).get_json()["message"]
    assert error == endpoint  # the parser's words for the text as written, not for the bounded one


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        (EVERYTHING, EVERYTHING + "\nLIMIT 11"),
        ("select * { ?s ?p ?o } order by ?s limit 99 offset 2", "select * { ?s ?p ?o } order by ?s limit 11 offset 2"),
        ("SELECT * { ?s ?p ?o } OFFSET 2", "SELECT * { ?s ?p ?o } OFFSET 2\nLIMIT 11"),
        ("SELECT * { ?s ?p ?o } LIMIT 4", "SELECT * { ?s ?p ?o } LIMIT 4"),
        ("SELECT * { ?s ?p ?o } VALUES ?s { <a> }", "SELECT * { ?s ?p ?o } LIMIT 11\nVALUES ?s { <a> }"),
        (
            "SELECT * { ?s ?p ?o { SELECT ?s { ?s ?p ?o } LIMIT 99 } }",
            "SELECT * { ?s ?p ?o { SELECT ?s { ?s ?p ?o } LIMIT 99 } }\nLIMIT 11",
        ),
        (
            'SELECT * { ?s <http://x/LIMIT> "} LIMIT 99" } # LIMIT 99',
            'SELECT * { ?s <http://x/LIMIT> "} LIMIT 99" } # LIMIT 99\nLIMIT 11',
        ),
        (
            "SELECT (EXISTS { ?a ?b ?c } AS ?e) WHERE { ?s ?p ?o }",
            "SELECT (EXISTS { ?a ?b ?c } AS ?e) WHERE { ?s ?p ?o }\nLIMIT 11",
        ),
        ("ASK { ?s ?p ?o }", None),
        ("CONSTRUCT WHERE { ?s ?p ?o }", "CONSTRUCT WHERE { ?s ?p ?o }\nLIMIT 11"),
        ("CONSTRUCT { ?s ?p ?o } WHERE { ?s ?p ?o } LIMIT 99", "CONSTRUCT { ?s ?p ?o } WHERE { ?s ?p ?o } LIMIT 11"),
        (
            "CONSTRUCT { ?s ?p ?o } { ?s ?p ?o } ORDER BY ?o",
            "CONSTRUCT { ?s ?p ?o } { ?s ?p ?o } ORDER BY ?o\nLIMIT 11",
        ),
        ("DESCRIBE ?s WHERE { ?s ?p ?o }", "DESCRIBE ?s WHERE { ?s ?p ?o }\nLIMIT 11"),
        ("DESCRIBE <a>", None),
        ("SELECT * { ?s ?p ?o", None),
        ("SELECT * { ?s ?p ?o } }", None),
    ],
)
def test_bounded_adds_or_lowers_only_the_outer_limit(text: str, expected: str | None) -> None:
    found = bounded(text, ROWS + 1)
    assert (found.text if found else None) == expected


def _endpoint_triples(client: FlaskClient, text: str) -> set[ox.Triple]:
    response = client.get("/sparql", query_string={"query": text}, headers={"Accept": "application/n-triples"})
    assert response.status_code == 200
    return set(ox.parse(response.get_data(), ox.RdfFormat.N_TRIPLES))


def _shown_triples(result: dict[str, Any]) -> list[ox.Triple]:
    return list(ox.parse(result["turtle"].encode(), ox.RdfFormat.TURTLE))


@pytest.mark.parametrize(
    "text",
    [
        "CONSTRUCT WHERE { ?s ?p ?o }",
        "DESCRIBE ?s WHERE { ?s a cbrs:DynamicPerceptionComponent }",
        # Sorted by class, the first 11 solutions name few classes: only the whole result shows there are more.
        "CONSTRUCT { <urn:x:all> <urn:x:classes> ?c } WHERE { ?s a ?c } ORDER BY ?c",
    ],
)
def test_a_big_graph_is_cut_at_as_many_triples_as_rows(client: FlaskClient, text: str) -> None:
    """CONSTRUCT WHERE { ?s ?p ?o } on OWLS-TC was a page of 21 MB that Chromium had not drawn after a minute."""
    whole = _endpoint_triples(client, text)
    assert len(whole) > ROWS
    result = _editor(client, text)["result"]
    shown = _shown_triples(result)
    assert result["kind"] == "graph" and result["truncated"] and result["count"] == len(shown) == ROWS
    if "DESCRIBE" not in text:  # a DESCRIBE's blank nodes are new on each reading
        assert set(shown) <= whole
    page = client.get("/query", query_string={"query": text}).get_data(as_text=True)
    assert f"The result was cut at {ROWS} triples." in page and f"the first {ROWS} triples" in page


@pytest.mark.parametrize(
    "text",
    [
        "CONSTRUCT { ?c rdfs:subClassOf home:Position } WHERE { ?c rdfs:subClassOf home:Position }",
        "CONSTRUCT { <urn:x:one> <urn:x:same> <urn:x:triple> } WHERE { ?s ?p ?o }",  # many solutions, one triple
        "DESCRIBE home:XCoordinate",  # RobotLocation's, with its restrictions described (kb.described), is 19
    ],
)
def test_a_graph_that_fits_is_whole_with_the_pages_prefixes(client: FlaskClient, text: str) -> None:
    result = _editor(client, text)["result"]
    whole = _endpoint_triples(client, text)
    assert not result["truncated"] and result["count"] == len(whole) <= ROWS
    if "DESCRIBE" not in text:
        assert set(_shown_triples(result)) == whole
    if "home:" in text:
        assert "@prefix home: <https://w3id.org/cbrs/home#>" in result["turtle"]
    assert "cut-notice" not in client.get("/query", query_string={"query": text}).get_data(as_text=True)
