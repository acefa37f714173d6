"""An update through the library or the endpoint's /update that would leave a readable semantic map
unreadable is refused and changes nothing, as ``cbrs update`` and a load into graph:map are; an update
that cannot write graph:map is not checked at all (docs/serving.md)."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest
from flask.testing import FlaskClient

from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import PREFIXES, GraphName
from cbrs.kb.semantic_map import MapError, SemanticMap
from cbrs.sparql_service import EndpointConfig, SparqlService
from cbrs.web import create_app

TOKEN = "map trial token"
MAP = "https://w3id.org/cbrs/graph/map"
TURTLE = "text/turtle"
WORLD_PREFIX = f"@prefix world: <{PREFIXES['world']}> . @prefix home: <{PREFIXES['home']}> . "
BREAKS = {
    "data": 'INSERT DATA { GRAPH graph:map { world:Pen home:shapeKind "sphere" } }',
    "where": "DELETE WHERE { GRAPH graph:map { world:Pen home:sizeX ?x } }",
    "where-after-data": (
        "INSERT DATA { GRAPH <urn:example:lab> { <urn:example:a> <urn:example:b> <urn:example:c> } } ;\n"
        "DELETE WHERE { GRAPH graph:map { world:Pen home:sizeX ?x } }"
    ),
}
LAB = "<urn:example:a> <urn:example:b> 1"
MOVE = (
    "DELETE { GRAPH graph:map { world:Pen home:yaw ?y } } INSERT { GRAPH graph:map { world:Pen home:yaw 0.5 } } "
    "WHERE { GRAPH graph:map { world:Pen home:yaw ?y } }"
)


@pytest.fixture(scope="module")
def kb() -> Iterator[KnowledgeBase]:
    """One seeded store for the module: its tests leave its map readable."""
    kb = KnowledgeBase.open(":memory:")
    yield kb
    kb.close()


@pytest.fixture(scope="module")
def client(kb: KnowledgeBase) -> FlaskClient:
    return create_app(SparqlService(kb, EndpointConfig(update_token=TOKEN))).test_client()


def _post(client: FlaskClient, text: str) -> Any:
    headers = {"Authorization": f"Bearer {TOKEN}"}
    return client.post("/update", data=text.encode(), content_type="application/sparql-update", headers=headers)


@pytest.mark.parametrize("text", BREAKS.values(), ids=BREAKS.keys())
def test_the_endpoint_refuses_an_update_that_breaks_the_map_and_changes_nothing(
    kb: KnowledgeBase, client: FlaskClient, text: str
) -> None:
    before = kb.store.dump()
    response = _post(client, text)
    assert response.status_code == 422
    body = response.get_json()
    assert body["error"] == "MapError" and body["message"].startswith("semantic map: Pen (")
    assert kb.store.dump() == before  # the other graph's write in the same request is gone too
    with pytest.raises(MapError) as direct:  # the message is the one the map's reader gives
        kb.update(text)
    assert body["message"] == str(direct.value)


def test_the_endpoint_takes_a_map_update_that_leaves_it_readable(kb: KnowledgeBase, client: FlaskClient) -> None:
    assert _post(client, MOVE).status_code == 204
    assert SemanticMap.read(kb).objects[PREFIXES["world"] + "Pen"].start.yaw == 0.5


def test_the_library_refuses_it_unless_told_not_to_check() -> None:
    kb = KnowledgeBase.open(":memory:")
    before = kb.store.dump()
    with pytest.raises(MapError) as refused:
        kb.update(BREAKS["where"])
    assert "nothing was changed" in "\n".join(refused.value.__notes__)
    assert kb.store.dump() == before
    kb.update(BREAKS["where"], check_map=False)  # a map broken on purpose: the reader says what is wrong
    with pytest.raises(MapError, match="has no home:sizeX"):
        SemanticMap.read(kb)


@pytest.mark.parametrize(
    ("text", "read"),
    [
        pytest.param(f"INSERT DATA {{ GRAPH <urn:example:lab> {{ {LAB} }} }}", False, id="data"),
        pytest.param(f"DELETE DATA {{ GRAPH <urn:example:lab> {{ {LAB} }} }}", False, id="delete"),
        pytest.param(
            "DELETE { GRAPH <urn:example:lab> { ?s ?p ?o } } WHERE { GRAPH <urn:example:lab> { ?s ?p ?o } }",
            False,
            id="where",
        ),
        pytest.param(MOVE.replace("0.5", "0.25"), True, id="map-where"),  # a value it did not have
        pytest.param("INSERT DATA { GRAPH graph:map { world:Pen rdfs:comment 'x' } }", True, id="map-data"),
        pytest.param("DELETE DATA { GRAPH graph:map { world:Pen rdfs:comment 'x' } }", True, id="map-delete"),
    ],
)
def test_only_an_update_that_may_write_the_map_reads_it(
    kb: KnowledgeBase, monkeypatch: pytest.MonkeyPatch, text: str, read: bool
) -> None:
    reads: list[KnowledgeBase] = []
    real = SemanticMap.read.__func__  # type: ignore[attr-defined]

    def counted(cls: type[SemanticMap], base: KnowledgeBase) -> SemanticMap:
        reads.append(base)
        return real(cls, base)  # type: ignore[no-any-return]

    kb._map_read = None  # no answer kept from an earlier test
    monkeypatch.setattr(SemanticMap, "read", classmethod(counted))
    kb.update(text)
    assert len(reads) == int(read)  # once, after the update: whether it read before is asked only if not now


@pytest.mark.parametrize(
    "text",
    [
        pytest.param("INSERT DATA { GRAPH graph:map { world:Cup rdfs:comment 'still broken' } }", id="data"),
        pytest.param(
            "DELETE { GRAPH graph:map { world:Cup home:yaw ?y } } INSERT { GRAPH graph:map { world:Cup home:yaw 0.3 } }"
            " WHERE { GRAPH graph:map { world:Cup home:yaw ?y } }",
            id="where",
        ),
    ],
)
def test_an_update_of_a_map_that_did_not_read_before_stands(text: str) -> None:
    """Left to the reader's error, as a load into such a map is: it was not this update that broke it."""
    kb = KnowledgeBase.open(":memory:")
    kb.update(BREAKS["where"], check_map=False)
    graph = GraphName.MAP.node
    broken = set(kb.store.quads(graph=graph))
    kb.update(text)  # undone to see whether the map read before, then written again
    changed = set(kb.store.quads(graph=graph)) ^ broken
    assert changed and {quad.subject.value for quad in changed} == {PREFIXES["world"] + "Cup"}
    with pytest.raises(MapError, match="has no home:sizeX"):
        SemanticMap.read(kb)


