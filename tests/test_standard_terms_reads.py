"""graph:entailed read in few requests (kb/statement_reads.py): a whole refresh writes exactly what the
computation it replaced, one query per aligned class and property, works out, on the embedded store, an
Oxigraph server and Virtuoso, for the bundled data and with aligned data of a user's; VALUES lists split
over several queries and answers read in pages give the same; a refresh and a description's change cost
a remote store a bounded number of requests, whatever the number of aligned terms.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator

import pyoxigraph as ox
import pytest

from cbrs.kb import KnowledgeBase, Store, statement_reads
from cbrs.kb.namespaces import PREFIXES, GraphName
from cbrs.kb.remote_store import RemoteStore
from cbrs.kb.standard_terms import Alignment, StandardTerms, read_alignment, rules
from tests.conftest import OxigraphServer, VirtuosoServer

ENTAILED = GraphName.ENTAILED.node
TEST, SOSA, CBRS = "urn:test:", PREFIXES["sosa"], PREFIXES["cbrs"]
# A user's ontology aligning its own terms (two levels under sosa:Sensor, an equivalent class, a
# subproperty of an aligned property, so with its domain, range and inverse) and data using them: in two
# graphs, in the default graph and in graph:entailed (neither read), about a blank node (not materialised).
USER = f"""
PREFIX t: <{TEST}>
INSERT DATA {{
  GRAPH t:ontology {{
    t:Camera rdfs:subClassOf t:Device . t:Device rdfs:subClassOf sosa:Sensor . t:Eye owl:equivalentClass t:Camera .
    t:watches rdfs:subPropertyOf sosa:observes . t:locatedOn rdfs:subPropertyOf home:mountedOn .
  }}
  GRAPH t:g1 {{ t:cam1 a t:Camera ; t:watches t:room ; rdfs:label "cam" . t:eye1 a t:Eye . t:cam1 t:locatedOn t:wall }}
  GRAPH t:g2 {{ t:cam1 a t:Camera . t:cam2 a t:Device ; t:watches t:cam1 . _:b a t:Camera ; t:watches t:room }}
  GRAPH graph:entailed {{ t:ghost a t:Camera }}
  t:dflt a t:Camera .
}}"""
# Ground statements a Virtuoso can take in a few requests: what the alignments need, and some data.
SMALL = ["core.ttl", "standards/owls.ttl", "standards/sosa.ttl", "standards/qudt.ttl", "standards/soma.ttl"]
SMALL += ["alignments.ttl"]


def per_term_closure(store: Store, alignment: Alignment) -> tuple[set[ox.Quad], set[ox.Quad]]:
    """The computation kb/statement_reads.py replaced, kept as the reference: one query per aligned class
    and per aligned property (StandardTerms._closure before it)."""
    types = "SELECT ?s ?c WHERE { GRAPH ?g { ?s a ?c } FILTER (?g != graph:entailed && isIRI(?s)) }"
    uses = "SELECT ?s ?p ?o WHERE { GRAPH ?g { ?s ?p ?o } FILTER (?g != graph:entailed && isIRI(?s)) }"
    triples: set[ox.Triple] = set()
    asserted: set[ox.Triple] = set()
    kind = ox.NamedNode(PREFIXES["rdf"] + "type")
    for cls in sorted(alignment.classes()):
        for row in store.query(types, {"c": ox.NamedNode(cls)}):  # type: ignore[union-attr]
            asserted.add(ox.Triple(row["s"], kind, row["c"]))
            triples.update(alignment.typed(row["s"], cls))
    for prop in sorted(alignment.properties()):
        for row in store.query(uses, {"p": ox.NamedNode(prop)}):  # type: ignore[union-attr]
            asserted.add(ox.Triple(row["s"], row["p"], row["o"]))
            triples.update(alignment.statement(row["s"], prop, row["o"]))

    def quad(t: ox.Triple) -> ox.Quad:
        return ox.Quad(t.subject, t.predicate, t.object, ENTAILED)

    named = {t for t in triples - asserted if not isinstance(t.subject, ox.BlankNode)}
    return {quad(t) for t in named if not isinstance(t.object, ox.BlankNode)}, {quad(t) for t in asserted}


def reference(store: Store) -> set[ox.Quad]:
    """What graph:entailed must hold, by the per-term computation (as kb.standard_terms.entailed combines it)."""
    terms = StandardTerms(store)
    alignment = read_alignment(store)
    wanted, asserted = per_term_closure(store, alignment)
    return wanted | (terms._rule_conclusions(alignment) - asserted)


def held(store: Store) -> set[ox.Quad]:
    return set(store.quads(graph=ENTAILED))


class Requests:
    """The HTTP requests remote stores send (their one sending method, counted)."""

    def __init__(self, monkeypatch: pytest.MonkeyPatch) -> None:
        self.sent = 0
        send = RemoteStore._post

        def counted(store: RemoteStore, *args: object, **kwargs: object) -> object:
            self.sent += 1
            return send(store, *args, **kwargs)  # type: ignore[arg-type]

        monkeypatch.setattr(RemoteStore, "_post", counted)

    def of(self, action: Callable[[], object]) -> int:
        before = self.sent
        action()
        return self.sent - before


@pytest.fixture(scope="module")
def bundled_quads(bundled_kb: KnowledgeBase) -> list[ox.Quad]:
    """The seeded store's statements but graph:entailed's: what the servers are filled with."""
    return [q for q in bundled_kb.store.quads() if q.graph_name != ENTAILED]


@pytest.fixture(scope="module")
def small_quads() -> list[ox.Quad]:
    """The standards, the alignments, the core ontology and the mini services, skolemised by a load."""
    from cbrs.kb.resources import ontology_dir
    from tests.conftest import MINI_FILES

    kb = KnowledgeBase(Store.open(":memory:"))
    kb.load([ontology_dir() / name for name in SMALL], graph="ontology")
    kb.load(MINI_FILES[1:])
    found = [q for q in kb.store.quads() if q.graph_name != ENTAILED]
    kb.close()
    return found


def filled(store: Store, quads: list[ox.Quad], user: bool) -> Store:
    store.add(quads)
    if user:
        scratch = ox.Store()
        scratch.update(USER, prefixes=PREFIXES)
        # Virtuoso takes neither a blank node nor the default graph in INSERT DATA
        virtuoso = isinstance(store, RemoteStore) and store.server == "virtuoso"
        store.add(
            q
            for q in scratch
            if not (virtuoso and (isinstance(q.subject, ox.BlankNode) or isinstance(q.graph_name, ox.DefaultGraph)))
        )
    store.query("ASK {}")  # a remote store opened empty checks its union default graph here, once
    return store


@pytest.mark.parametrize("user", [False, True], ids=["bundled", "user-aligned"])
def test_the_embedded_store_refreshes_to_what_the_per_term_computation_gives(
    bundled_quads: list[ox.Quad], user: bool
) -> None:
    store = filled(Store.open(":memory:"), bundled_quads, user)
    StandardTerms(store).refresh()
    entailed = held(store)
    assert entailed == reference(store)
    if user:  # the user's data reached: through two levels, an equivalence, a subproperty's range and inverse
        assert store.query(
            f"PREFIX t: <{TEST}> ASK {{ GRAPH graph:entailed {{ t:cam1 a sosa:Sensor ; sosa:observes t:room . "
            "t:eye1 a sosa:Sensor . t:room sosa:isObservedBy t:cam1 } }"
        )
        assert not {q for q in entailed if q.subject in (ox.NamedNode(TEST + "dflt"), ox.NamedNode(TEST + "ghost"))}
    store.close()


@pytest.fixture
def oxigraph_store(oxigraph_server: OxigraphServer) -> Iterator[Store]:
    oxigraph_server.clear()
    store = Store.open(oxigraph_server.url)
    yield store
    store.close()


@pytest.mark.parametrize("user", [False, True], ids=["bundled", "user-aligned"])
def test_an_oxigraph_server_refreshes_to_what_the_per_term_computation_and_the_embedded_store_give(
    oxigraph_store: Store, bundled_quads: list[ox.Quad], user: bool, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The same graph:entailed as on the embedded store, in at most: the alignments (2 queries), the rules
    before and after the first write, the statements (2 queries, types and properties: each under
    TERMS_PER_QUERY terms, and Oxigraph cuts no answer), graph:entailed as held (1), and the two writes
    (each under Oxigraph's batch)."""
    store = filled(oxigraph_store, bundled_quads, user)
    requests = Requests(monkeypatch)
    sent = requests.of(StandardTerms(store).refresh)
    assert held(store) == reference(store)
    embedded = filled(Store.open(":memory:"), bundled_quads, user)
    StandardTerms(embedded).refresh()
    assert held(store) == held(embedded)
    assert sent <= 2 + 2 * len(rules()) + 2 + 1 + 2  # it was 142 with one query per aligned term


