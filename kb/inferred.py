"""graph:inferred: what an OWL 2 DL reasoner concluded of the store and the store does not already say.

``cbrs check --write-inferred`` (:func:`cbrs.check.write_inferred`) hands HermiT's conclusions here: the
inferred subclasses, subproperties and equivalences of named classes and properties, and the types of
named individuals. :func:`replace_inferred` keeps those no other graph states (graph:entailed included,
so what the alignments already entail is not said twice) and makes graph:inferred hold exactly them, in
one update: all or nothing, nothing written when they are what it holds, and a conclusion of an earlier
run the ontology no longer gives goes.

It is a graph of its own, not part of graph:entailed, because the two are kept differently: graph:entailed
is worked out again after every write (:mod:`kb.standard_terms`) and a refresh would drop what HermiT
said; graph:inferred is a reasoner's snapshot, taken when asked (a Java run of seconds, too slow for every
write), and stays as it was until the next write-back. The statements it holds are in the store's union
default graph, so every SPARQL query sees them (docs/ontologies.md, "HermiT's conclusions in the store").
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import pyoxigraph as ox

from cbrs.kb.knowledge_base import KnowledgeBase
from cbrs.kb.namespaces import GRAPH, OWL, RDF, RDFS

__all__ = ["INFERRED", "PREDICATES", "InferredGraph", "replace_inferred"]

INFERRED = ox.NamedNode(GRAPH + "inferred")
"""The graph HermiT's conclusions are written to (not one of :class:`GraphName`: no write of cbrs's
touches it, and only a write-back replaces it)."""

PREDICATES = tuple(
    ox.NamedNode(iri)
    for iri in (
        RDF + "type",
        RDFS + "subClassOf",
        RDFS + "subPropertyOf",
        OWL + "equivalentClass",
        OWL + "equivalentProperty",
    )
)
"""The predicates of the conclusions graph:inferred holds."""
_SYMMETRIC = frozenset(PREDICATES[3:])


@dataclass(frozen=True)
class InferredGraph:
    """What a write-back did to graph:inferred."""

    graph: str
    holds: int
    """Conclusions the graph holds now."""
    added: int
    removed: int
    already_said: int
    """Conclusions left out because another graph states them or graph:entailed holds them."""

    @property
    def changed(self) -> bool:
        return bool(self.added or self.removed)

    def to_dict(self) -> dict[str, object]:
        return {
            "graph": self.graph,
            "holds": self.holds,
            "added": self.added,
            "removed": self.removed,
            "already_said": self.already_said,
        }


def replace_inferred(kb: KnowledgeBase, conclusions: Iterable[ox.Triple]) -> InferredGraph:
    """Make graph:inferred hold those of ``conclusions`` (triples with one of :data:`PREDICATES`) that no
    other graph holds, in one update; no write when it holds them already. After a change the knowledge
    base brings what it derives up to date (:meth:`KnowledgeBase.replace_graph`: graph:entailed, whose
    alignments read the inferred types too, and the descriptions it has read)."""
    conclusions = list(dict.fromkeys(conclusions))
    if any(triple.predicate not in PREDICATES for triple in conclusions):
        raise ValueError("replace_inferred takes types, subclasses, subproperties and equivalences only")
    said = _said_elsewhere(kb)
    unsaid = [t for t in conclusions if not _is_said(t, said)]
    new = _one_way(unsaid)
    quads = [ox.Quad(t.subject, t.predicate, t.object, INFERRED) for t in new]
    held = set(kb.store.quads(graph=INFERRED))
    wanted = set(quads)
    report = InferredGraph(
        INFERRED.value, len(wanted), len(wanted - held), len(held - wanted), len(conclusions) - len(unsaid)
    )
    if report.changed:
        kb.replace_graph(INFERRED, quads)
    return report


def _said_elsewhere(kb: KnowledgeBase) -> set[tuple[ox.NamedNode | ox.BlankNode | ox.Triple, ox.NamedNode, object]]:
    """The statements with one of :data:`PREDICATES` in every graph but graph:inferred (graph:entailed too)."""
    return {
        (quad.subject, quad.predicate, quad.object)
        for predicate in PREDICATES
        for quad in kb.store.quads(None, predicate, None)
        if quad.graph_name != INFERRED
    }


def _is_said(
    triple: ox.Triple, said: set[tuple[ox.NamedNode | ox.BlankNode | ox.Triple, ox.NamedNode, object]]
) -> bool:
    if (triple.subject, triple.predicate, triple.object) in said:
        return True
    if triple.predicate in _SYMMETRIC and isinstance(triple.object, ox.NamedNode):
        return (triple.object, triple.predicate, triple.subject) in said
    return False


def _one_way(triples: list[ox.Triple]) -> list[ox.Triple]:
    """Each equivalence once, from the lesser IRI to the greater (HermiT names both ways round), in order."""
    kept = []
    for triple in triples:
        if triple.predicate in _SYMMETRIC and triple.subject.value > triple.object.value:  # type: ignore[union-attr]
            triple = ox.Triple(triple.object, triple.predicate, triple.subject)  # type: ignore[arg-type]
        kept.append(triple)
    return list(dict.fromkeys(kept))
