"""An update of a remote store gets the embedded store's checks, before anything is sent (kb/remote_updates.py).

Against the session's loopback ``oxigraph serve`` (tests/conftest.py), seeded by one request with what a
seed writes; the embedded store given the same update is the reference for the error and its words.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Iterator
from pathlib import Path

import httpx
import pyoxigraph as ox
import pytest

from cbrs.kb import KnowledgeBase
from cbrs.kb.errors import BlankNodeInsertError, QuerySyntaxError, StoreEvaluationError, UndeclaredSuperclassError
from cbrs.kb.namespaces import OWL, RDF, RDFS, GraphName
from cbrs.kb.remote_store import RemoteStore
from cbrs.kb.remote_updates import CheckedCopy, as_on_union, operations
from cbrs.kb.semantic_map import MapError
from cbrs.kb.served_updates import HEADER, claims_checked
from cbrs.kb.shapes import DescriptionShapeError
from cbrs.kb.store import Store, data_block
from cbrs.kb.superclasses import RemovedDeclarationError
from cbrs.server import ServeConfig, Server
from cbrs.sparql_service import EndpointConfig
from tests.conftest import OxigraphServer, VirtuosoServer
from tests.helpers_seeded import put_quads, seeded_quads

EXAMPLES = Path(__file__).parent.parent / "docs" / "examples"
LAB = "PREFIX lab: <https://example.org/lab#>\n"
ENTAILED = b"<https://w3id.org/cbrs/graph/entailed>"
RDFS_LABEL = ox.NamedNode("http://www.w3.org/2000/01/rdf-schema#label")
MAP = GraphName.MAP.node
LAB_GRAPH = ox.NamedNode("https://example.org/lab#g")
SUBCLASS = ox.NamedNode(RDFS + "subClassOf")
UPDATE_TYPE = "application/sparql-update"


@pytest.fixture(scope="module")
def seed() -> bytes:
    return seeded_quads()


@pytest.fixture
def remote(
    remote_location: str, oxigraph_server: OxigraphServer, seed: bytes
) -> Iterator[tuple[KnowledgeBase, list[httpx.Request]]]:
    """A seeded knowledge base on the server, and the requests it sends from now on."""
    put_quads(oxigraph_server, seed)
    kb = KnowledgeBase.open(remote_location)
    assert isinstance(kb.store, RemoteStore)
    seen: list[httpx.Request] = []
    kb.store._http().event_hooks["request"].append(seen.append)
    yield kb, seen
    kb.close()


def _writes(seen: list[httpx.Request]) -> list[str]:
    return [request.content.decode() for request in seen if request.url.path == "/update"]


def _refusal(kb: KnowledgeBase, text: str, error: type[Exception]) -> Exception:
    with pytest.raises(error) as refused:
        kb.update(text)
    return refused.value


REFUSED = [
    pytest.param(
        LAB + "INSERT DATA { GRAPH graph:ontology { lab:Apple rdfs:subClassOf home:Fruit } }",
        UndeclaredSuperclassError,
        id="insert-data-superclass",
    ),
    pytest.param(
        "INSERT { GRAPH graph:ontology { ?c rdfs:subClassOf home:Fruit } }\n"
        "WHERE { GRAPH graph:map { world:Pen a ?c } }",
        UndeclaredSuperclassError,
        id="insert-where-superclass",
    ),
    pytest.param(
        LAB + "INSERT DATA { GRAPH graph:world { lab:note lab:says 'kept?' } } ;\n"
        "DELETE WHERE { GRAPH graph:map { world:Pen home:sizeX ?x } }",
        MapError,
        id="two-operations-map",
    ),
    pytest.param(
        (EXAMPLES / "lab9_mistake_new_table.ru").read_text(encoding="utf-8"), MapError, id="stranded-on-the-table"
    ),
    pytest.param(
        (EXAMPLES / "lab7_mistake_where_is_my_pne.ru").read_text(encoding="utf-8"),
        DescriptionShapeError,
        id="description",
    ),
    pytest.param(  # home:Server stays under it
        "DELETE WHERE { GRAPH graph:ontology { home:ComputingDevice ?p ?o } }",
        RemovedDeclarationError,
        id="removed-declaration",
    ),
]


@pytest.mark.parametrize(("text", "error"), REFUSED)
def test_a_refused_update_sends_nothing_and_says_what_the_embedded_store_says(
    remote: tuple[KnowledgeBase, list[httpx.Request]], text: str, error: type[Exception]
) -> None:
    kb, seen = remote
    before = kb.store.dump()
    on_server = _refusal(kb, text, error)
    assert _writes(seen) == [] and kb.store.dump() == before  # the world graph's note too: all or nothing
    embedded = KnowledgeBase.open(":memory:")
    try:
        reference = _refusal(embedded, text, error)
    finally:
        embedded.close()
    assert str(on_server) == str(reference)
    assert getattr(on_server, "__notes__", None) == getattr(reference, "__notes__", None)


def test_a_where_without_graph_reads_the_union_as_the_server_does(
    remote: tuple[KnowledgeBase, list[httpx.Request]],
) -> None:
    kb, seen = remote
    before = kb.store.dump()
    text = "DELETE { GRAPH graph:map { world:Pen home:sizeX ?x } } WHERE { world:Pen home:sizeX ?x }"
    _refusal(kb, text, MapError)  # the server's default graph is the union: the pattern finds the pen's size
    assert _writes(seen) == [] and kb.store.dump() == before


def test_a_checked_update_writes_what_the_server_would_in_one_request(
    remote: tuple[KnowledgeBase, list[httpx.Request]], oxigraph_server: OxigraphServer, seed: bytes
) -> None:
    kb, seen = remote
    text = (  # no GRAPH in the WHERE: on the server it reads the union, so it finds the pen
        "DELETE { GRAPH graph:map { world:Pen home:x ?x } } INSERT { GRAPH graph:map { world:Pen home:x ?moved } }\n"
        "WHERE { world:Pen home:x ?x BIND (?x + 0.01 AS ?moved) }"
    )
    kb.update(text)
    change, *entailed = _writes(seen)
    assert "DELETE DATA" in change and "INSERT DATA" in change and "WHERE" not in change
    assert all("graph/entailed" in write for write in entailed)
    checked = kb.store.dump()
    oxigraph_server.clear()
    put_quads(oxigraph_server, seed)
    kb.store.update(text)  # the text itself, carried out by the server
    sent = kb.store.dump()
    assert [line for line in checked.splitlines() if ENTAILED not in line] == [
        line for line in sent.splitlines() if ENTAILED not in line
    ]
    assert checked != seed


def test_an_update_nothing_checks_is_sent_as_it_is_without_a_copy(
    remote: tuple[KnowledgeBase, list[httpx.Request]], monkeypatch: pytest.MonkeyPatch
) -> None:
    kb, seen = remote

    def no_copy(*_: object) -> None:
        raise AssertionError("the store was copied")

    monkeypatch.setattr(CheckedCopy, "__init__", no_copy)
    data = "INSERT DATA { GRAPH graph:world { <https://example.org/lab#a> <https://example.org/lab#b> 1 } }"
    clear = "DELETE WHERE { GRAPH graph:world { ?s <https://example.org/lab#b> ?o } }"
    kb.update(data)
    kb.update(clear)
    written = [write for write in _writes(seen) if "graph/entailed" not in write]
    assert len(written) == 2 and written[0].endswith(data) and written[1].endswith(clear)


def test_an_update_of_a_blank_node_the_store_holds_is_sent_as_its_text_once_checked(
    remote: tuple[KnowledgeBase, list[httpx.Request]],
) -> None:
    kb, seen = remote
    graph = ox.NamedNode("https://example.org/lab#g")
    kb.store.add([ox.Quad(ox.BlankNode(), ox.NamedNode("https://example.org/lab#p"), ox.Literal("x"), graph)])
    seen.clear()
    text = LAB + "DELETE { GRAPH lab:g { ?b lab:p ?o } } WHERE { GRAPH lab:g { ?b lab:p ?o } }"
    kb.update(text)  # no data block can name the node: the server is sent the text
    assert text in _writes(seen)[0] and next(iter(kb.store.quads(graph=graph)), None) is None


def test_an_operation_that_fails_on_an_empty_store_runs_on_the_copy(
    remote: tuple[KnowledgeBase, list[httpx.Request]],
) -> None:
    kb, _ = remote
    graph = ox.NamedNode("https://example.org/lab#g")
    kb.store.add([ox.Quad(graph, RDFS_LABEL, ox.Literal("a lab's graph"), graph)])
    kb.update(LAB + "DROP GRAPH lab:g")  # read first on an empty store, where the graph is not
    assert "https://example.org/lab#g" not in kb.store.graphs()
    with pytest.raises(StoreEvaluationError, match=kb.store.location):  # the server's own words: it is not there
        kb.update(LAB + "DROP GRAPH lab:g")


def test_operations_are_split_outside_braces_strings_and_iris_with_the_prologue_carried() -> None:
    text = (
        "PREFIX a: <http://a/;x>\nINSERT DATA { a:s a:p 'a ; b' ; a:q 1 } ;\n# a comment ; here\n"
        "BASE <http://b/> DELETE WHERE { ?s a:p ?o } ;"
    )
    assert operations(text) == [
        ("PREFIX a: <http://a/;x>\n", "INSERT DATA { a:s a:p 'a ; b' ; a:q 1 }"),
        ("PREFIX a: <http://a/;x>\nBASE <http://b/>\n", "DELETE WHERE { ?s a:p ?o }"),
    ]


@pytest.mark.parametrize(
    ("operation", "expected"),
    [
        ("DELETE WHERE { ?s ?p ?o }", "DELETE { ?s ?p ?o }\nUSING <g>\nWHERE { ?s ?p ?o }"),
        ("delete { ?s ?p ?o } insert { ?s ?p 1 } where { ?s ?p ?o }", None),
        ("INSERT { ?s ?p 1 } WHERE { { ?s ?p ?o } UNION { GRAPH ?g { ?s ?p ?o } } }", None),
        ("WITH <h> DELETE { ?s ?p ?o } WHERE { ?s ?p ?o }", "same"),
        ("DELETE { ?s ?p ?o } USING <h> WHERE { ?s ?p ?o }", "same"),
        ("INSERT DATA { <s> <p> 'WHERE' }", "same"),
        ("CLEAR GRAPH <h>", "same"),
    ],
)
def test_an_operation_reads_the_union_unless_it_names_its_dataset(operation: str, expected: str | None) -> None:
    rewritten = as_on_union(operation, "USING <g>")
    if expected == "same":
        assert rewritten == operation
    elif expected is None:  # USING goes just before the top-level WHERE
        at = operation.upper().index("WHERE", operation.index("}"))
        assert rewritten == operation[:at] + "USING <g>\n" + operation[at:]
    else:
        assert rewritten == expected


BROKEN = (
    LAB + "INSERT DATA { GRAPH graph:world { lab:a lab:b 1 } } ;\n"
    'INSERT DATA { GRAPH graph:requirements { lab:R a cbrs:Requirement ; cbrs:hasOWLSModel "x" } }'
)


@pytest.fixture(params=["oxigraph", "virtuoso"])
def unseeded(request: pytest.FixtureRequest) -> Iterator[KnowledgeBase]:
    """A knowledge base on an emptied server holding one quad of its own, not seeded (Virtuoso takes some 10 s
    to seed): the descriptions' shapes are checked all the same."""
    if request.param == "oxigraph":
        url = str(request.getfixturevalue("remote_location"))
    else:
        virtuoso: VirtuosoServer = request.getfixturevalue("virtuoso_server")
        virtuoso.clear()
        url = virtuoso.url
    kb = KnowledgeBase(RemoteStore.open(url))
    kb.store.add([ox.Quad(ox.NamedNode("https://example.org/lab#kept"), RDFS_LABEL, ox.Literal("kept"), MAP)])
    yield kb
    kb.close()


