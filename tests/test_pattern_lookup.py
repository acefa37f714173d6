"""Point lookups without the SPARQL engine (cbrs.pattern_lookup): the same bytes as Oxigraph's answer.

The oracle is Oxigraph itself: the query evaluated by pyoxigraph's SPARQL engine over the union default
graph with cbrs's prefixes, as the endpoint's single-scan path evaluates it, serialised as SPARQL JSON.
Equal bytes mean the same head, the same bindings as a multiset, and the same order (so ``LIMIT``
keeps the same solutions).
"""

from __future__ import annotations

import json
import random
import time
from collections import Counter
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pyoxigraph as ox
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from cbrs import pattern_lookup
from cbrs.kb import KnowledgeBase
from cbrs.kb.errors import QuerySyntaxError
from cbrs.kb.namespaces import PREFIXES
from cbrs.scan_queries import single_scan, uses_prefixes
from cbrs.sparql_service import EndpointConfig, QueryTimeoutError, ResultTooLargeError, SparqlService

EX = "http://example.org/lookup/"
RDF_TYPE = "http://www.w3.org/1999/02/22-rdf-syntax-ns#type"
XSD = "http://www.w3.org/2001/XMLSchema#"
HOME = PREFIXES["home"]
# Subjects and IRI objects: plain, non-ASCII, one in a namespace of cbrs's prefix table, and one that is in
# no triple (a lookup that finds nothing).
IRIS = [f"{EX}a", f"{EX}b", f"{EX}ç/é#x", f"{HOME}Cup", f"{EX}absent"]
PREDICATES = [f"{EX}p", f"{EX}q", RDF_TYPE, f"{HOME}on"]
TEXTS = ["", "plain", 'quote " and \\ back', "line\nbreak\ttab\x01\x1f\x7f", "éß 中文 😀 \u2028", "\U0010fffd"]


def random_store(rng: random.Random, store: ox.Store) -> None:
    """Fill ``store`` with triples over a few terms, each in one or more of the default graph and
    named graphs (an IRI, a blank node): the union default graph then repeats them."""
    graphs: list[ox.NamedNode | ox.BlankNode | ox.DefaultGraph] = [
        ox.DefaultGraph(), ox.NamedNode(f"{EX}g1"), ox.NamedNode(f"{EX}g2"), ox.BlankNode("graph"),
    ]  # fmt: skip
    subjects: list[Any] = [ox.NamedNode(iri) for iri in IRIS[:-1]] + [ox.BlankNode("b1"), ox.BlankNode("b2")]
    for _ in range(rng.randrange(1, 60)):
        subject = rng.choice(subjects)
        predicate = ox.NamedNode(rng.choice(PREDICATES))
        obj = random_object(rng, subjects)
        for graph in rng.sample(graphs, rng.randrange(1, len(graphs) + 1)):
            store.add(ox.Quad(subject, predicate, obj, graph))


def random_object(rng: random.Random, subjects: list[Any]) -> Any:
    kind = rng.randrange(7)
    text = rng.choice(TEXTS)
    if kind == 0:
        return ox.Literal(text)
    if kind == 1:
        return ox.Literal(text, language=rng.choice(["en", "en-GB", "fr-be", "ar"]))
    if kind == 2:
        direction = rng.choice([ox.BaseDirection.LTR, ox.BaseDirection.RTL])
        return ox.Literal(text, language=rng.choice(["en", "ar"]), direction=direction)
    if kind == 3:
        datatype = rng.choice([f"{XSD}integer", f"{XSD}string", f"{XSD}boolean", f"{EX}type"])
        return ox.Literal(
            str(rng.randrange(-3, 3)) if datatype != f"{EX}type" else text, datatype=ox.NamedNode(datatype)
        )
    if kind == 4:
        return ox.Triple(rng.choice(subjects[:3]), ox.NamedNode(f"{EX}p"), ox.Literal(text))
    return rng.choice(subjects)


