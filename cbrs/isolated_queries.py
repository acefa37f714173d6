"""A SPARQL query evaluated in a child process and its result handed back as terms, so that a crash of the
engine costs the child and not the caller.

Oxigraph aborts the process on a panic, and one is reachable from a short query (pyoxigraph 0.5.13):
``ORDER BY`` over dateTimes some with a time zone and some without, which a store's data may hold and a
text of 278 characters can make (:mod:`kb.engine_faults`). The query guard lets a short text run in the
caller's process, since no short text can overflow the stack. So ``cbrs query`` evaluates a text that
sorts (:func:`kb.engine_faults.sorts`) in a query worker (:class:`cbrs.query_workers.QueryProcesses`: one
process started for the query and stopped after it, on a snapshot of the store) and prints its answer as
it prints one evaluated in its own process; a worker that dies of a panic is an
:class:`~kb.errors.EngineFaultError` naming it. A text that does not sort runs in the caller's process,
as before: no other panic is known to be reachable, and a worker costs 0.15 s on the bundled store on
disk and 0.5 s in memory, where the snapshot is a copy (docs/security.md, "When the engine itself
crashes").

A library user evaluates a text in isolation the same way: ``with IsolatedQueries(kb.store) as isolated:
isolated.query(text)``.
"""

from __future__ import annotations

import math
import sys
from types import TracebackType

import pyoxigraph as ox

from cbrs.kb.errors import EngineFaultError, QueryTooComplexError
from cbrs.kb.store import EmbeddedStore
from cbrs.query_workers import QueryProcesses, Request

__all__ = ["IsolatedQueries", "IsolatedResult"]

IsolatedResult = ox.QuerySolutions | ox.QueryBoolean | list[ox.Triple]
"""What :meth:`IsolatedQueries.query` gives: a SELECT's solutions, an ASK's boolean, or a CONSTRUCT's or
DESCRIBE's triples in the order the engine gave them (a list: a ``QueryTriples`` cannot be made anew)."""

_RESULTS = "application/sparql-results+json"  # lossless for every term, blank nodes' labels included
_GRAPH = "application/n-triples"


class IsolatedQueries:
    """Queries on ``store`` evaluated in worker processes on snapshots of it.

    ``keep`` workers stay started between queries (0: each query starts its own and stops it, for a
    command that runs one). ``timeout`` seconds and ``memory`` resident bytes (0: no limit) stop a query
    with :class:`cbrs.query_workers.QueryStopped`; a result is never cut short by size."""

    def __init__(self, store: EmbeddedStore, keep: int = 0, timeout: float = math.inf, memory: int = 0) -> None:
        self.store = store
        self.timeout = timeout
        self.processes = QueryProcesses(store, keep, memory)

    def query(self, text: str) -> IsolatedResult:
        """``text``'s result, as :meth:`EmbeddedStore.query` would give it, after the same checks."""
        self.store.check_query(text)
        request = Request(
            text=text,
            results_type=_RESULTS,
            graph_type=_GRAPH,
            results_format=_RESULTS,
            graph_format=_GRAPH,
            limit=sys.maxsize,
            timeout=self.timeout,
        )
        try:
            body, media_type = self.processes.run(request)
        except EngineFaultError as error:  # the workers do not know the text
            raise EngineFaultError(text, error.reason) from None
        except QueryTooComplexError as error:
            raise QueryTooComplexError(text, error.message) from None
        if media_type == _GRAPH:
            return [quad.triple for quad in ox.parse(body, format=ox.RdfFormat.N_TRIPLES)]
        return ox.parse_query_results(body, format=ox.QueryResultsFormat.JSON)

    def close(self) -> None:
        """Stop the workers and delete the snapshots."""
        self.processes.close()

    def __enter__(self) -> IsolatedQueries:
        return self

    def __exit__(
        self, kind: type[BaseException] | None, error: BaseException | None, traceback: TracebackType | None
    ) -> None:
        self.close()
