"""A DESCRIBE's answer completed through the blank nodes the loader skolemised.

Oxigraph answers ``DESCRIBE <r>`` with the triples whose subject is ``<r>`` and, recursively, those of the
blank nodes they reach: a concise bounded description. cbrs skolemises every blank node on load
(:mod:`kb.loader`, RDF 1.1 section 3.5: ``genid:…`` IRIs), so what a class says through one, an OWL
restriction (``rdfs:subClassOf [ a owl:Restriction ; owl:onProperty … ]``), a list, a description's
models and parameters, is stored under an IRI the engine does not follow: a describe of the class showed
``rdfs:subClassOf genid:…`` and nothing about it. :func:`complete` adds what the engine would have
followed had they stayed blank: the triples about every skolemised node the answer reaches, recursively
through skolemised nodes only (a named resource it reaches stays a bare IRI, as in any DESCRIBE).

Bounded, as a concise bounded description must be on a store of any shape: at most ``depth`` links from
the answer's own triples (:data:`DEPTH`; an OWL list of n members is n links deep) and ``most`` triples
added (:data:`MOST`); a node past either bound is left as it was, a bare IRI (docs/serving.md, "DESCRIBE").
"""

from __future__ import annotations

from collections.abc import Callable, Collection, Iterable
from typing import TYPE_CHECKING

import pyoxigraph as ox

from cbrs.kb.skolem import is_skolem

if TYPE_CHECKING:
    from cbrs.kb.store import Store

__all__ = ["DEPTH", "MOST", "about_in", "complete"]

DEPTH = 64
"""The most links followed from the engine's answer: a restriction on a union of a 60-member list fits."""
MOST = 10_000
"""The most triples added to one answer (a describe of many resources with large restrictions stops there)."""


def complete(
    triples: Iterable[ox.Triple],
    about: Callable[[ox.NamedNode], Iterable[ox.Triple]],
    depth: int = DEPTH,
    most: int = MOST,
) -> list[ox.Triple]:
    """``triples`` (a DESCRIBE's answer, in the engine's order), then the triples ``about`` gives for each
    skolemised node they reach, breadth first, each node once and each triple once, within ``depth`` links
    and ``most`` added triples."""
    found = list(triples)
    seen = set(found)
    done: set[object] = {triple.subject for triple in found}  # the engine described these already
    frontier = _unfollowed(found, done)
    added = 0
    for _ in range(depth):
        if not frontier:
            break
        reached: list[ox.Triple] = []
        for node in frontier:
            done.add(node)
            for triple in about(node):
                if triple in seen:
                    continue
                if added >= most:
                    return found
                seen.add(triple)
                found.append(triple)
                reached.append(triple)
                added += 1
        frontier = _unfollowed(reached, done)
    return found


def _unfollowed(triples: Iterable[ox.Triple], done: set[object]) -> list[ox.NamedNode]:
    """The skolemised objects of ``triples`` not described yet, each once, in order."""
    nodes: dict[ox.NamedNode, None] = {}
    for triple in triples:
        node = triple.object
        if isinstance(node, ox.NamedNode) and is_skolem(node) and node not in done:
            nodes[node] = None
    return list(nodes)


def about_in(store: Store, graphs: Collection[ox.NamedNode] | None = None) -> Callable[[ox.NamedNode], list[ox.Triple]]:
    """What ``store`` states about a node, for :func:`complete`: in every graph (cbrs's default graph is
    their union), or in ``graphs`` only (a query's dataset); a triple stated in several graphs once."""
    allowed = None if graphs is None else frozenset(graphs)

    def about(node: ox.NamedNode) -> list[ox.Triple]:
        triples = (quad.triple for quad in store.quads(subject=node) if allowed is None or quad.graph_name in allowed)
        return list(dict.fromkeys(triples))

    return about