def random_lookup(rng: random.Random) -> str:
    """A query of the shape cbrs.pattern_lookup takes: one pattern of IRIs (written whole or as prefixed
    names), ``a`` and variables, SELECT (some variables or *) or ASK, with or without LIMIT."""
    prologue: list[str] = []
    if rng.random() < 0.3:
        prologue.append(f"PREFIX ex: <{EX}>")
    if rng.random() < 0.2:
        prologue.append(f"PREFIX home: <{EX}>")  # the query's own declaration wins over cbrs's table

    declared = " ".join(prologue)

    def iri(value: str) -> str:
        local = value[len(EX) :]
        if value.startswith(EX) and local.isalnum() and local.isascii() and rng.random() < 0.6:
            if "PREFIX ex:" in declared:
                return f"ex:{local}"
            if "PREFIX home:" in declared:
                return f"home:{local}"
        if value.startswith(HOME) and "PREFIX home:" not in declared and rng.random() < 0.5:
            return f"home:{value[len(HOME) :]}"
        return f"<{value}>"

    names = rng.sample(["s", "p", "o", "x", "y1", "_z", "Ab"], 3)
    sigils = [rng.choice("?$") for _ in names]
    bound = rng.sample([0, 1, 2], rng.randrange(1, 4))  # at least one bound term: a single scan
    terms = []
    for position in range(3):
        if position not in bound:
            terms.append(sigils[position] + names[position])
        elif position == 1:
            predicate = rng.choice(PREDICATES)
            terms.append("a" if predicate == RDF_TYPE and rng.random() < 0.5 else iri(predicate))
        else:
            terms.append(iri(rng.choice(IRIS)))
    variables = [names[i] for i in range(3) if i not in bound]
    space = rng.choice([" ", "\n", "\t "])
    form = rng.randrange(4)
    if form == 0:
        head = "ASK"
    elif form == 1:
        head = "SELECT *"
    else:
        projected = rng.sample(variables, rng.randrange(len(variables) + 1)) + (["unbound"] if form == 3 else [])
        if not projected:
            projected = ["unbound"]
        head = "SELECT " + " ".join(rng.choice("?$") + name for name in projected)
    where = rng.choice(["WHERE ", "where", ""])
    limit = f"{space}LIMIT {rng.randrange(6)}" if rng.random() < 0.4 else ""
    dot = rng.choice(["", " .", "."])
    return f"{' '.join(prologue)}{space}{head}{space}{where}{{ {space.join(terms)}{dot} }}{limit}"


def engine(store: ox.Store, text: str) -> bytes:
    """Oxigraph's own answer, evaluated as the endpoint's single-scan path evaluates it."""
    prefixes = PREFIXES if uses_prefixes(text) else None
    result: Any = store.query(text, prefixes=prefixes, use_default_graph_as_union=True)
    return bytes(result.serialize(format=ox.QueryResultsFormat.JSON))


def direct(store: ox.Store, text: str, limit: int = 1 << 30) -> bytes:
    match = single_scan(text)
    assert match is not None, text
    lookup = pattern_lookup.parse(match, PREFIXES)
    assert lookup is not None, text
    return pattern_lookup.json_results(store, lookup, limit, time.monotonic() + 60)


def bindings(body: bytes) -> tuple[Any, Counter[str]]:
    answer = json.loads(body)
    rows = answer.get("results", {}).get("bindings", [])
    return answer["head"], Counter(json.dumps(row, sort_keys=True) for row in rows)


# A real random.Random that Hypothesis seeds (use_true_random): its own Random made every one of the
# some 400 calls per example a choice it records for shrinking, 8 of the test's 8.7 s; the same 100
# stores and 800 lookups are compared, and a failure is replayed from its seed (it is not shrunk).
@settings(max_examples=100, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.randoms(use_true_random=True))
def test_a_direct_lookup_answers_the_bytes_oxigraph_writes(rng: random.Random) -> None:
    store = ox.Store()
    random_store(rng, store)
    for _ in range(8):
        text = random_lookup(rng)
        mine, theirs = direct(store, text), engine(store, text)
        assert bindings(mine) == bindings(theirs), text
        assert mine == theirs, text


def test_an_on_disk_store_answers_alike(tmp_path: Path) -> None:
    rng = random.Random(18)
    store = ox.Store(str(tmp_path / "store"))
    random_store(rng, store)
    random_store(rng, store)
    for _ in range(300):
        text = random_lookup(rng)
        assert direct(store, text) == engine(store, text), text


