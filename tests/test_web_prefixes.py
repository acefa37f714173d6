"""The browser derives a prefix for each namespace of the store that cbrs declares none for
(``books:Novel`` for ``http://127.0.0.1/ontology/books.owl#Novel``), unique, never a declared prefix,
and uses it wherever it shortens an IRI: links, titles, twins, search, pictures, the editor."""

from __future__ import annotations

import random
import re
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from flask.testing import FlaskClient

from cbrs.kb import KnowledgeBase, derived_prefixes
from cbrs.kb.namespaces import PREFIXES
from cbrs.sparql_service import EndpointConfig, SparqlService
from cbrs.web import create_app
from cbrs.web.prefixes import derive, name_for, namespace

BOOKS = "http://127.0.0.1/ontology/books.owl#"
MIRROR = "http://example.com/mirror/books.owl#"  # the same file name as BOOKS'
SERVICE_ONTO = "http://127.0.0.1/ontology/Service.owl#"  # would read as the declared service:
SERVICE = "http://127.0.0.1/services/1.1/novel_price_service.owls#"
TURTLE = f"""@prefix owl: <http://www.w3.org/2002/07/owl#> .
@prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> .
<{BOOKS}Book> a owl:Class .
<{BOOKS}Novel> a owl:Class ; rdfs:subClassOf <{BOOKS}Book> ; rdfs:label "Novel" .
<{MIRROR}Novel> a owl:Class ; rdfs:subClassOf <{BOOKS}Book> .
<{SERVICE_ONTO}Thing> a owl:Class .
<{BOOKS}Odd%20one> a owl:Class ; rdfs:subClassOf <{BOOKS}Book> .
"""
AD = f"""@prefix cbrs: <https://w3id.org/cbrs/core#> .
@prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> .
<{SERVICE}NOVEL_PRICE> a cbrs:MethodInvocationComponent ; rdfs:label "novel price" ;
    cbrs:deviceName "novel_price_service" ; cbrs:serviceName "NovelPrice" ;
    cbrs:hasOWLSModel [ a cbrs:OWLSModel ;
        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "_NOVEL" ; cbrs:parameterType <{BOOKS}Novel> ] ] .
"""
TOKEN = "prefix-test-token"


# -- the rule ------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("ns", "name"),
    [
        (BOOKS, "books"),
        ("http://127.0.0.1/ontology/Mid-level-ontology.owl#", "Mid-level-ontology"),
        ("http://127.0.0.1/services/1.1/3wheeledcar_price_service.owls#", "ns3wheeledcar_price_service"),
        ("http://127.0.0.1/services/1.1/_Toyotaprice_service.owls#", "Toyotaprice_service"),
        ("http://purl.org/dc/elements/1.1/", "elements"),  # the last segment with a letter
        ("http://www.example.org/", "example"),  # no path: the host's first name
        ("http://127.0.0.1/#", "ns"),
        ("http://example.org/a b.c/x.owl#", "x"),
        ("http://example.org/ä.owl#", "ns"),  # nothing of the name is ASCII
    ],
)
def test_the_name_a_namespace_asks_for(ns: str, name: str) -> None:
    assert name_for(ns) == name


@pytest.mark.parametrize(
    ("iri", "ns"),
    [(BOOKS + "Novel", BOOKS), ("http://x.org/a/b", "http://x.org/a/"), ("http://x.org/a/", None), ("urn:x:y", None)],
)
def test_the_namespace_of_an_iri(iri: str, ns: str | None) -> None:
    assert namespace(iri) == ns


def _many_namespaces(seed: int) -> list[str]:
    """Namespaces whose names collide with each other, with declared prefixes and with numbered names."""
    rng = random.Random(seed)
    stems = ["books", "Books", "books1", "books2", "service", "Service", "owl", "home", "x", "ns", "ns1", "3d", "_3d"]
    hosts = ["http://127.0.0.1/ontology/", "http://example.com/a/", "http://example.org/b/c/"]
    endings = [".owl#", ".owls#", "#", "/"]
    return [rng.choice(hosts) + rng.choice(stems) + rng.choice(endings) for _ in range(60)]


