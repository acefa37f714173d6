"""Read typed service descriptions out of the store through the named queries."""

from __future__ import annotations

import logging
from collections.abc import Callable
from typing import Any, Literal, cast

import pyoxigraph as ox

from cbrs.kb.errors import BlankNodeError, InvalidDescriptionError, NotAnIriError, NotFoundError
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

Rows = list[dict[str, Term]]
Source = Callable[[str, str], Rows]
"""Where a reader gets the rows of a per-description query (its name, the description's IRI)."""


class DescriptionReader:
    """Builds Advertisement and Requirement objects; part trees are cached per concept.

    The hasPart rows of every concept are read at once, by ``concept_parts`` with no concept bound,
    the first time a tree is needed: one query instead of one per concept (on an on-disk store each
    took about 0.1 s, a minute for the 645 concepts of OWLS-TC). They and the trees are kept until
    :meth:`clear_cache` or, on an embedded store, until its generation changes (any write through it).
    """

    def __init__(self, store: Store, queries: QueryLibrary) -> None:
        self._store = store
        self._queries = queries
        self._trees: dict[str, PartNode] = {}
        self._parts: dict[str, list[dict[str, Term]]] | None = None
        self._generation: object = getattr(store, "generation", None)

    def clear_cache(self) -> None:
        """Forget cached part trees (call after the ontology graph changes)."""
        self._trees.clear()
        self._parts = None

    def _current(self) -> None:
        """Drop the caches if the store was written since they were filled."""
        generation = getattr(self._store, "generation", None)
        if generation != self._generation:
            self._generation = generation
            self.clear_cache()

    def _part_rows(self, concept: str) -> list[dict[str, Term]]:
        """The ``concept_parts`` rows of ``concept``, from the one read of every concept's rows."""
        if self._parts is None:
            table: dict[str, list[dict[str, Term]]] = {}
            for row in self._queries.select_every(self._store, "concept_parts"):
                whole = row.get("concept")
                if isinstance(whole, ox.NamedNode):  # a bound concept is always an IRI
                    table.setdefault(whole.value, []).append(row)
            self._parts = table
        return self._parts.get(concept, [])

    def advertisement_iris(self) -> list[str]:
        """The advertisements' IRIs; one that is a blank node (an update's doing) is passed over."""
        return _named(row["service"] for row in self._queries.select(self._store, "advertisements"))

    def requirement_iris(self) -> list[str]:
        return _named(row["requirement"] for row in self._queries.select(self._store, "requirements"))

    def read(self, iri: str) -> ServiceDescription:
        """The advertisement or requirement ``iri``; NotFoundError when it is neither, BlankNodeError
        (400) when a node of it is blank. Read from the store every time, its queries asked for at once
        (one request to a remote store)."""
        return self._read_from(_Prefetched(self._store, self._queries, {"description": iri}), iri)

    def _one(self, name: str, iri: str) -> Rows:
        """The rows of one description: the query with it bound."""
        return self._queries.select(self._store, name, {"description": iri})

    def _read_from(self, rows: Source, iri: str) -> ServiceDescription:
        try:
            return self._read(rows, iri)
        except BlankNodeError as error:
            raise BlankNodeError(iri, error.node) from None
        except NotAnIriError as error:
            raise NotAnIriError(iri, error.value) from None

    def _read(self, rows: Source, iri: str) -> ServiceDescription:
        head = rows("description", iri)
        if not head:
            raise NotFoundError(iri, "service description")
        types = tuple(sorted({_iri(row["type"]) for row in head}))
        first = {name: _value(term) for row in head for name, term in row.items() if name != "type"}
        parameters = self._parameters(rows, iri)
        conditions = self._conditions(rows, iri)
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
            area=self._area(rows, iri),
            qos=self._qos(rows, iri),
        )
        if CBRS.Requirement in types:
            return Requirement(**common, requested_by=first.get("requestedBy"), for_task=first.get("forTask"))
        kinds = [t for t in types if t not in (CBRS.Advertisement, CBRS.ServiceDescription)]
        return Advertisement(
            **common,
            kind=kinds[0] if kinds else CBRS.Advertisement,
            device=first.get("device"),
            realizes_action=first.get("realizesAction"),
            ports=self._ports(rows, iri),
        )

    def read_action(self, iri: str, label: str | None = None) -> Requirement:
        """The IOPE an action class carries (OWL 2 punning), as a requirement to compose for.

        NotFoundError when ``iri`` carries no OWL-S model.
        """
        rows = self._queries.select(self._store, "description_model", {"description": iri})
        if not rows or rows[0]["models"].value == "0":
            raise NotFoundError(iri, "action with inputs, outputs, preconditions or effects")
        parameters = self._parameters(self._one, iri)
        conditions = self._conditions(self._one, iri)
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
        """Every readable advertisement: one with a blank node inside, or a literal where an IRI is
        needed, is passed over (and logged), so one bad update does not stop matching and planning for
        everyone."""
        return [cast(Advertisement, found) for found in self._readable(self.advertisement_iris())]

    def requirements(self) -> list[Requirement]:
        return [cast(Requirement, found) for found in self._readable(self.requirement_iris())]

    def _readable(self, iris: list[str]) -> list[ServiceDescription]:
        batch = _Batch(self._store, self._queries) if len(iris) > 1 else None
        found = []
        for iri in iris:
            rows = batch or _Prefetched(self._store, self._queries, {"description": iri})
            try:
                found.append(self._read_from(rows, iri))
            except (BlankNodeError, NotAnIriError) as error:
                log.warning("passed over: %s", error)
        return found

    def part_tree(self, concept: str) -> PartNode:
        """The concept with its hasPart children, recursively; a cycle is a modelling error."""
        self._current()
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
        rows = self._part_rows(concept)
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

    def _parameters(self, rows: Source, iri: str) -> dict[str, tuple[Parameter, ...]]:
        """Inputs and outputs, from one query."""
        found: dict[str, list[Parameter]] = {"input": [], "output": []}
        for row in rows("description_parameters", iri):
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

    def _conditions(self, rows: Source, iri: str) -> dict[str, tuple[Statement, ...]]:
        """Preconditions and effects, from one query."""
        found: dict[str, list[Statement]] = {"precondition": [], "effect": [], "delete": []}
        for row in rows("description_conditions", iri):
            role = _value(row["role"])
            missing = [part for part in ("subject", "predicate", "object") if part not in row]
            if missing:
                names = ", ".join(f"cbrs:condition{part.title()}" for part in missing)
                problem = f"{role} {_iri(row['condition'])} lacks {names}"
                raise InvalidDescriptionError(iri, [problem])
            found[role].append(Statement(_iri(row["subject"]), _iri(row["predicate"]), _iri(row["object"])))
        return {role: tuple(items) for role, items in found.items()}

    def _area(self, rows: Source, iri: str) -> EffectiveArea | None:
        found = rows("description_sea", iri)
        if not found:
            return None
        areas = tuple(sorted({_iri(row["area"]) for row in found if "area" in row}))
        box = [found[0].get(name) for name in ("minX", "maxX", "minY", "maxY")]
        bounds = None
        if all(term is not None for term in box):
            x0, x1, y0, y1 = (float(_value(cast(Term, term))) for term in box)
            bounds = (x0, x1, y0, y1)
        return EffectiveArea(areas, bounds)

    def _qos(self, rows: Source, iri: str) -> tuple[QoSValue, ...]:
        values = []
        for row in rows("description_qos", iri):
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

    def _ports(self, rows: Source, iri: str) -> tuple[Port, ...]:
        kinds = {CBRS.ServicePort: "service", CBRS.DataPort: "data", CBRS.EventPort: "event"}
        ports = []
        for row in rows("description_ports", iri):
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