def test_a_deregistration_costs_a_remote_store_few_requests(
    oxigraph_store: Store, bundled_quads: list[ox.Quad], monkeypatch: pytest.MonkeyPatch
) -> None:
    """Bringing graph:entailed up to date after a description went (StandardTerms.changed on a remote
    store) reads the statements about all its nodes in two queries (those they are the subject of, and
    the object through a property with a range or an inverse), then: the first write, the rules, the second
    write; before, a query per node and per node and such property (95 here)."""
    kb = KnowledgeBase(filled(oxigraph_store, bundled_quads, user=False))
    kb.refresh_standard_terms()
    requests = Requests(monkeypatch)
    changes: list[int] = []
    changed = kb.standard_terms.changed

    def counted(*args: object) -> object:
        before = requests.sent
        result = changed(*args)  # type: ignore[arg-type]
        changes.append(requests.sent - before)
        return result

    monkeypatch.setattr(kb.registry._standard_terms, "changed", counted)
    kb.registry.deregister(PREFIXES["svc"] + "LocateMobileRobot_CeilingCamera01")
    assert held(kb.store) == reference(kb.store)
    assert len(changes) == 1 and changes[0] <= 2 + 1 + len(rules()) + 1


@pytest.mark.parametrize("server", ["oxigraph", "virtuoso"])
def test_split_lists_and_paged_answers_give_the_same_graph_entailed(
    server: str, small_quads: list[ox.Quad], request: pytest.FixtureRequest, monkeypatch: pytest.MonkeyPatch
) -> None:
    """With a few terms a query and a few rows a page (paged on Oxigraph too), every statement is still
    read once: on Virtuoso the pages are its ordered-subquery form, and each query joins VALUES blocks.
    The per-term computation runs once (140 requests, a second on Virtuoso); after an update and a
    deregistration read that way, a whole refresh read the usual way finds nothing to change."""
    if server == "oxigraph":
        running: OxigraphServer | VirtuosoServer = request.getfixturevalue("oxigraph_server")
    else:
        running = request.getfixturevalue("virtuoso_server")
    running.clear()
    store = filled(Store.open(running.url), small_quads, user=True)
    try:
        kb = KnowledgeBase(store)
        kb.refresh_standard_terms()
        alignment = read_alignment(store)
        wanted, asserted = per_term_closure(store, alignment)
        assert held(store) == wanted | (kb.standard_terms._rule_conclusions(alignment) - asserted)
        with monkeypatch.context() as split:
            split.setattr(statement_reads, "TERMS_PER_QUERY", 30)  # a type pattern's share: 15 classes
            split.setattr(statement_reads, "ROWS_PER_PAGE", 40)
            split.setattr(RemoteStore, "server", property(lambda _: "other"))
            requests = Requests(split)
            sent = requests.of(lambda: StandardTerms(store)._closure(alignment))
            assert StandardTerms(store)._closure(alignment)[0] == wanted
            queries = -(-len(alignment.classes()) // 15) + -(-len(alignment.properties()) // 30)
            assert len(asserted) > 40 and sent >= queries > 2  # several queries, one at least read in pages
            before = held(store)
            store.update(f"DELETE DATA {{ GRAPH <{TEST}g2> {{ <{TEST}cam2> <{TEST}watches> <{TEST}cam1> }} }}")
            kb.refresh_standard_terms()
            assert held(store) != before
            kb.registry.deregister("http://example.org/mini#Locate")  # its nodes' statements, split and paged
        again = StandardTerms(store).refresh()
        assert again.added == again.removed == 0
    finally:
        store.close()


def test_no_aligned_terms_reads_nothing() -> None:
    store = Store.open(":memory:")
    assert statement_reads.statements(store, [{"p": []}, {"s": [], "o": [ox.NamedNode(CBRS + "x")]}]) == set()
    assert list(statement_reads.queries([])) == []
