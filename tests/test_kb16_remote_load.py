"""A load into a remote store writes only the triples the store lacks, as one into an embedded store does
(tests/test_load_writes_new.py), and asks which it holds with one query per graph and chunk of quads
(``RemoteStore.contains_each``), never a request per triple: a reload of OWLS-TC 4 into an Oxigraph
server took minutes of single-quad requests. Each test runs on ``oxigraph serve`` and on Virtuoso 7
(skipped where it is not installed), whose ``VALUES`` joins differ (docs/remote-store.md)."""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator
from pathlib import Path
from urllib.parse import unquote_plus

import pyoxigraph as ox
import pytest

from cbrs.kb import KnowledgeBase, RdfParseError, Store, StoreError
from cbrs.kb.catalog import Catalogue
from cbrs.kb.loader import load_files
from cbrs.kb.namespaces import GraphName
from cbrs.kb.remote_store import RemoteStore
from cbrs.kb.staged_writes import STAGING
from tests.conftest import OxigraphServer, VirtuosoServer
from tests.test_remote_servers import SERVERS

from .test_load_counts import NAVIGATE, ONTOLOGY, OVERLAP, THREE, _write

EX = "http://example.org/counts#"
FORM = "application/x-www-form-urlencoded"
SERVICES = GraphName.SERVICES.node
DECIMAL = ox.NamedNode("http://www.w3.org/2001/XMLSchema#decimal")
# literals whose text a SPARQL query must escape (one language-tagged: Virtuoso joins none from VALUES);
# an IRI with characters a query could misread
AWKWARD = [
    ox.Literal('say "hi" } ; DROP ALL ; {'),
    ox.Literal("two\nlines and a # and a \\ backslash"),
    ox.Literal("'''long quote'''", language="en"),
    ox.Literal("0.50", datatype=DECIMAL),  # kept as "0.5" by Oxigraph
    ox.NamedNode("http://example.org/counts#odd?q=1&r=%7B"),
]


@pytest.fixture(scope="module", params=SERVERS)
def server(request: pytest.FixtureRequest) -> str:
    """The ``--store`` URL of a server seeded once for the module: Oxigraph's base URL, Virtuoso's one
    ``/sparql`` URL. Each test writes triples of its own (``ex:``, OWL-S's navigate service) and reads
    what its own writes did, so that they can share the seed (Virtuoso takes some 10 s to write it)."""
    if request.param == "oxigraph":
        servers: Callable[..., OxigraphServer] = request.getfixturevalue("oxigraph_servers")
        url = servers(on_disk=False).url
    else:
        virtuoso: VirtuosoServer = request.getfixturevalue("virtuoso_server")
        virtuoso.clear()
        url = virtuoso.url
    KnowledgeBase.open(url).close()
    return url


@pytest.fixture
def kb(server: str) -> Iterator[KnowledgeBase]:
    kb = KnowledgeBase.open(server)
    assert isinstance(kb.store, RemoteStore)
    yield kb
    kb.close()


def _node(name: str) -> ox.NamedNode:
    return ox.NamedNode(EX + name)