def _ours(store: Store) -> list[str]:
    """The quads of cbrs's graphs and the lab's (not Virtuoso's own, whose blank nodes pyoxigraph refuses)."""
    graphs = [g for g in store.graphs() if g.startswith(("https://w3id.org/cbrs/", "https://example.org/"))]
    return sorted(str(quad) for graph in graphs for quad in store.quads(graph=ox.NamedNode(graph)))


def test_a_refused_request_of_two_operations_leaves_both_servers_as_they_were(unseeded: KnowledgeBase) -> None:
    before = _ours(unseeded.store)
    refused = _refusal(unseeded, BROKEN, DescriptionShapeError)
    assert "nothing was changed" in refused.__notes__ and _ours(unseeded.store) == before  # the world's quad too
    assert len(before) == 1


def test_the_copy_holds_what_the_server_holds(remote: tuple[KnowledgeBase, list[httpx.Request]]) -> None:
    kb, _ = remote
    kb.store.update(LAB + "INSERT DATA { lab:inTheDefaultGraph lab:p 1 . GRAPH lab:g { [] lab:p 2 } }")
    copy = CheckedCopy(kb.store)
    assert _unlabelled(copy.before) == _unlabelled(kb.store.quads()) and len(copy.before) > 8000


def _unlabelled(quads: Iterable[ox.Quad]) -> list[str]:
    """``quads`` as text, a blank node's label left out (the copy's labels are its own)."""
    return sorted(re.sub(r"_:\w+", "_:", str(quad)) for quad in quads)