PER_DESCRIPTION = (
    "description",
    "description_parameters",
    "description_conditions",
    "description_sea",
    "description_qos",
    "description_ports",
)
"""The named queries a description is read from, asked for together (:meth:`QueryLibrary.select_each`)."""


class _Prefetched:
    """The rows of every :data:`PER_DESCRIPTION` query with ``values`` bound, asked for at once on the
    first call: one request to a remote store instead of six (a run reads a step's description again
    after each step; FetchMyPen's 15 steps cost 90 requests)."""

    def __init__(self, store: Store, queries: QueryLibrary, values: dict[str, str]) -> None:
        self._store = store
        self._queries = queries
        self._values = values
        self._rows: dict[str, Rows] | None = None

    def table(self) -> dict[str, Rows]:
        if self._rows is None:
            answers = self._queries.select_each(self._store, [(name, self._values) for name in PER_DESCRIPTION])
            self._rows = dict(zip(PER_DESCRIPTION, answers, strict=True))
        return self._rows

    def __call__(self, name: str, iri: str) -> Rows:
        return self.table()[name]


class _Batch:
    """The rows of many descriptions: each per-description query is run once with no description
    bound and its rows are grouped by description, in the order the query gives them (its ORDER BY
    holds within a group). Reading every advertisement so costs six queries, not six per
    advertisement (OWLS-TC's 1,137 descriptions: 6,825 queries, 4 s on disk), and one request to a
    remote store (:class:`_Prefetched`)."""

    def __init__(self, store: Store, queries: QueryLibrary) -> None:
        self._every = _Prefetched(store, queries, {})
        self._tables: dict[str, dict[str, Rows]] = {}

    def __call__(self, name: str, iri: str) -> Rows:
        table = self._tables.get(name)
        if table is None:
            table = {}
            for row in self._every.table()[name]:
                owner = row.get("description")
                if isinstance(owner, ox.NamedNode):  # a bound description is always an IRI
                    table.setdefault(owner.value, []).append(row)
            self._tables[name] = table
        return table.get(iri, [])


def _iri(term: Term) -> str:
    if isinstance(term, ox.BlankNode):
        raise BlankNodeError("(a description)", str(term))
    if not isinstance(term, ox.NamedNode):
        raise NotAnIriError("(a description)", str(term))
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