def _requests(store: RemoteStore, monkeypatch: pytest.MonkeyPatch) -> list[tuple[str, str, str]]:
    """The endpoint, body and content type of each HTTP request ``store`` makes from now on."""
    sent: list[tuple[str, str, str]] = []
    post = store._post

    def recorded(url: str, body: str, content_type: str, *args: object, **kwargs: object) -> object:
        sent.append((url, body, content_type))
        return post(url, body, content_type, *args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(store, "_post", recorded)
    return sent


def _adds(store: Store, monkeypatch: pytest.MonkeyPatch) -> list[list[ox.Quad]]:
    calls: list[list[ox.Quad]] = []
    add = store.add

    def recorded(quads: Iterable[ox.Quad]) -> None:
        quads = list(quads)
        calls.append(quads)
        add(quads)

    monkeypatch.setattr(store, "add", recorded)
    return calls


def _ours(store: Store) -> list[str]:
    """The quads of the cbrs graphs and of the staging graphs (not Virtuoso's own graphs), sorted."""
    return sorted(
        str(quad)
        for graph in store.graphs()
        if graph.startswith("https://w3id.org/cbrs/")
        for quad in store.quads(graph=ox.NamedNode(graph))
    )


def test_the_store_says_which_quads_it_holds_in_chunks(
    kb: KnowledgeBase, server: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    store = kb.store
    assert isinstance(store, RemoteStore)
    world = GraphName.WORLD.node
    held = [ox.Quad(_node(f"s{i}"), _node("p"), term, world) for i, term in enumerate(AWKWARD)]
    held += [ox.Quad(_node(f"n{i}"), _node("p"), ox.Literal(f"v{i}"), world) for i in range(7)]
    store.add(held)
    asked = [
        *held,
        ox.Quad(_node("s0"), _node("p"), AWKWARD[0], SERVICES),  # held, but in another graph
        ox.Quad(_node("s1"), _node("p"), ox.Literal("two\nlines"), world),  # another literal
        ox.Quad(_node("s3"), _node("p"), ox.Literal("0.5", datatype=DECIMAL), world),  # the form it is kept in
        ox.Quad(_node("s2"), _node("p"), ox.Literal("'''long quote'''", language="de"), world),
        ox.Quad(_node("gone"), _node("p"), ox.Literal("v1"), world),
        ox.Quad(ox.BlankNode("b"), _node("p"), ox.Literal("v1"), world),  # names nothing on the server
    ]
    store.batch = 4  # chunks of 4 quads: the 12 of graph:world in 4 queries, graph:services' one in 1
    sent = _requests(store, monkeypatch)
    answer = store.contains_each(asked)
    virtuoso = server.endswith("/sparql")  # the two language-tagged literals asked in a query of their own
    assert len(sent) == (6 if virtuoso else 5)
    assert sum("VALUES (?i ?s ?p ?o)" in unquote_plus(body) for _, body, _ in sent) == 5
    # Oxigraph takes the long text as the body, unencoded; Virtuoso answers only a form
    assert {kind for _, _, kind in sent} == {FORM if virtuoso else "application/sparql-query"}
    assert answer == [True] * len(held) + [False, False, True, False, False, False]
    assert answer[:-1] == [store.contains(quad) for quad in asked[:-1]]  # what it says of each alone


def test_a_reload_writes_nothing_and_asks_per_chunk(
    kb: KnowledgeBase, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Before, the OWL-S merge check asked the server about each triple of a file whose service it held
    (one request each), then the load wrote every triple again."""
    files = [_write(tmp_path, "three.ttl", THREE), NAVIGATE]
    first = kb.load(files, catalogue=ONTOLOGY)
    assert first.added_quads > 0
    before = _ours(kb.store)
    assert isinstance(kb.store, RemoteStore)
    sent = _requests(kb.store, monkeypatch)
    adds = _adds(kb.store, monkeypatch)
    again = load_files(kb.store, files, catalogue=Catalogue.open(ONTOLOGY))
    if kb.store.rewrites_held:  # Virtuoso: every quad written again (a read may lag a drop), counted as held
        assert [len(added) for added in adds] == [again.quads]
    else:
        assert adds == []
        assert [url for url, _, _ in sent if url != kb.store.endpoints.query] == []  # no update at all
    checks = [body for _, body, _ in sent if "VALUES (?i ?s ?p ?o)" in unquote_plus(body)]
    assert 1 <= len(checks) <= 3  # one per graph the files write (graph:services, graph:ontology)
    assert len(sent) < 30 < again.quads  # not a request per triple
    assert (again.added_quads, again.already_present) == (0, again.quads)
    assert [item.added for item in again.files] == [{}, {}]  # counted per file, as on an embedded store
    assert _ours(kb.store) == before


def test_a_partly_held_file_writes_only_its_new_triple(
    kb: KnowledgeBase, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    kb.load([_write(tmp_path, "three.ttl", THREE)])
    adds = _adds(kb.store, monkeypatch)
    report = kb.load([_write(tmp_path, "overlap.ttl", OVERLAP)])
    new = ox.Quad(_node("g"), _node("p"), _node("h"), SERVICES)
    if kb.store.rewrites_held:  # Virtuoso: the whole file written (a read may lag a drop); counted the same
        assert len(adds) == 1 and new in adds[0] and len(adds[0]) == report.quads
    else:
        assert adds == [[new]]
    assert report.added == {SERVICES.value: 1}
    assert report.files[0].added == {SERVICES.value: 1}


def test_a_failed_write_of_the_new_triples_leaves_the_store_as_it_was(
    kb: KnowledgeBase, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The triples the store lacks are written as every remote write is, all or nothing: staged past the
    batch size, and here the publication fails; the staging graphs are dropped again."""
    store = kb.store
    assert isinstance(store, RemoteStore)
    kb.load([_write(tmp_path, "three.ttl", THREE)])
    before = _ours(store)
    many = "".join(f"ex:n{i} ex:p ex:m{i} .\n" for i in range(12))
    bigger = _write(tmp_path, "bigger.ttl", THREE + many)
    store.batch = 5  # 12 new triples: staged in three batches, then published
    update = store._update

    def failing(text: str, original: str | None) -> None:
        if text.lstrip().startswith("INSERT {"):
            raise StoreError(store.location, "the publication failed (simulated)")
        update(text, original)

    monkeypatch.setattr(store, "_update", failing)
    with pytest.raises(StoreError, match="simulated"):
        kb.load([bigger])
    assert _ours(store) == before
    assert not [graph for graph in store.graphs() if graph.startswith(STAGING)]


def test_a_failed_parse_after_a_partly_held_file_writes_nothing(kb: KnowledgeBase, tmp_path: Path) -> None:
    kb.load([_write(tmp_path, "three.ttl", THREE)])
    before = _ours(kb.store)
    broken = _write(tmp_path, "z_broken.ttl", "@prefix ex: <http://example.org/counts#> .\nex:x ex:p .\n")
    with pytest.raises(RdfParseError, match=r"z_broken\.ttl"):
        kb.load([_write(tmp_path, "overlap.ttl", OVERLAP), broken])
    assert _ours(kb.store) == before
