"""The component container's repository (paper section 2.2): register, update and deregister
advertisements, each as one transaction on the services graph."""

from __future__ import annotations

from collections.abc import Iterable

import pyoxigraph as ox

from cbrs.kb.conditions import CONDITION_PARTS, LEGACY_PARTS
from cbrs.kb.errors import AlreadyRegisteredError, InvalidDescriptionError, NotFoundError
from cbrs.kb.loader import parse_bytes
from cbrs.kb.namespaces import BASE, RDF, GraphName, shorten
from cbrs.kb.shapes import check_descriptions
from cbrs.kb.skolem import closure
from cbrs.kb.standard_terms import StandardTerms
from cbrs.kb.store import Store
from cbrs.kb.vocab import CBRS


class ComponentRegistry:
    """Advertisements in the services graph. A description is the advertisement's own triples
    plus those of the nodes hanging off it (its OWLS, SEA and QoS models, parameters, conditions)."""

    def __init__(self, store: Store, standard_terms: StandardTerms | None = None) -> None:
        self._store = store
        self._graph = GraphName.SERVICES.node
        self._standard_terms = standard_terms or StandardTerms(store)  # graph:entailed kept up to date

    def register(self, turtle: str | bytes, source: str = "<registration>") -> list[str]:
        """Add the advertisements described in ``turtle``; refuses any that already exist."""
        quads, iris = self._parse(turtle, source)
        for iri in iris:
            if self.is_registered(iri):
                raise AlreadyRegisteredError(iri)
        before = self._standard_terms.begin()
        self._store.add(quads)
        self._standard_terms.changed(before, [], quads)
        return iris

    def update(self, turtle: str | bytes, source: str = "<update>") -> list[str]:
        """Replace the descriptions of the advertisements in ``turtle``; each must exist."""
        quads, iris = self._parse(turtle, source)
        old: list[ox.Quad] = []
        for iri in iris:
            if not self.is_registered(iri):
                raise NotFoundError(iri, "registered advertisement")
            old.extend(self.description_quads(iri))
        new, kept = set(quads), set(old)
        before = self._standard_terms.begin()
        self._store.replace([q for q in old if q not in new], [q for q in quads if q not in kept])
        self._standard_terms.changed(before, old, quads)
        return iris

    def deregister(self, iri: str) -> int:
        """Remove one advertisement's description; returns the number of triples removed."""
        if not self.is_registered(iri):
            raise NotFoundError(iri, "registered advertisement")
        old = self.description_quads(iri)
        before = self._standard_terms.begin()
        self._store.replace(old, [])
        self._standard_terms.changed(before, old, [])
        return len(old)

    def is_registered(self, iri: str) -> bool:
        node = ox.NamedNode(iri)
        return any(True for _ in self._store.quads(node, ox.NamedNode(RDF + "type"), None, self._graph))

    def description_quads(self, iri: str) -> list[ox.Quad]:
        """The advertisement's triples and, recursively, those of its skolemised nodes."""
        return closure([ox.NamedNode(iri)], lambda node: self._store.quads(node, None, None, self._graph))  # type: ignore[arg-type]

    def _parse(self, turtle: str | bytes, source: str) -> tuple[list[ox.Quad], list[str]]:
        raw = turtle.encode("utf-8") if isinstance(turtle, str) else turtle
        parsed = parse_bytes(raw, source, ox.RdfFormat.TURTLE, graph=GraphName.SERVICES, base_iri=BASE)
        iris = _advertisements(self._store, parsed.quads)
        if not iris:
            check_descriptions(self._store, parsed.quads)  # a misspelt component kind gets its did-you-mean
            raise InvalidDescriptionError(
                source, ["it describes no advertisement (a subject typed with a cbrs component kind)"]
            )
        for iri in iris:
            problems = _problems(iri, parsed.quads)
            if problems:
                raise InvalidDescriptionError(iri, problems)
        check_descriptions(self._store, parsed.quads)  # SHACL shapes and declared terms (kb/shapes.py)
        return parsed.quads, iris


def _advertisements(store: Store, quads: Iterable[ox.Quad]) -> list[str]:
    kinds = _advertisement_classes(store)
    return sorted(
        {
            q.subject.value
            for q in quads
            if q.predicate.value == RDF + "type"
            and isinstance(q.subject, ox.NamedNode)
            and isinstance(q.object, ox.NamedNode)
            and q.object.value in kinds
        }
    )


def _advertisement_classes(store: Store) -> set[str]:
    result = store.query("SELECT ?c WHERE { ?c rdfs:subClassOf* cbrs:Advertisement }")
    assert isinstance(result, ox.QuerySolutions)
    return {row["c"].value for row in result} | {CBRS.Advertisement}


def _problems(iri: str, quads: list[ox.Quad]) -> list[str]:
    """What the six-tuple lacks: checked on the triples before anything is written."""
    by_subject: dict[str, dict[str, list[str]]] = {}
    for q in quads:
        if isinstance(q.subject, ox.NamedNode) and not isinstance(q.object, ox.Triple):
            fields = by_subject.setdefault(q.subject.value, {})
            fields.setdefault(q.predicate.value, []).append(q.object.value)
    own = by_subject.get(iri, {})
    problems = []
    for prop, label in ((CBRS.serviceName, "service name (SN)"), (CBRS.deviceName, "device name (DN)")):
        if len(own.get(prop, [])) != 1:
            problems.append(f"needs exactly one {label}, cbrs:{prop.rsplit('#', 1)[1]}")
    models = own.get(CBRS.hasOWLSModel, [])
    if len(models) != 1:
        return [*problems, "needs exactly one cbrs:hasOWLSModel"]
    model = by_subject.get(models[0], {})
    if not model.get(CBRS.hasOutput) and not model.get(CBRS.hasEffect):
        problems.append("its OWLS model has neither an output nor an effect")
    for prop in (CBRS.hasInput, CBRS.hasOutput):
        for parameter in model.get(prop, []):
            if not by_subject.get(parameter, {}).get(CBRS.parameterType):
                problems.append(f"parameter {parameter} has no cbrs:parameterType")
    for prop in (CBRS.hasPrecondition, CBRS.hasEffect):
        for condition in model.get(prop, []):
            fields = by_subject.get(condition, {})
            legacy = [shorten(p) for p in LEGACY_PARTS if fields.get(p)]
            missing = [shorten(p) for p in CONDITION_PARTS if not fields.get(p)]
            if legacy:
                problems.append(
                    f"condition {condition} uses {', '.join(legacy)}, the reified form of core 0.1.0 "
                    "(outside OWL 2 DL): write cbrs:conditionSubject, cbrs:conditionPredicate and cbrs:conditionObject"
                )
            elif missing:
                problems.append(f"condition {condition} lacks {', '.join(missing)}")
    return problems