@pytest.mark.parametrize("seed", range(5))
def test_derived_prefixes_are_unique_never_declared_and_the_same_in_any_order(seed: int) -> None:
    namespaces = _many_namespaces(seed)
    table = derive(namespaces)
    assert sorted(table.values()) == sorted(set(namespaces))  # one prefix each, none shared
    declared = {name.casefold() for name in PREFIXES}
    assert not {name.casefold() for name in table} & declared  # not even by case (Service, service)
    assert len({name.casefold() for name in table}) == len(table)
    assert all(re.fullmatch(r"[A-Za-z][A-Za-z0-9_-]*", name) for name in table)  # a SPARQL prefix name
    shuffled = list(namespaces)
    random.Random(seed).shuffle(shuffled)
    assert derive(shuffled) == table


def test_a_name_two_namespaces_ask_for_is_numbered_for_both() -> None:
    table = derive([BOOKS, MIRROR, SERVICE_ONTO, "http://127.0.0.1/ontology/books1.owl#"])
    assert table == {
        "books1": "http://127.0.0.1/ontology/books1.owl#",  # its own name, kept
        "books2": BOOKS,
        "books3": MIRROR,
        "Service1": SERVICE_ONTO,  # "service" is declared
    }


def test_declared_namespaces_and_the_ones_they_start_with_get_none() -> None:
    assert derive([PREFIXES["home"], PREFIXES["home"] + "sub/", "https://w3id.org/cbrs/"]) == {}


# -- the pages -----------------------------------------------------------------------------------


@pytest.fixture
def kb(tmp_path: Path) -> Iterator[KnowledgeBase]:
    (tmp_path / "books.ttl").write_text(TURTLE, encoding="utf-8")
    (tmp_path / "ad.ttl").write_text(AD, encoding="utf-8")
    kb = KnowledgeBase.open(":memory:")
    kb.load([tmp_path / "books.ttl"])
    kb.load([tmp_path / "ad.ttl"])
    yield kb
    kb.close()


@pytest.fixture
def client(kb: KnowledgeBase) -> FlaskClient:
    return create_app(SparqlService(kb, EndpointConfig(update_token=TOKEN))).test_client()


@pytest.fixture
def reads(monkeypatch: pytest.MonkeyPatch) -> list[int]:
    """One entry per read of the store's namespaces (by the table kept per store, which the pages take)."""
    counted: list[int] = []
    original = derived_prefixes.read

    def counting(kb: KnowledgeBase) -> dict[str, str]:
        counted.append(1)
        return original(kb)

    monkeypatch.setattr(derived_prefixes, "read", counting)
    return counted


def _html(client: FlaskClient, path: str, **query: str) -> str:
    response = client.get(path, query_string=query)
    assert response.status_code == 200, (path, response.text[:300])
    return response.text


def _json(client: FlaskClient, path: str, **query: str) -> Any:
    response = client.get(path, query_string=query)
    assert response.status_code == 200, (path, response.text[:300])
    return response.get_json()


def test_pages_name_iris_with_the_derived_prefixes(client: FlaskClient) -> None:
    novel = f'title="{BOOKS}Novel">books1:Novel</a>'  # books1: a second books.owl is in the store
    for path, query in (
        ("/taxonomy", {}),
        ("/taxonomy/class", {"iri": BOOKS + "Book"}),
        ("/service", {"iri": SERVICE + "NOVEL_PRICE"}),
        ("/services", {}),
        ("/resource", {"iri": BOOKS + "Book"}),
    ):
        assert novel in _html(client, path, **query), path
    assert f'title="{MIRROR}Novel">books2:Novel</a>' in _html(client, "/taxonomy/class", iri=BOOKS + "Book")
    assert "<title>Class books1:Book · cbrs</title>" in _html(client, "/taxonomy/class", iri=BOOKS + "Book")
    assert ">Service1:Thing<" in _html(client, "/resource", iri=SERVICE_ONTO + "Thing")
    odd = _html(client, "/taxonomy/class", iri=BOOKS + "Book")  # no prefixed name can hold a %: its tail
    assert '<span class="ns">books.owl#</span>Odd%20one</a>' in odd