def test_the_union_default_graph_repeats_a_triple_once_per_graph_it_is_in() -> None:
    store = ox.Store()
    triple = (ox.NamedNode(f"{EX}a"), ox.NamedNode(f"{EX}p"), ox.NamedNode(f"{EX}b"))
    for graph in (ox.DefaultGraph(), ox.NamedNode(f"{EX}g1"), ox.BlankNode("g2")):
        store.add(ox.Quad(*triple, graph))
    for text in (f"SELECT ?o WHERE {{ <{EX}a> ?p ?o }}", f"SELECT * WHERE {{ <{EX}a> <{EX}p> <{EX}b> }}"):
        for body in (direct(store, text), engine(store, text)):
            assert len(json.loads(body)["results"]["bindings"]) == 3


@pytest.mark.parametrize(
    "text",
    [
        pytest.param(f'SELECT ?s WHERE {{ ?s <{EX}p> "plain" }}', id="literal-object"),
        pytest.param(f"SELECT ?s WHERE {{ ?s <{EX}p> 1 }}", id="number-object"),
        pytest.param(f"SELECT ?o FROM <{EX}g1> WHERE {{ <{EX}a> ?p ?o }}", id="from"),
        pytest.param(f"BASE <{EX}> SELECT ?o WHERE {{ <a> ?p ?o }}", id="base"),
        pytest.param(f"PREFIX ex: <{EX}> PREFIX ex: <{HOME}> SELECT ?o WHERE {{ ex:a ?p ?o }}", id="prefix-twice"),
        pytest.param(f"SELECT ?p ?p WHERE {{ <{EX}a> ?p ?o }}", id="projected-twice"),
        pytest.param(f"SELECT ?ö WHERE {{ <{EX}a> ?p ?ö }}", id="non-ascii-variable"),
        pytest.param(f"PREFIX ex: <{EX}> SELECT ?o WHERE {{ ex:é ?p ?o }}", id="non-ascii-local-name"),
        pytest.param("SELECT ?o WHERE { nope:a ?p ?o }", id="undeclared-prefix"),
        pytest.param("SELECT ?o WHERE { <relative> ?p ?o }", id="relative-iri"),
        pytest.param("PREFIX ex: <relative/> SELECT ?o WHERE { ex:a ?p ?o }", id="relative-namespace"),
        pytest.param("ASK {}", id="empty-group"),
    ],
)
def test_other_single_scans_are_left_to_the_engine(text: str) -> None:
    match = single_scan(text)
    assert match is not None
    assert pattern_lookup.parse(match, PREFIXES) is None


# -- through the endpoint (SparqlService.query_here) --------------------------------------------------

LOOKUP = "SELECT ?p ?o WHERE { home:Cup ?p ?o }"


@pytest.fixture
def spy(monkeypatch: pytest.MonkeyPatch) -> list[str]:
    """The lookups answered directly, by their text's lookup."""
    taken: list[str] = []
    answer = pattern_lookup.json_results

    def counted(store: ox.Store, lookup: pattern_lookup.Lookup, limit: int, deadline: float) -> bytes:
        taken.append(repr(lookup))
        return answer(store, lookup, limit, deadline)

    monkeypatch.setattr(pattern_lookup, "json_results", counted)
    return taken


@pytest.mark.parametrize(
    ("text", "accept", "short"),
    [
        pytest.param(LOOKUP, None, None, id="default-json"),
        pytest.param(LOOKUP, "application/json", None, id="accept-json"),
        pytest.param(LOOKUP, None, "json", id="format-json"),
        pytest.param("ASK { ?s a home:Cup }", "application/sparql-results+json", None, id="ask"),
        pytest.param("select * { ?s a ?o } LIMIT 3", None, None, id="star-limit"),
    ],
)
def test_the_endpoint_answers_a_lookup_directly_as_the_engine_did(
    bundled_kb: KnowledgeBase, spy: list[str], text: str, accept: str | None, short: str | None
) -> None:
    service = SparqlService(bundled_kb, EndpointConfig())
    here = service.query_here(text, accept, short, None, 1 << 20)
    assert spy, "the lookup went to the engine"
    assert here is not None
    theirs = service._evaluate(text, accept, short, time.monotonic() + 30, {"union": True}, flat=True)
    assert (here.body, here.media_type) == (theirs.body, theirs.media_type)
    assert json.loads(here.body)


