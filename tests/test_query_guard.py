"""kb.query_guard: texts that would crash Oxigraph's recursive engine are refused, and the process lives.

Each hostile text here killed the process before the guard (a segfault inside Oxigraph's parser or
planner); run in this process, a regression ends the test session with the same crash.
"""

from __future__ import annotations

import pytest

from cbrs.kb.errors import QuerySyntaxError, QueryTooComplexError
from cbrs.kb.query_guard import QueryGuard
from cbrs.kb.store import EmbeddedStore

# The issue's text: the old bracket guard read '<+(+(...>' as an IRI.
ISSUE_QUERY = "SELECT * WHERE { FILTER(1<" + "+(" * 5000 + "1+" + ")" * 5000 + ">0) }"

# Deep trees without deep brackets: chains the parser folds into one nested node per link.
HOSTILE = [
    pytest.param(ISSUE_QUERY, id="iri-lookalike-nesting"),
    pytest.param("SELECT * WHERE { ?s ?p ?o " + "OPTIONAL { ?s ?p ?o } " * 4000 + "}", id="optional-chain"),
    pytest.param("SELECT * WHERE { " + "{} UNION " * 20000 + "{} }", id="union-chain"),
    pytest.param("SELECT * WHERE { FILTER(" + "1+" * 60000 + "1) }", id="plus-chain"),
    pytest.param("SELECT * WHERE { FILTER(" + "1||" * 40000 + "1) }", id="or-chain"),
    pytest.param("SELECT * WHERE { FILTER(" + "!" * 60000 + "true) }", id="not-chain"),
    pytest.param("SELECT * WHERE { " + " ".join(f"BIND({i} AS ?v{i})" for i in range(4000)) + " }", id="bind-chain"),
    pytest.param("SELECT * WHERE { ?s ?p ?o " + "MINUS { ?s ?p ?o } " * 4000 + "}", id="minus-chain"),
]


@pytest.fixture
def store() -> EmbeddedStore:
    store = EmbeddedStore.open(":memory:")
    store.update("INSERT DATA { <urn:a> <urn:p> <urn:b> }")
    return store


@pytest.mark.parametrize("text", HOSTILE)
def test_a_text_that_crashes_the_engine_is_refused_and_the_store_lives(store: EmbeddedStore, text: str) -> None:
    with pytest.raises(QueryTooComplexError) as refused:
        store.query(text)
    assert "crashed the store's SPARQL engine" in str(refused.value)
    assert refused.value.query == text
    assert refused.value.http_status == 400
    assert bool(store.query("ASK { <urn:a> <urn:p> <urn:b> }"))


def test_an_update_that_crashes_the_engine_is_refused_and_writes_nothing(store: EmbeddedStore) -> None:
    before = store.dump()
    text = "INSERT { <urn:x> <urn:p> <urn:y> } WHERE { ?s ?p ?o " + "OPTIONAL { ?s ?p ?o } " * 4000 + "}"
    with pytest.raises(QueryTooComplexError, match="update crashed"):
        store.update(text)
    assert store.dump() == before


def test_a_long_well_formed_query_runs_after_its_check() -> None:
    guard = QueryGuard()
    try:
        store = EmbeddedStore.open(":memory:")
        store.guard = guard
        store.update("INSERT DATA { <urn:a> <urn:p> 1 }")
        filters = "FILTER(?o != 2) " * 200
        rows = list(store.query("SELECT ?s WHERE { ?s ?p ?o " + filters + "}"))
        assert [row["s"].value for row in rows] == ["urn:a"]
        assert guard.crashes == 0
    finally:
        guard.close()


def test_a_long_query_with_a_syntax_error_gets_the_parsers_message() -> None:
    guard = QueryGuard()
    try:
        text = "SELECT * WHERE { ?s ?p ?o " + "FILTER(?o != 1) " * 200  # the closing brace is missing
        with pytest.raises(QuerySyntaxError) as refused:
            guard.admit("query", text)
        assert not isinstance(refused.value, QueryTooComplexError)
        assert "error at 1:" in str(refused.value)
    finally:
        guard.close()


def test_short_texts_are_not_sent_to_a_checker() -> None:
    guard = QueryGuard(direct_chars=100)
    try:
        guard.admit("query", "SELECT * WHERE { this is not SPARQL }")  # short: straight to the store
        assert guard._idle == []
    finally:
        guard.close()


def test_a_checked_text_is_remembered_and_a_crashed_checker_is_replaced() -> None:
    guard = QueryGuard(direct_chars=10, remember=2)
    try:
        good = "SELECT * WHERE { ?s ?p ?o }"
        guard.admit("query", good)
        first = guard._idle[0]
        guard.admit("query", good)  # remembered: no new check
        assert guard._idle == [first]
        with pytest.raises(QueryTooComplexError):
            guard.admit("query", ISSUE_QUERY)
        assert guard.crashes == 1
        assert not first.alive()
        guard.admit("query", "ASK { ?s ?p ?o }")  # a fresh checker takes over
        assert guard._idle and guard._idle[0].alive()
    finally:
        guard.close()


# 300^4 rows of VALUES, none kept: slow even on the checker's empty store.
VALUES = " ".join(f"VALUES ?v{i} {{ {' '.join(str(n) for n in range(300))} }}" for i in range(4))
NOTHING = "FILTER(?v0 + ?v1 + ?v2 + ?v3 < 0)"


def test_a_query_that_parses_but_evaluates_slowly_is_admitted_at_the_deadline() -> None:
    guard = QueryGuard(direct_chars=10, timeout=1.0)
    try:
        guard.admit("query", f"SELECT ?v0 WHERE {{ {VALUES} {NOTHING} }}")  # parsed at once, filtered for ever
        assert guard.crashes == 0
    finally:
        guard.close()


def test_a_text_that_cannot_be_checked_in_time_is_refused() -> None:
    guard = QueryGuard(direct_chars=10, timeout=1.0)
    try:
        with pytest.raises(QueryTooComplexError, match="query could not be checked within 1 s"):
            guard.admit("query", f"SELECT (COUNT(*) AS ?n) WHERE {{ {VALUES} }}")  # aggregates evaluate as they parse
        slow = f"INSERT {{ <urn:a> <urn:p> ?v0 }} WHERE {{ {VALUES} {NOTHING} }}"
        with pytest.raises(QueryTooComplexError, match="could not be checked within 1 s"):
            guard.admit("update", slow)
    finally:
        guard.close()