@pytest.mark.parametrize(
    ("method", "target", "body", "media_type"),
    [
        pytest.param("put", f"?graph={MAP}", WORLD_PREFIX + 'world:Pen home:shapeKind "box" .', TURTLE, id="put"),
        pytest.param("post", f"?graph={MAP}", WORLD_PREFIX + 'world:Pen home:shapeKind "sphere" .', TURTLE, id="post"),
        pytest.param(
            "post",
            "",
            f"<urn:example:lab> {{ <urn:example:a> <urn:example:b> 1 }} <{MAP}> {{ <{PREFIXES['world']}Pen> "
            f'<{PREFIXES["home"]}shapeKind> "sphere" }}',
            "application/trig",
            id="post-dataset",
        ),
    ],
)
def test_the_graph_store_refuses_a_write_that_breaks_the_map_and_writes_nothing(
    kb: KnowledgeBase, client: FlaskClient, method: str, target: str, body: str, media_type: str
) -> None:
    before = kb.store.dump()
    send = getattr(client, method)
    response = send(f"/store{target}", data=body, content_type=media_type, headers={"Authorization": f"Bearer {TOKEN}"})
    assert response.status_code == 422
    assert response.get_json()["message"].startswith("semantic map: Pen (")
    assert kb.store.dump() == before


def test_the_graph_store_takes_a_map_that_reads(kb: KnowledgeBase, client: FlaskClient) -> None:
    auth = {"Authorization": f"Bearer {TOKEN}"}
    stored = client.get(f"/store?graph={MAP}", headers={"Accept": TURTLE}).data
    assert client.put(f"/store?graph={MAP}", data=stored, content_type=TURTLE, headers=auth).status_code == 204
    comment = WORLD_PREFIX + 'world:Pen <http://www.w3.org/2000/01/rdf-schema#comment> "the blue one" .'
    assert client.post(f"/store?graph={MAP}", data=comment, content_type=TURTLE, headers=auth).status_code == 204
    assert PREFIXES["world"] + "Pen" in SemanticMap.read(kb).objects


def test_a_put_of_the_map_is_checked_as_a_whole_home(kb: KnowledgeBase, client: FlaskClient) -> None:
    """A PUT replaces the home, as ``cbrs load --graph map --replace`` does, and is checked as one:
    a map whose mobile robot starts in no room (which reads, thing by thing) is refused, and nothing is
    written. (A map without the mobile robot is taken: tests/test_no_base.py.)"""
    auth = {"Authorization": f"Bearer {TOKEN}"}
    stored = client.get(f"/store?graph={MAP}", headers={"Accept": "application/n-triples"}).data.decode()
    base_x = f"<{PREFIXES['svc']}P3DX01> <{PREFIXES['home']}x> "
    outside = "\n".join(
        f'{base_x}"30.0"^^<http://www.w3.org/2001/XMLSchema#decimal> .' if line.startswith(base_x) else line
        for line in stored.splitlines()
    )
    assert outside != stored
    before = kb.store.dump()
    response = client.put(f"/store?graph={MAP}", data=outside, content_type="application/n-triples", headers=auth)
    assert response.status_code == 422
    message = response.get_json()["message"]
    assert "P3DX01" in message and "in no room of the map" in message
    assert kb.store.dump() == before
