"""A graph IRI an update writes that is a slip of one of the store's own (``graph#map`` for ``graph/map``).

Any IRI may name a graph of the store, and a lab may keep graphs of its own. But an IRI in cbrs's own
namespace of graphs, or one spelt all but as one of them, that is none of them is a slip: an update that
wrote the twenty-second round's pen drawer into ``<https://w3id.org/cbrs/graph#map>`` (a hash, where the
store's graphs end in ``/map``) was accepted and reported ``https://w3id.org/cbrs/graph#map: 9 added``, and
no task saw the drawer. Such an update is refused before it runs, naming the graph meant.
"""

from __future__ import annotations

import difflib
import re
from collections.abc import Iterable

import pyoxigraph as ox

from cbrs.kb.errors import KnowledgeBaseError
from cbrs.kb.namespaces import GRAPH, GraphName

_CLOSE = 0.9
"""How alike (difflib's ratio) an IRI must be to a graph's IRI to be taken for a slip of it."""


class GraphSlipError(KnowledgeBaseError):
    """An update writes a graph whose IRI is a slip of one of the store's graphs; nothing was changed."""

    http_status = 422

    def __init__(self, graph: str, meant: GraphName | None) -> None:
        self.graph = graph
        self.meant = meant
        known = ", ".join(f"graph:{name.value}" for name in GraphName)
        hint = (
            f"did you mean graph:{meant.value} (<{meant.iri}>)? " if meant is not None else f"the store's are {known}; "
        )
        super().__init__(
            f"this update writes graph <{graph}>, which is none of the store's graphs but is spelt as one: {hint}"
            "graph: is bound to <https://w3id.org/cbrs/graph/> for every update, so leave out a PREFIX graph: of "
            "your own; nothing was changed"
        )


def slip_of(iri: str) -> GraphName | bool | None:
    """The store's graph ``iri`` is a slip of (False: it is no slip; None: a slip of none in particular)."""
    known = {name.iri: name for name in GraphName}
    if iri in known or iri.startswith(GRAPH + "staging/"):  # kb/staged_writes.py's own
        return False
    plain = re.sub(r"[#/]+", "/", iri.lower().replace("http://", "https://"))
    for name in GraphName:
        if plain.rstrip("/") == name.iri:
            return name
    close = difflib.get_close_matches(iri, list(known), n=1, cutoff=_CLOSE)
    if close:
        return known[close[0]]
    if plain.startswith("https://w3id.org/cbrs/graph"):
        return None
    return False


def refuse_slips(graphs: Iterable[ox.NamedNode | ox.DefaultGraph | ox.BlankNode]) -> None:
    """Raise :class:`GraphSlipError` for the first graph of ``graphs`` that is a slip of the store's."""
    for graph in graphs:
        if not isinstance(graph, ox.NamedNode):
            continue
        meant = slip_of(graph.value)
        if meant is not False:
            raise GraphSlipError(graph.value, meant if isinstance(meant, GraphName) else None)