@pytest.mark.parametrize(
    ("text", "accept", "short"),
    [
        pytest.param(LOOKUP, "text/csv", None, id="csv"),
        pytest.param(LOOKUP, None, "xml", id="xml"),
        pytest.param(LOOKUP, "text/tab-separated-values", None, id="tsv"),
        pytest.param('SELECT ?s WHERE { ?s rdfs:label "cup"@en }', None, None, id="literal"),
        pytest.param("SELECT ?o FROM <urn:none> WHERE { home:Cup ?p ?o }", None, None, id="from"),
        pytest.param("ASK {}", None, None, id="empty-group"),
    ],
)
def test_the_shapes_not_taken_are_answered_by_the_engine_as_before(
    bundled_kb: KnowledgeBase, spy: list[str], text: str, accept: str | None, short: str | None
) -> None:
    service = SparqlService(bundled_kb, EndpointConfig())
    here = service.query_here(text, accept, short, None, 1 << 20)
    assert not spy
    assert here is not None
    theirs = service.query(text, accept, short)
    assert (here.body, here.media_type) == (theirs.body, theirs.media_type)


def test_a_refused_query_is_refused_by_the_engine(bundled_kb: KnowledgeBase, spy: list[str]) -> None:
    service = SparqlService(bundled_kb, EndpointConfig())
    with pytest.raises(QuerySyntaxError):
        service.query_here("SELECT ?o WHERE { nope:Cup ?p ?o }", None, None, None, 1 << 20)
    assert not spy


def test_a_lookup_past_the_inline_budget_goes_to_a_thread_and_past_the_limit_is_refused(
    bundled_kb: KnowledgeBase, spy: list[str]
) -> None:
    text = "SELECT ?s ?o WHERE { ?s a ?o }"
    whole = SparqlService(bundled_kb, EndpointConfig()).query(text).body
    service = SparqlService(bundled_kb, EndpointConfig(max_result_bytes=len(whole) - 1))
    assert service.query_here(text, None, None, None, 1024) is None  # the thread's path answers it
    with pytest.raises(ResultTooLargeError):
        service.query_here(text, None, None, None, len(whole) * 2)
    exact = SparqlService(bundled_kb, EndpointConfig(max_result_bytes=len(whole)))
    answer = exact.query_here(text, None, None, None, len(whole))
    assert answer is not None and answer.body == whole
    assert len(spy) == 3


def test_a_lookup_past_its_deadline_is_refused(bundled_kb: KnowledgeBase, spy: list[str]) -> None:
    service = SparqlService(bundled_kb, EndpointConfig(timeout=-1.0))
    with pytest.raises(QueryTimeoutError):
        service.query_here(LOOKUP, None, None, None, 1 << 20)
    assert spy


class EndlessStore:
    """Yields the same quad forever, counting them: a scan that would never end by itself."""

    def __init__(self) -> None:
        self.read = 0

    def quads_for_pattern(self, *pattern: Any) -> Iterator[ox.Quad]:
        quad = ox.Quad(ox.NamedNode(f"{EX}a"), ox.NamedNode(f"{EX}p"), ox.Literal("x" * 100))
        while True:
            self.read += 1
            yield quad


def endless_lookup() -> pattern_lookup.Lookup:
    match = single_scan(f"SELECT ?p ?o WHERE {{ <{EX}a> ?p ?o }}")
    assert match is not None
    lookup = pattern_lookup.parse(match, {})
    assert lookup is not None
    return lookup


def test_the_budget_stops_a_scan_as_it_goes() -> None:
    store = EndlessStore()
    with pytest.raises(pattern_lookup.Stopped, match="too-large"):
        pattern_lookup.json_results(store, endless_lookup(), 10_000, time.monotonic() + 60)  # type: ignore[arg-type]
    assert store.read < 100  # about 150 bytes a solution


def test_the_deadline_stops_a_scan_as_it_goes() -> None:
    store = EndlessStore()
    with pytest.raises(pattern_lookup.Stopped, match="timeout"):
        pattern_lookup.json_results(store, endless_lookup(), 1 << 40, time.monotonic() - 1)  # type: ignore[arg-type]
    assert store.read <= 64


def test_an_on_disk_store_is_left_to_the_engine(tmp_path: Path, spy: list[str]) -> None:
    """On disk the direct path costs what it saves (cbrs.pattern_lookup), so the engine answers."""
    kb = KnowledgeBase.open(str(tmp_path / "store"))
    try:
        service = SparqlService(kb, EndpointConfig(isolate=False))
        here = service.query_here(LOOKUP, None, None, None, 1 << 20)
        assert here is not None and json.loads(here.body)["results"]["bindings"]
        assert not spy
    finally:
        kb.close()