def test_the_twins_give_the_derived_name_and_the_whole_iri(client: FlaskClient) -> None:
    resource = _json(client, "/resource.json", iri=BOOKS + "Novel")
    assert resource["iri"] == BOOKS + "Novel" and resource["name"] == "books1:Novel"
    values = [v["term"] for group in resource["outgoing"] for v in group["values"]]
    assert {"type": "iri", "value": BOOKS + "Book", "name": "books1:Book"} in values


def test_a_derived_name_is_taken_back_where_the_pages_take_names(client: FlaskClient) -> None:
    assert _json(client, "/resource.json", iri="books1:Novel")["iri"] == BOOKS + "Novel"
    assert _json(client, "/taxonomy/class.json", iri="books2:Novel")["iri"] == MIRROR + "Novel"
    found = _json(client, "/search.json", q="books1:Novel")
    assert found["iri"] == {"iri": BOOKS + "Novel", "name": "books1:Novel"}
    ranked = _json(client, "/match.json", inputs="books1:Novel")
    assert ranked["requirement"]["inputs"] == [BOOKS + "Novel"]


def test_search_and_pictures_use_them(client: FlaskClient) -> None:
    found = _json(client, "/search.json", q="novel")
    assert {"books1:Novel", "books2:Novel"} <= {m["name"] for m in found["terms"]["matches"]}
    page = _html(client, "/taxonomy/class", iri=BOOKS + "Novel")
    picture = re.search(r"<svg.*?</svg>", page, flags=re.S)
    assert picture is not None and ">books1:Book<" in picture.group() and ">books1:Novel<" in picture.group()


def test_the_editor_declares_the_derived_prefixes_a_query_uses(client: FlaskClient) -> None:
    text = "SELECT ?c WHERE { ?c rdfs:subClassOf books1:Book } ORDER BY ?c"
    body = _json(client, "/query.json", query=text)
    assert body["added_prefixes"] == [{"prefix": "books1", "namespace": BOOKS}]
    assert [row["c"]["value"] for row in body["result"]["rows"]] == sorted(
        [BOOKS + "Novel", BOOKS + "Odd%20one", MIRROR + "Novel"]
    )
    csv = client.get(next(d["href"] for d in body["downloads"] if d["format"] == "csv"))
    assert csv.status_code == 200 and BOOKS + "Novel" in csv.text  # the endpoint gets the PREFIX line too
    page = _html(client, "/query", query=text)
    assert f"PREFIX books1: &lt;{BOOKS}&gt;" in page and ">books1:Novel</a>" in page
    own = f"PREFIX books1: <{MIRROR}>\n{text}"  # a prefix the query declares is its own
    assert _json(client, "/query.json", query=own)["added_prefixes"] == []


def test_one_read_a_store_generation_and_a_new_namespace_shows_after_a_write(
    client: FlaskClient, reads: list[int]
) -> None:
    for path in ("/taxonomy", "/services", "/resource?iri=books1:Book", "/search?q=novel"):
        assert client.get(path).status_code == 200, path
    assert len(reads) == 1
    update = (
        "PREFIX owl: <http://www.w3.org/2002/07/owl#> PREFIX rdfs: <http://www.w3.org/2000/01/rdf-schema#>\n"
        "INSERT DATA { GRAPH <https://w3id.org/cbrs/graph/ontology> {\n"
        f"  <http://example.org/lab/films.owl#Film> a owl:Class ; rdfs:subClassOf <{BOOKS}Book> }} }}"
    )
    response = client.post("/sparql", data={"update": update}, headers={"Authorization": f"Bearer {TOKEN}"})
    assert response.status_code == 204
    assert _json(client, "/resource.json", iri="http://example.org/lab/films.owl#Film")["name"] == "films:Film"
    assert len(reads) == 2


def test_a_store_without_a_generation_reads_them_once_a_page(
    client: FlaskClient, kb: KnowledgeBase, reads: list[int]
) -> None:
    """A remote store counts no writes: the table is read again for each page, but once for all the
    IRIs a page shortens (the taxonomy page shortens every class)."""
    kb.store.generation = None  # type: ignore[attr-defined]  # as a remote store has none
    for path in ("/taxonomy", "/taxonomy/class?iri=books1:Book"):
        assert client.get(path).status_code == 200, path
    assert len(reads) == 2
