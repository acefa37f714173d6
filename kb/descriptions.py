"""Read typed service descriptions out of the store through the named queries."""

from __future__ import annotations

import logging
from typing import Any, Literal, cast

import pyoxigraph as ox

from cbrs.kb.errors import BlankNodeError, InvalidDescriptionError, NotFoundError
from cbrs.kb.model import (
    Advertisement,
    EffectiveArea,
    Parameter,
    PartNode,
    Port,
    QoSValue,
    Requirement,
    ServiceDescription,
    Statement,
)
from cbrs.kb.queries import QueryLibrary
from cbrs.kb.store import Store, Term
from cbrs.kb.vocab import CBRS

log = logging.getLogger("kb.descriptions")

MAX_PART_DEPTH = 8  # deeper part structures are modelling errors, not taxonomies


class DescriptionReader:
    """Builds Advertisement and Requirement objects; part trees are cached per concept."""

    def __init__(self, store: Store, queries: QueryLibrary) -> None:
        self._store = store
        self._queries = queries
        self._trees: dict[str, PartNode] = {}

    def clear_cache(self) -> None:
        """Forget cached part trees (call after the ontology graph changes)."""
        self._trees.clear()

    def advertisement_iris(self) -> list[str]:
        """The advertisements' IRIs; one that is a blank node (an update's doing) is passed over."""
        return _named(row["service"] for row in self._queries.select(self._store, "advertisements"))

    def requirement_iris(self) -> list[str]:
        return _named(row["requirement"] for row in self._queries.select(self._store, "requirements"))

    def read(self, iri: str) -> ServiceDescription:
        """The advertisement or requirement ``iri``; NotFoundError when it is neither, BlankNodeError
        (400) when a node of it is blank."""
        try:
            return self._read(iri)
        except BlankNodeError as error:
            raise BlankNodeError(iri, error.node) from None

    def _read(self, iri: str) -> ServiceDescription:
        head = self._queries.select(self._store, "description", {"description": iri})
        if not head:
            raise NotFoundError(iri, "service description")
        types = tuple(sorted({_iri(row["type"]) for row in head}))
        first = {name: _value(term) for row in head for name, term in row.items() if name != "type"}
        parameters = self._parameters(iri)
        conditions = self._conditions(iri)
        common: dict[str, Any] = dict(
            iri=iri,
            types=types,
            label=first.get("label"),
            comment=first.get("comment"),
            device_name=first.get("deviceName"),
            service_name=first.get("serviceName"),
            category=first.get("category"),
            inputs=parameters["input"],
            outputs=parameters["output"],
            preconditions=conditions["precondition"],
            effects=conditions["effect"],
            deletes=conditions["delete"],
            area=self._area(iri),
            qos=self._qos(iri),
        )
        if CBRS.Requirement in types:
            return Requirement(**common, requested_by=first.get("requestedBy"), for_task=first.get("forTask"))
        kinds = [t for t in types if t not in (CBRS.Advertisement, CBRS.ServiceDescription)]
        return Advertisement(
            **common,
            kind=kinds[0] if kinds else CBRS.Advertisement,
            device=first.get("device"),
            realizes_action=first.get("realizesAction"),
            ports=self._ports(iri),
        )

    def read_action(self, iri: str, label: str | None = None) -> Requirement:
        """The IOPE an action class carries (OWL 2 punning), as a requirement to compose for.

        NotFoundError when ``iri`` carries no OWL-S model.
        """
        rows = self._queries.select(self._store, "description_model", {"description": iri})
        if not rows or rows[0]["models"].value == "0":
            raise NotFoundError(iri, "action with inputs, outputs, preconditions or effects")
        parameters = self._parameters(iri)
        conditions = self._conditions(iri)
        return Requirement(
            iri=iri,
            types=(CBRS.Requirement,),
            label=label,
            inputs=parameters["input"],
            outputs=parameters["output"],
            preconditions=conditions["precondition"],
            effects=conditions["effect"],
            deletes=conditions["delete"],
            for_task=iri,
        )

    def advertisements(self) -> list[Advertisement]:
        """Every readable advertisement: one with a blank node inside is passed over (and logged), so
        one bad update does not stop matching and planning for everyone."""
        return [cast(Advertisement, found) for found in self._readable(self.advertisement_iris())]

    def requirements(self) -> list[Requirement]:
        return [cast(Requirement, found) for found in self._readable(self.requirement_iris())]

    def _readable(self, iris: list[str]) -> list[ServiceDescription]:
        found = []
        for iri in iris:
            try:
                found.append(self.read(iri))
            except BlankNodeError as error:
                log.warning("passed over: %s", error)
        return found

    def part_tree(self, concept: str) -> PartNode:
        """The concept with its hasPart children, recursively; a cycle is a modelling error."""
        if concept not in self._trees:
            self._trees[concept] = self._build_tree(concept, None, (), concept)
        return self._trees[concept]

    # -- pieces ------------------------------------------------------------------------------

    def _build_tree(self, concept: str, via: str | None, path: tuple[str, ...], root: str) -> PartNode:
        if concept in path:
            cycle = " -> ".join((*path[path.index(concept) :], concept))
            raise InvalidDescriptionError(root, [f"hasPart cycle {cycle}"])
        if len(path) >= MAX_PART_DEPTH:
            raise InvalidDescriptionError(root, [f"hasPart structure deeper than {MAX_PART_DEPTH} below {root}"])
        rows = self._queries.select(self._store, "concept_parts", {"concept": concept})
        by_property: dict[str, list[tuple[str, str]]] = {}
        for row in rows:
            by_property.setdefault(_iri(row["property"]), []).append((_iri(row["part"]), _iri(row["owner"])))
        children = []
        for prop, parts in sorted(by_property.items()):
            # A subclass may narrow an inherited part; its own restriction wins.
            own = [part for part, owner in parts if owner == concept]
            for part in sorted(set(own or [part for part, _ in parts])):
                children.append(self._build_tree(part, prop, (*path, concept), root))
        return PartNode(concept, via, tuple(children))

    def _parameters(self, iri: str) -> dict[str, tuple[Parameter, ...]]:
        """Inputs and outputs, from one query."""
        rows = self._queries.select(self._store, "description_parameters", {"description": iri})
        found: dict[str, list[Parameter]] = {"input": [], "output": []}
        for row in rows:
            direction = cast(Literal["input", "output"], _value(row["direction"]))
            if "type" not in row:
                raise InvalidDescriptionError(iri, [f"{direction} {_iri(row['parameter'])} has no cbrs:parameterType"])
            concept = _iri(row["type"])
            found[direction].append(
                Parameter(
                    iri=_iri(row["parameter"]),
                    direction=direction,
                    type=concept,
                    name=_value(row["name"]) if "name" in row else None,
                    tree=self.part_tree(concept),
                )
            )
        return {direction: tuple(items) for direction, items in found.items()}

    def _conditions(self, iri: str) -> dict[str, tuple[Statement, ...]]:
        """Preconditions and effects, from one query."""
        rows = self._queries.select(self._store, "description_conditions", {"description": iri})
        found: dict[str, list[Statement]] = {"precondition": [], "effect": [], "delete": []}
        for row in rows:
            role = _value(row["role"])
            missing = [part for part in ("subject", "predicate", "object") if part not in row]
            if missing:
                problem = f"{role} {_iri(row['condition'])} lacks rdf:{', rdf:'.join(missing)}"
                raise InvalidDescriptionError(iri, [problem])
            found[role].append(Statement(_iri(row["subject"]), _iri(row["predicate"]), _iri(row["object"])))
        return {role: tuple(items) for role, items in found.items()}

    def _area(self, iri: str) -> EffectiveArea | None:
        rows = self._queries.select(self._store, "description_sea", {"description": iri})
        if not rows:
            return None
        areas = tuple(sorted({_iri(row["area"]) for row in rows if "area" in row}))
        box = [rows[0].get(name) for name in ("minX", "maxX", "minY", "maxY")]
        bounds = None
        if all(term is not None for term in box):
            x0, x1, y0, y1 = (float(_value(cast(Term, term))) for term in box)
            bounds = (x0, x1, y0, y1)
        return EffectiveArea(areas, bounds)

    def _qos(self, iri: str) -> tuple[QoSValue, ...]:
        rows = self._queries.select(self._store, "description_qos", {"description": iri})
        values = []
        for row in rows:
            better = _iri(row["betterWhen"]) if "betterWhen" in row else None
            direction: Literal["lower", "higher"] | None = (
                "lower" if better == CBRS.Lower else "higher" if better == CBRS.Higher else None
            )
            try:
                number = float(_value(row["value"]))
            except ValueError:
                raise InvalidDescriptionError(iri, [f"QoS {_iri(row['metric'])} is not a number"]) from None
            values.append(QoSValue(_iri(row["metric"]), number, direction))
        return tuple(values)

    def _ports(self, iri: str) -> tuple[Port, ...]:
        kinds = {CBRS.ServicePort: "service", CBRS.DataPort: "data", CBRS.EventPort: "event"}
        ports = []
        for row in self._queries.select(self._store, "description_ports", {"description": iri}):
            kind = kinds.get(_iri(row["portType"]))
            if kind is None:
                continue
            ports.append(
                Port(
                    iri=_iri(row["port"]),
                    kind=cast(Literal["service", "data", "event"], kind),
                    name=_value(row["name"]) if "name" in row else None,
                    data_type=_iri(row["dataType"]) if "dataType" in row else None,
                    topic=_value(row["topic"]) if "topic" in row else None,
                    message_type=_value(row["messageType"]) if "messageType" in row else None,
                )
            )
        return tuple(ports)


def _iri(term: Term) -> str:
    if isinstance(term, ox.BlankNode):
        raise BlankNodeError("(a description)", str(term))
    if not isinstance(term, ox.NamedNode):
        raise TypeError(f"expected an IRI, got {term}")
    return term.value


def _named(terms: Any) -> list[str]:
    found = []
    for term in terms:
        if isinstance(term, ox.NamedNode):
            found.append(term.value)
        else:
            log.warning("passed over a description named by the blank node %s", term)
    return found


def _value(term: Term) -> str:
    return term.value