@pytest.fixture(scope="module")
def served() -> Iterator[tuple[Server, KnowledgeBase, list[httpx.Request]]]:
    """A ``cbrs serve`` (in this process, loopback) on an embedded store, a knowledge base on it, and the
    requests it sends (cleared by each test that reads them). Shared: a test that writes puts it back."""
    server = Server(
        KnowledgeBase.open(":memory:"), ServeConfig(port=0, bridge_port=0, endpoint=EndpointConfig(update_token="t"))
    )
    server.start()
    try:
        client = KnowledgeBase(RemoteStore.open(f"http://127.0.0.1:{server.http_port}", token="t"))
    except BaseException:
        server.stop(timeout=10)
        raise
    assert isinstance(client.store, RemoteStore)
    seen: list[httpx.Request] = []
    client.store._http().event_hooks["request"].append(seen.append)
    yield server, client, seen
    client.close()
    server.stop(timeout=10)


def test_a_cbrs_serve_as_the_remote_store_is_checked_and_reads_its_default_graph(
    served: tuple[Server, KnowledgeBase, list[httpx.Request]],
) -> None:
    server, client, _ = served
    held = server.kb.store.dump()
    _refusal(client, "DELETE WHERE { GRAPH graph:map { world:Pen home:sizeX ?x } }", MapError)
    # its updates run on an embedded store, whose WHERE reads the default graph alone: this finds nothing
    client.update("DELETE { GRAPH graph:map { world:Pen home:sizeX ?x } } WHERE { world:Pen home:sizeX ?x }")
    assert server.kb.store.dump() == held


