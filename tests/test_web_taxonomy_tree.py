"""The taxonomy page on a big store: each tree shows the levels that fit in ``CBRS_TAXONOMY_NODES``
nodes, and a node cut off there links to ``/taxonomy?root=`` (the tree below it), so that every term
is still a few clicks away. OWLS-TC's whole class tree was a page of 9 MB."""

from __future__ import annotations

import re
from collections.abc import Iterator
from html import unescape
from typing import Any

import pytest
from flask.testing import FlaskClient

from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import expand
from cbrs.sparql_service import SparqlService
from cbrs.web import create_app, taxonomy

LIMIT = 40


@pytest.fixture(scope="module")
def client(bundled_kb: KnowledgeBase) -> FlaskClient:
    app = create_app(SparqlService(bundled_kb))
    app.config["CBRS_TAXONOMY_NODES"] = LIMIT
    return app.test_client()


@pytest.fixture(scope="module")
def whole(bundled_kb: KnowledgeBase) -> FlaskClient:
    return create_app(SparqlService(bundled_kb)).test_client()


def walk(nodes: list[dict[str, Any]]) -> Iterator[dict[str, Any]]:
    for node in nodes:
        yield node
        yield from walk(node["children"])


def more_links(page: str) -> list[str]:
    return [unescape(href) for href in re.findall(r'<a class="more" href="([^"]+)"', page)]


def test_the_default_limit_leaves_the_bundled_taxonomy_whole(whole: FlaskClient) -> None:
    body = whole.get("/taxonomy.json").get_json()
    assert not any("more" in node for node in walk(body["classes"] + body["properties"]))
    assert more_links(whole.get("/taxonomy").text) == []


def test_a_tree_past_the_limit_shows_the_levels_that_fit(client: FlaskClient, whole: FlaskClient) -> None:
    body = client.get("/taxonomy.json").get_json()
    classes = list(walk(body["classes"]))
    assert len(body["classes"]) <= len(classes) <= LIMIT
    cut = [node for node in classes if "more" in node]
    assert cut and all(node["children"] == [] and node["more"] > 0 for node in cut)
    full = {node["iri"]: node for node in walk(whole.get("/taxonomy.json").get_json()["classes"])}
    assert all(len(full[node["iri"]]["children"]) == node["more"] for node in cut)


def test_every_term_is_reachable_through_the_more_links(client: FlaskClient, whole: FlaskClient) -> None:
    full = whole.get("/taxonomy.json").get_json()
    expected = {node["iri"] for node in walk(full["classes"] + full["properties"])}
    seen: set[str] = set()
    pending, visited = ["/taxonomy"], set()
    for _ in range(400):  # bounded: the bundled taxonomy needs far fewer pages
        if not pending:
            break
        url = pending.pop()
        if url in visited:
            continue
        visited.add(url)
        response = client.get(url)
        assert response.status_code == 200, url
        body = client.get(url.replace("/taxonomy", "/taxonomy.json", 1)).get_json()
        seen |= {node["iri"] for node in walk(body["classes"] + body["properties"])}
        pending += more_links(response.text)
    assert not pending
    assert seen == expected


def test_a_subtree_starts_at_its_root_with_the_path_to_it(client: FlaskClient) -> None:
    body = client.get("/taxonomy.json", query_string={"root": "home:Position"}).get_json()
    assert body["root"]["iri"] == expand("home:Position") and body["root"]["kind"] == "class"
    assert [node["iri"] for node in body["classes"]] == [expand("home:Position")]
    assert body["properties"] == []
    assert expand("home:RobotPosition") in {node["iri"] for node in walk(body["classes"])}
    assert body["root"]["paths"], "home:Position sits below some class"
    page = client.get("/taxonomy", query_string={"root": "home:Position"})
    assert page.status_code == 200 and "Below" in page.text and 'id="properties"' not in page.text


def test_a_subtree_with_a_search_keeps_only_the_matches_and_their_ancestors(client: FlaskClient) -> None:
    body = client.get("/taxonomy.json", query_string={"root": "home:Position", "q": "robotposition"}).get_json()
    shown = {node["iri"] for node in walk(body["classes"])}
    assert expand("home:RobotPosition") in shown
    assert expand("home:ApproachPosition") not in shown


def test_a_root_that_is_no_term_is_a_404_and_a_malformed_one_a_400(client: FlaskClient) -> None:
    missing = client.get("/taxonomy", query_string={"root": "home:NoSuchClass"})
    assert missing.status_code == 404 and "home#NoSuchClass" in missing.text and "Traceback" not in missing.text
    assert client.get("/taxonomy.json", query_string={"root": "home:NoSuchClass"}).get_json()["error"]
    assert client.get("/taxonomy", query_string={"root": "no such thing"}).status_code == 400


def test_the_match_list_is_cut_but_counts_every_match(client: FlaskClient, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(taxonomy, "MAX_MATCHES", 3)
    body = client.get("/taxonomy.json", query_string={"q": "position"}).get_json()
    assert len(body["matches"]) == 3 and body["match_count"] > 3
    page = client.get("/taxonomy", query_string={"q": "position"}).text
    assert f"{body['match_count']} matches" in page and "The first 3 are listed" in page


def test_the_class_page_links_its_subtree(whole: FlaskClient) -> None:
    page = whole.get("/taxonomy/class", query_string={"iri": "home:Position"}).text
    assert 'href="/taxonomy?root=home:Position"' in page
    assert whole.get("/taxonomy?root=home:Position").status_code == 200


def test_the_match_list_puts_the_best_matches_first(client: FlaskClient, monkeypatch: pytest.MonkeyPatch) -> None:
    """In name order an exact match could fall past the listed ones (OWLS-TC's Car was 72nd of 406)."""
    monkeypatch.setattr(taxonomy, "MAX_MATCHES", 3)
    body = client.get("/taxonomy.json", query_string={"q": "position"}).get_json()
    assert body["matches"][0]["name"] == "home:Position"
    assert body["match_count"] > 3
