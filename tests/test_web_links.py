"""Every link the browser's pages give leads somewhere: a crawl from the overview, bounded, finds no
error page. Graph names (the overview's table, the graph column of every triple) led to 404s: a graph
is the subject of no triple. Their page now says how many triples the graph holds and links them."""

from __future__ import annotations

import re
from collections import deque
from html import unescape
from typing import Any

import pytest
from flask.testing import FlaskClient

from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import GraphName
from cbrs.sparql_service import SparqlService
from cbrs.web import create_app

BROWSER_ACCEPT = "text/html,application/xhtml+xml,application/xml;q=0.9,image/avif,image/webp,*/*;q=0.8"
PAGES = 300  # fetched by the crawl: enough to reach every kind of page and link from the start pages
SKIP = ("/static/", "/sparql", "/camera", "/tasks/events", "/store", "/plans/graph.svg")


@pytest.fixture(scope="module")
def client(bundled_kb: KnowledgeBase) -> FlaskClient:
    return create_app(SparqlService(bundled_kb)).test_client()


def test_a_crawl_from_the_overview_finds_no_broken_link(client: FlaskClient) -> None:
    pending: deque[str] = deque(["/"])
    seen: set[str] = set()
    broken: list[tuple[int, str]] = []
    starts = [
        "/taxonomy",
        "/services",
        "/search?q=position",
        "/plans?task=FetchMyPen",
        "/match?requirement=req:FetchMyPen",
    ]
    pending.extend(starts)
    for _ in range(20_000):  # bounded, in pops and in pages fetched
        if not pending or len(seen) >= PAGES:
            break
        url = pending.popleft()
        if url in seen:
            continue
        seen.add(url)
        response = client.get(url, headers={"Accept": BROWSER_ACCEPT})
        if response.status_code >= 400:
            broken.append((response.status_code, url))
            continue
        if response.mimetype == "text/html":
            for href in re.findall(r'href="(/[^"#]*)"', response.text):
                href = unescape(href)
                if not href.startswith(SKIP) and href not in seen:
                    pending.append(href)
    assert len(seen) == PAGES
    assert broken == []
    assert any(url.startswith("/resource?iri=https://w3id.org/cbrs/graph") for url in seen)


def test_a_graph_name_has_a_page_with_its_size_and_its_triples(client: FlaskClient) -> None:
    body = client.get("/resource.json", query_string={"iri": GraphName.ONTOLOGY.iri}).get_json()
    statistics = {g["graph"]: g["triples"] for g in client.get("/index.json").get_json()["graphs"]}
    assert body["graph"]["triples"] == statistics[GraphName.ONTOLOGY.iri] and body["graph"]["triples"] > 0
    download = next(p["href"] for p in body["pages"] if "Turtle" in p["text"])
    turtle = client.get(download, headers={"Accept": BROWSER_ACCEPT})
    assert turtle.status_code == 200 and turtle.mimetype == "text/turtle"  # not RDF/XML for a browser
    empty = client.get("/resource.json", query_string={"iri": GraphName.WORLD.iri}).get_json()
    assert empty["graph"]["triples"] == 0 and empty["pages"] == []  # nothing to download
    page = client.get("/resource", query_string={"iri": GraphName.WORLD.iri})
    assert page.status_code == 200 and "0 triples" in page.text
    assert client.get("/resource.json", query_string={"iri": "https://w3id.org/cbrs/graph/nothing"}).status_code == 404


def test_a_sparql_client_still_gets_what_it_asks_for(client: FlaskClient) -> None:
    xml = client.get("/store", query_string={"graph": GraphName.MAP.iri}, headers={"Accept": "application/rdf+xml"})
    assert xml.status_code == 200 and xml.mimetype == "application/rdf+xml"


def test_each_figure_of_the_overview_opens_its_list(client: FlaskClient) -> None:
    body = client.get("/index.json").get_json()
    links, counts = body["card_links"], body["counts"]
    services = client.get(links["services"].replace("/services", "/services.json", 1)).get_json()
    assert services["count"] == counts["services"]
    path, _, anchor = links["requirements"].partition("#")
    assert f'id="{anchor}"' in client.get(path).text
    assert len(client.get("/services.json").get_json()["requirements"]) == counts["requirements"]
    tree = client.get(links["actions"].replace("/taxonomy", "/taxonomy.json", 1)).get_json()

    def walk(nodes: list[dict[str, Any]]) -> set[str]:
        return {n["iri"] for n in nodes} | {i for n in nodes for i in walk(n["children"])}

    assert len(walk(tree["classes"])) == counts["actions"] + 1  # the actions, below act:Action
    page = client.get("/").text
    assert all(f'<a class="card-link" href="{href}">' in page for href in links.values())