@pytest.mark.parametrize(("text", "error"), REFUSED)
def test_a_cbrs_serve_is_sent_a_checked_update_as_it_is_and_its_refusal_is_the_embedded_stores(
    served: tuple[Server, KnowledgeBase, list[httpx.Request]],
    monkeypatch: pytest.MonkeyPatch,
    text: str,
    error: type[Exception],
) -> None:
    server, client, seen = served
    assert isinstance(client.store, RemoteStore) and client.store.checks_updates  # from the open's first answer

    def no_copy(*_: object) -> None:
        raise AssertionError("the store was copied: the server checks the update itself")

    monkeypatch.setattr(CheckedCopy, "__init__", no_copy)
    held = server.kb.store.dump()
    seen.clear()
    on_server = _refusal(client, text, error)
    assert [request.url.path for request in seen] == ["/update"] and seen[0].content.decode().endswith(text)
    assert server.kb.store.dump() == held
    embedded = KnowledgeBase.open(":memory:")
    try:
        reference = _refusal(embedded, text, error)
    finally:
        embedded.close()
    assert type(on_server) is type(reference)
    assert str(on_server) == str(reference)
    assert getattr(on_server, "__notes__", None) == getattr(reference, "__notes__", None)


def test_a_cbrs_serve_carries_out_an_update_that_passes_and_keeps_graph_entailed_itself(
    served: tuple[Server, KnowledgeBase, list[httpx.Request]],
) -> None:
    server, client, seen = served
    held = server.kb.store.dump()
    added = "INSERT DATA { GRAPH graph:services { <https://example.org/lab#Cam9> a cbrs:DynamicPerceptionComponent } }"
    reference = KnowledgeBase.open(":memory:")
    try:
        reference.update(added)
        entailed = set(reference.store.quads(graph=GraphName.ENTAILED.node))
    finally:
        reference.close()
    assert entailed != set(server.kb.store.quads(graph=GraphName.ENTAILED.node))  # the update entails something
    seen.clear()
    try:
        client.update(added)
        assert [request.url.path for request in seen] == ["/update"]  # no copy read, no refresh from here
        assert set(client.store.quads(graph=GraphName.ENTAILED.node)) == entailed  # the server's refresh
    finally:
        client.update(added.replace("INSERT", "DELETE"))
    assert server.kb.store.dump() == held


