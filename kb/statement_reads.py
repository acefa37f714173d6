"""Reading the statements graph:entailed is worked out from, in few requests on a remote store.

:mod:`kb.standard_terms` reads, for a whole refresh, every statement typing a node with an aligned class
or using an aligned property, and, after a description changed, every statement about its nodes. Asked
term by term that was some 140 queries a refresh: index lookups on the embedded store, but a round trip
each on a remote one, which made every load, update and registration over HTTP cost 0.5 to 2.5 s.

So the terms are asked together. The embedded store is read by pattern lookups (quicker than a query per
term). A remote one gets one query per pattern (all aligned classes; all aligned properties), listing its
terms, up to :data:`TERMS_PER_QUERY`, in ``VALUES`` blocks written by pyoxigraph's serialiser
(:func:`kb.remote_store.sparql_term`: IRIs validated, nothing pasted in as text). A server that may cut
an answer short (Virtuoso's ResultSetMaxRows, 10,000 rows by default; any server but Oxigraph's) is read
in ordered pages of :data:`ROWS_PER_PAGE` rows, the order fixed in a subquery as
:meth:`RemoteStore.quads` pages; one whose cap is lower still refuses the answer (a ``StoreError`` naming
ResultSetMaxRows), never cuts it silently.

Only statements in a named graph other than graph:entailed, with an IRI subject, are read: those a
refresh works from.
"""

from __future__ import annotations

import itertools
from collections.abc import Iterator, Mapping, Sequence

import pyoxigraph as ox

from cbrs.kb.namespaces import GraphName
from cbrs.kb.results import releases_results
from cbrs.kb.store import EmbeddedStore, Store

Pattern = Mapping[str, Sequence[ox.NamedNode]]
"""Statements ``?s ?p ?o`` whose positions ``s``, ``p`` or ``o`` named here hold one of the terms given."""

TERMS_PER_QUERY = 1_000
"""The most terms one query lists (about 60 KB of text): more are asked in further queries."""
ROWS_PER_PAGE = 5_000
"""The rows of one page from a server that may cut an answer: under Virtuoso's default cap of 10,000
(it says an answer of exactly the cap was cut)."""

_ENTAILED = GraphName.ENTAILED.node


def statements(store: Store, patterns: Sequence[Pattern]) -> set[ox.Triple]:
    """The statements matching any of ``patterns`` in a named graph other than graph:entailed, with an IRI
    subject (a pattern with an empty list of terms matches nothing)."""
    patterns = [p for p in patterns if all(p.values())]
    if isinstance(store, EmbeddedStore):
        return _looked_up(store, patterns)
    from cbrs.kb.remote_store import RemoteStore  # the HTTP client: only for a remote store (a CLI start)

    found: set[ox.Triple] = set()
    pages = not (isinstance(store, RemoteStore) and store.server == "oxigraph")
    for text in queries(patterns):
        found.update(_read_pages(store, text) if pages else _read(store, text))
    return found


def queries(patterns: Sequence[Pattern]) -> Iterator[str]:
    """SELECT DISTINCT ``?s ?p ?o`` queries asking for ``patterns``: one per pattern, with one ``VALUES``
    block per position it names, or several for a pattern of more than :data:`TERMS_PER_QUERY` terms.
    Patterns are not joined by ``UNION``: Virtuoso 7 answered ``?p`` as a string literal, in an ordered
    (so a paged) query, when every branch bound it to the same IRI (a class list split in two)."""
    from cbrs.kb.remote_store import sparql_term

    for pattern in patterns:
        for part in _split(pattern):
            blocks = " ".join(
                f"VALUES ?{position} {{ {' '.join(sparql_term(position, term) for term in terms)} }}"
                for position, terms in sorted(part.items())
            )
            yield (
                f"SELECT DISTINCT ?s ?p ?o WHERE {{\n  {blocks}\n  GRAPH ?g {{ ?s ?p ?o }}\n"
                f"  FILTER (?g != {_ENTAILED} && isIRI(?s))\n}}"
            )


def _split(pattern: Pattern) -> Iterator[dict[str, Sequence[ox.NamedNode]]]:
    """``pattern`` as patterns of at most :data:`TERMS_PER_QUERY` terms in all."""
    share = max(1, TERMS_PER_QUERY // len(pattern))
    chunks = [
        [(position, terms[start : start + share]) for start in range(0, len(terms), share)]
        for position, terms in pattern.items()
    ]
    for combination in itertools.product(*chunks):
        yield dict(combination)


def _looked_up(store: EmbeddedStore, patterns: Sequence[Pattern]) -> set[ox.Triple]:
    found: set[ox.Triple] = set()
    for pattern in patterns:
        anything: list[ox.NamedNode | None] = [None]
        lists = [list(pattern[position]) if position in pattern else anything for position in "spo"]
        for subject, predicate, obj in itertools.product(*lists):
            for quad in store.quads(subject, predicate, obj):
                graph = quad.graph_name
                if isinstance(quad.subject, ox.NamedNode) and isinstance(graph, ox.NamedNode) and graph != _ENTAILED:
                    found.add(quad.triple)
    return found


@releases_results
def _read(store: Store, text: str) -> list[ox.Triple]:
    result = store.query(text)
    assert isinstance(result, ox.QuerySolutions)
    return [ox.Triple(row["s"], row["p"], row["o"]) for row in result]


def _read_pages(store: Store, text: str) -> Iterator[ox.Triple]:
    """The answer to ``text`` a page at a time: the order is fixed in a subquery and the page taken outside
    it (Virtuoso refuses an ORDER BY with an OFFSET past its MaxSortedTopRows, but not this). The rows are
    distinct, so the pages do not overlap; a write by another client between two pages can shift them, as
    it can :meth:`RemoteStore.quads`'s."""
    offset = 0
    while True:
        page = _read(
            store, f"SELECT ?s ?p ?o WHERE {{ {{ {text} ORDER BY ?s ?p ?o }} }} LIMIT {ROWS_PER_PAGE} OFFSET {offset}"
        )
        yield from page
        offset += len(page)
        if len(page) < ROWS_PER_PAGE:
            return
