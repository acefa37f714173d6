"""What a SPARQL update a person sends (``cbrs update``) changed, graph by graph, and whether it may run whole.

pyoxigraph tells nothing of what an update did. An update of ground data (``INSERT DATA`` / ``DELETE DATA``,
read for certain by :mod:`kb.update_delta`) is counted quad by quad: what it added and removed in each
graph. Any other update (``DELETE { } INSERT { } WHERE { }``, ``DROP GRAPH``, ``LOAD``) is counted by each
graph's size before and after, which gives the net change only (a quad removed and another added in one
graph count as nothing, and such a report says no size changed rather than that nothing did).
graph:entailed, which follows every write, is counted by its refresh.

A request of several operations is one transaction on Oxigraph (embedded or served), but not on every
server: Virtuoso 7 keeps what the first operation wrote when the second fails (docs/remote-store.md). There
such a text is refused before it is sent, so that "all or nothing" holds wherever the update runs.
"""

from __future__ import annotations

import re
from collections import Counter
from dataclasses import dataclass

import pyoxigraph as ox

from cbrs.kb.errors import KnowledgeBaseError
from cbrs.kb.namespaces import GraphName, shorten
from cbrs.kb.sparql_lexemes import HIDING
from cbrs.kb.store import EmbeddedStore, Store

NO_SIZE_CHANGED = (
    "no graph changed in size (a statement replaced by another is not seen this way: only INSERT DATA and "
    "DELETE DATA are counted statement by statement)"
)
"""What an update counted by the graphs' sizes says when none changed: it may still have replaced values,
so "nothing changed" would claim what was not measured."""

DEFAULT_GRAPH = ""
"""How a report names the default graph (an update whose data names no ``GRAPH`` writes there)."""

# Strings, IRIs and comments hide what is inside them; then the brackets and separators that count.
_SEPARATOR = re.compile(HIDING + r"|[{}]|;", re.DOTALL)
_CONTENT = re.compile(HIDING + r"|\S", re.DOTALL)


class UpdateSplitError(KnowledgeBaseError):
    """An update of several operations sent to a server that does not run a request as one transaction."""

    def __init__(self, location: str, operations: int) -> None:
        self.location = location
        self.operations = operations
        super().__init__(
            f"store {location} does not run a request of several operations as one transaction (Virtuoso 7 "
            f"keeps what the first wrote when a later one fails), and this update has {operations}: send them "
            "one at a time (docs/remote-store.md)"
        )


@dataclass(frozen=True)
class GraphChange:
    """What an update changed in one graph: ``added`` and ``removed`` counted quad by quad, or (both None)
    only the ``net`` change in its size."""

    graph: str
    net: int
    added: int | None = None
    removed: int | None = None

    def text(self) -> str:
        where = shorten(self.graph) if self.graph else "the default graph"
        if self.added is not None and self.removed is not None:
            return f"{where}: {self.added} added, {self.removed} removed"
        sign = "+" if self.net > 0 else ""
        return f"{where}: {sign}{self.net} triples (net: the size before and after)"


@dataclass(frozen=True)
class UpdateReport:
    """What one update changed, graph by graph (graph:entailed last), graphs it left as they were left out."""

    changes: tuple[GraphChange, ...]
    exact: bool
    """Whether the update's own graphs were counted quad by quad (a data update), not by their sizes."""
    counted: bool = True
    """False when a data update's effect was not borne out by the store afterwards (another writer?)."""

    @property
    def changed(self) -> bool:
        return any(change.net or change.added or change.removed for change in self.changes)

    def lines(self) -> list[str]:
        """The report as ``cbrs update`` prints it, a line a graph."""
        if not self.counted:
            return ["the update ran; what it changed could not be counted (the store changed meanwhile)"]
        if not self.changed:
            return ["nothing changed" if self.exact else NO_SIZE_CHANGED]
        return [change.text() for change in self.changes]


def operations(text: str) -> int:
    """How many operations the update ``text`` has: the parts its ``;`` separators (outside brackets,
    strings, IRIs and comments) cut it into that hold more than blanks and comments."""
    cuts, depth = [0], 0
    for match in _SEPARATOR.finditer(text):
        token = match.group()
        if token == "{":
            depth += 1
        elif token == "}":
            depth = max(depth - 1, 0)
        elif token == ";" and depth == 0:
            cuts.append(match.end())
    parts = [text[start:end] for start, end in zip(cuts, [*cuts[1:], len(text) + 1], strict=True)]
    return sum(1 for part in parts if any(not m.group().startswith("#") for m in _CONTENT.finditer(part.rstrip(";"))))


def refuse_split(store: Store, text: str) -> None:
    """Raise :class:`UpdateSplitError` for an update of several operations to a store that does not keep a
    request whole (``keeps_requests_whole``, :mod:`kb.remote_store`)."""
    if getattr(store, "keeps_requests_whole", True):
        return
    count = operations(text)
    if count > 1:
        raise UpdateSplitError(store.location, count)


def graph_sizes(store: Store) -> Counter[str]:
    """Each named graph's size, and on an embedded store the default graph's (a remote store's union
    default graph cannot be told apart from its named graphs but by a costly query)."""
    sizes: Counter[str] = Counter()
    result = store.query("SELECT ?g (COUNT(*) AS ?n) WHERE { GRAPH ?g { ?s ?p ?o } } GROUP BY ?g")
    assert isinstance(result, ox.QuerySolutions)
    for row in result:
        sizes[row["g"].value] = int(row["n"].value)
    if isinstance(store, EmbeddedStore):
        sizes[DEFAULT_GRAPH] = sum(1 for _ in store.quads(graph=ox.DefaultGraph()))
    return sizes


def net_changes(before: Counter[str], after: Counter[str]) -> list[GraphChange]:
    """The graphs whose size changed, by IRI (graph:entailed left out: its refresh counts it)."""
    graphs = sorted(set(before) | set(after))
    return [
        GraphChange(graph, after[graph] - before[graph])
        for graph in graphs
        if after[graph] != before[graph] and graph != GraphName.ENTAILED.iri
    ]


def exact_changes(added: frozenset[ox.Quad], removed: frozenset[ox.Quad]) -> list[GraphChange]:
    """The graphs a data update changed, from the quads it added and removed."""

    def graph_of(quad: ox.Quad) -> str:
        return quad.graph_name.value if isinstance(quad.graph_name, ox.NamedNode) else DEFAULT_GRAPH

    plus, minus = Counter(map(graph_of, added)), Counter(map(graph_of, removed))
    return [
        GraphChange(graph, plus[graph] - minus[graph], plus[graph], minus[graph])
        for graph in sorted(set(plus) | set(minus))
    ]