@pytest.mark.parametrize(
    ("text", "error", "words"),
    [
        pytest.param(
            "INSERT DATA { <urn:a> <urn:b> ", QuerySyntaxError, "SPARQL syntax error: error at 1:", id="syntax"
        ),
        pytest.param("DROP GRAPH <urn:x:absent>", StoreEvaluationError, "update failed: ", id="evaluation"),
        pytest.param(
            "INSERT DATA { GRAPH graph:world { <urn:a> <urn:b> _:x } }",
            BlankNodeInsertError,
            "inserts a blank node",
            id="blank",
        ),
    ],
)
def test_a_cbrs_serve_refusing_the_text_itself_is_told_as_the_embedded_store_tells_it(
    served: tuple[Server, KnowledgeBase, list[httpx.Request]], text: str, error: type[Exception], words: str
) -> None:
    _, client, _ = served
    refused = _refusal(client, text, error)
    assert type(refused) is error and words in str(refused)
    assert '"error"' not in str(refused)  # the server's message, not its JSON
    if isinstance(refused, StoreEvaluationError):
        assert str(refused).startswith(f"store {client.store.location}: update failed: ")  # the store as named


def test_only_a_cbrs_server_saying_so_is_taken_to_check_its_updates(
    served: tuple[Server, KnowledgeBase, list[httpx.Request]], remote_location: str
) -> None:
    server, _, _ = served
    base = f"http://127.0.0.1:{server.http_port}"
    for answer in (
        httpx.post(base + "/sparql", data={"query": "ASK {}"}),  # the hot path
        httpx.get(base + "/sparql", headers={"Accept": "text/turtle"}),  # the service description, from Flask
        httpx.post(base + "/update", content=b"CLEAR GRAPH <urn:x>", headers={"Content-Type": UPDATE_TYPE}),
    ):
        assert claims_checked(answer.headers.get(HEADER)), answer.request.url
    assert not claims_checked("cbrs/0.1.0") and not claims_checked("oxigraph/0.4 checked-updates")
    other = RemoteStore.open(remote_location)  # Oxigraph: the copy's path
    try:
        assert not other.checks_updates
    finally:
        other.close()


def test_a_delete_data_of_a_used_terms_last_statements_is_refused_against_the_store_itself(
    remote: tuple[KnowledgeBase, list[httpx.Request]], monkeypatch: pytest.MonkeyPatch
) -> None:
    """A data update that needs no other check is checked with a few lookups on the server, no copy."""
    kb, seen = remote
    term = ox.NamedNode("https://w3id.org/cbrs/home#ComputingDevice")
    text = "DELETE DATA {\n" + data_block(kb.store.quads(term)) + "}"

    def no_copy(*_: object) -> None:
        raise AssertionError("the store was copied")

    monkeypatch.setattr(CheckedCopy, "__init__", no_copy)
    before = kb.store.dump()
    on_server = _refusal(kb, text, RemovedDeclarationError)
    assert _writes(seen) == [] and kb.store.dump() == before
    embedded = KnowledgeBase.open(":memory:")
    try:
        reference = _refusal(embedded, text, RemovedDeclarationError)
    finally:
        embedded.close()
    assert str(on_server) == str(reference) and "home:Server rdfs:subClassOf home:ComputingDevice stays" in str(
        reference
    )


def test_removing_a_used_terms_last_statement_leaves_both_servers_as_they_were(unseeded: KnowledgeBase) -> None:
    """On Oxigraph and Virtuoso, the check on the copy: a DELETE WHERE and a DROP of the graph declaring
    home:Fruit (a lab's, with the home vocabulary's header) are refused while a banana is under it."""
    home = "https://w3id.org/cbrs/home"
    unseeded.store.add(
        [
            ox.Quad(ox.NamedNode(home), ox.NamedNode(RDF + "type"), ox.NamedNode(OWL + "Ontology"), MAP),
            ox.Quad(ox.NamedNode(home + "#Fruit"), ox.NamedNode(RDF + "type"), ox.NamedNode(OWL + "Class"), LAB_GRAPH),
            ox.Quad(ox.NamedNode("https://example.org/lab#Banana"), SUBCLASS, ox.NamedNode(home + "#Fruit"), MAP),
        ]
    )
    before = _ours(unseeded.store)
    for text in (LAB + "DELETE WHERE { GRAPH lab:g { home:Fruit ?p ?o } }", LAB + "DROP GRAPH lab:g"):
        refused = _refusal(unseeded, text, RemovedDeclarationError)
        assert "Banana rdfs:subClassOf home:Fruit stays" in str(refused) and _ours(unseeded.store) == before
