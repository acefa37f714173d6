"""The component container's repository (paper section 2.2): register, update and deregister
advertisements, each as one transaction on the services graph."""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path

import pyoxigraph as ox

from cbrs.kb.conditions import CONDITION_PARTS, LEGACY_PARTS
from cbrs.kb.errors import (
    AlreadyRegisteredError,
    ForeignStatementError,
    InvalidDescriptionError,
    NotFoundError,
    OutsideRegistryError,
)
from cbrs.kb.loader import LoadReport, parse_bytes, prepare_owls, registration_format
from cbrs.kb.namespaces import BASE, RDF, RDFS, GraphName, shorten, written
from cbrs.kb.owls import is_owls, is_owls_service
from cbrs.kb.owls_source import GraphReads, owls_services, owls_source
from cbrs.kb.results import releases_results
from cbrs.kb.shapes import check_descriptions, line_of, nearest_term
from cbrs.kb.skolem import closure, is_skolem
from cbrs.kb.standard_terms import StandardTerms
from cbrs.kb.store import Store
from cbrs.kb.vocab import CBRS


@dataclass(frozen=True)
class Synced:
    """What :meth:`ComponentRegistry.synced` did: the advertisements it registered and those it updated,
    and for an OWL-S input the report of its conversion (what ``cbrs load`` of the file would note:
    unresolved imports and concepts, conversion notes, mended parts); ``None`` for any other input."""

    registered: list[str]
    updated: list[str]
    conversion: LoadReport | None = None


class ComponentRegistry:
    """Advertisements in the services graph. A description is the advertisement's own triples
    plus those of the nodes hanging off it (its OWLS, SEA and QoS models, parameters, conditions)."""

    def __init__(self, store: Store, standard_terms: StandardTerms | None = None) -> None:
        self._store = store
        self._graph = GraphName.SERVICES.node
        self._standard_terms = standard_terms or StandardTerms(store)  # graph:entailed kept up to date

    def register(self, turtle: str | bytes, source: str = "<registration>") -> list[str]:
        """Add the advertisements described in ``turtle``; refuses any that already exist, in graph:services
        or in another graph (:class:`OutsideRegistryError`: ``cbrs load`` of a file that declares classes
        puts its descriptions into graph:ontology), where a second description would be read merged
        with the first (two OWLS models' inputs and outputs, both QoS values), before anything is written."""
        return self.register_all([(turtle, source)])

    def register_all(self, inputs: Sequence[tuple[str | bytes, str]]) -> list[str]:
        """:meth:`register` for several inputs, each ``(text, source)``, in one transaction: every one is
        checked before anything is written, so a bad file registers none of the others (a lab's component
        and the devices it needs, in files of their own). An advertisement two inputs describe is
        refused (:class:`InvalidDescriptionError` naming the second): read together, its two
        descriptions would merge."""
        parsed = self._parse_all(inputs, owls=False)
        quads = [quad for these, _, _ in parsed for quad in these]
        iris = [iri for _, named, _ in parsed for iri in named]
        for iri in iris:
            if self._types(iri):  # an advertisement, or another resource of the graph (a device) by that IRI
                raise AlreadyRegisteredError(iri)
            self._refuse_elsewhere(iri)
        before = self._standard_terms.begin()
        self._store.add(quads)
        self._standard_terms.changed(before, [], quads)
        return iris

    def update(self, turtle: str | bytes, source: str = "<update>") -> list[str]:
        """Replace the descriptions of the advertisements in ``turtle``; each must exist. What goes is
        what :meth:`deregister` would remove: one loaded from OWL-S loses its OWL-S triples too, which
        no longer describe it (its service node's own went, its profile and process stayed)."""
        quads, iris = self._parse(turtle, source)
        for iri in iris:
            if not self.is_registered(iri):
                raise self._not_found(iri)
        self._write(quads, iris)
        return iris

    def sync(self, turtle: str | bytes, source: str = "<update>") -> tuple[list[str], list[str]]:
        """:meth:`synced`'s registered and updated IRIs."""
        done = self.synced(turtle, source)
        return done.registered, done.updated

    def synced(self, turtle: str | bytes, source: str = "<update>") -> Synced:
        """Bring graph:services in line with ``turtle``: replace the descriptions of its advertisements
        that are registered, register the others, in one transaction; returns (registered, updated).
        A file of two advertisements one of which was deregistered could be neither registered again
        (the other is registered) nor updated (one is not). What :meth:`register` refuses (another
        resource by an advertisement's IRI) and :meth:`update` refuses (an advertisement held in another
        graph, which this would register a second time) is refused here too, before anything is written.

        An OWL-S file is converted as ``cbrs load`` converts it (:func:`kb.loader.prepare_owls`), and what
        an earlier load of it gave its registered services (:meth:`owned_quads`, OWL-S triples included)
        is replaced by what it gives now: what ``cbrs deregister`` of each and ``cbrs load FILE`` did in
        several transactions, of which a failed load left the services deregistered. Its report says what
        the conversion noted, as a load of the file would (``cbrs register --update`` prints it)."""
        return self.synced_all([(turtle, source)])[0]

    def synced_all(self, inputs: Sequence[tuple[str | bytes, str]]) -> list[Synced]:
        """:meth:`synced` for several inputs, each ``(text, source)``, in one transaction (all or none),
        one :class:`Synced` per input; an advertisement two inputs describe is refused, as by
        :meth:`register_all`."""
        done: list[Synced] = []
        parsed = self._parse_all(inputs, owls=True)
        for _, iris, conversion in parsed:
            added = []
            for iri in iris:
                if self.is_registered(iri):
                    continue
                if self._types(iri):
                    raise AlreadyRegisteredError(iri)  # a device by that IRI: not the file's to replace
                self._refuse_elsewhere(iri)
                added.append(iri)
            done.append(Synced(added, [iri for iri in iris if iri not in added], conversion))
        self._write([quad for these, _, _ in parsed for quad in these], [iri for d in done for iri in d.updated])
        return done

    def _parse_all(
        self, inputs: Sequence[tuple[str | bytes, str]], owls: bool
    ) -> list[tuple[list[ox.Quad], list[str], LoadReport | None]]:
        """Each input's quads, advertisements and (``owls``: an OWL-S input's) conversion report, checked as
        :meth:`_parse` checks one; an advertisement two inputs describe is refused naming the second."""
        parsed: list[tuple[list[ox.Quad], list[str], LoadReport | None]] = []
        first: dict[str, str] = {}
        for turtle, source in inputs:
            conversion: list[LoadReport] = []
            quads, iris = self._parse(turtle, source, owls=owls, conversion=conversion)
            for iri in iris:
                if iri in first:
                    raise _described_twice(iri, first[iri], source)
                first[iri] = source
            parsed.append((quads, iris, conversion[0] if conversion else None))
        return parsed

    def _refuse_elsewhere(self, iri: str) -> None:
        """Raise :class:`OutsideRegistryError` when another graph holds an advertisement by ``iri``."""
        missing = self._not_found(iri)
        if isinstance(missing, OutsideRegistryError):
            raise missing

    def _write(self, quads: list[ox.Quad], registered: list[str]) -> None:
        """Replace what the ``registered`` advertisements own with ``quads`` in one store transaction, and
        bring graph:entailed up to date. What they own is read as deregistering them one after the other
        would remove it: a node only they share (a QoS model, an OWL-S file's header) goes with the last,
        and comes back as ``quads`` give it now; read for each alone, it stayed, beside its new values."""
        lookup = GraphReads(self._store, self._graph)
        old: list[ox.Quad] = []
        for iri in registered:
            owned = self._owned(iri, lookup)
            lookup.drop(owned)
            old.extend(owned)
        new, kept = set(quads), set(old)
        before = self._standard_terms.begin()
        self._store.replace([q for q in old if q not in new], [q for q in quads if q not in kept])
        self._standard_terms.changed(before, old, quads)

    def deregister(self, iri: str) -> int:
        """Remove one advertisement's description, or a requirement's from the requirements graph (which
        has no registry of its own: an edited requirement file is loaded again after this); returns the
        number of triples removed."""
        graph = self._graph
        if not self.is_registered(iri):
            requirement = (ox.NamedNode(iri), ox.NamedNode(RDF + "type"), ox.NamedNode(CBRS.Requirement))
            graph = GraphName.REQUIREMENTS.node
            if next(iter(self._store.quads(*requirement, graph)), None) is None:
                raise self._not_found(iri, "registered advertisement or requirement")
        old = self.owned_quads(iri, graph)
        before = self._standard_terms.begin()
        self._store.replace(old, [])
        self._standard_terms.changed(before, old, [])
        return len(old)

    def _not_found(self, iri: str, what: str = "registered advertisement") -> NotFoundError:
        """Not registered: said so, or where the advertisement is when another graph holds it."""
        kinds = _advertisement_classes(self._store)
        for quad in self._store.quads(ox.NamedNode(iri), ox.NamedNode(RDF + "type"), None):
            if isinstance(quad.object, ox.NamedNode) and quad.object.value in kinds:
                return OutsideRegistryError(
                    iri, str(quad.graph_name.value) if isinstance(quad.graph_name, ox.NamedNode) else ""
                )
        return NotFoundError(iri, what)

    def is_registered(self, iri: str) -> bool:
        """Whether graph:services types ``iri`` as an advertisement (a component kind, or a lab's subclass
        of one). Any type would do before, so ``cbrs deregister`` of a device removed the device."""
        types = self._types(iri)
        if not types:
            return False
        return bool(types & _KIND_SET) or bool(types & _advertisement_classes(self._store))

    def _types(self, iri: str) -> set[str]:
        node = ox.NamedNode(iri)
        return {q.object.value for q in self._store.quads(node, ox.NamedNode(RDF + "type"), None, self._graph)}  # type: ignore[union-attr]

    def description_quads(
        self, iri: str, graph: ox.NamedNode | None = None, lookup: GraphReads | None = None
    ) -> list[ox.Quad]:
        """The advertisement's triples (in the services graph, or ``graph``) and, recursively, those of
        its parts: skolemised nodes, and models, parameters, conditions and ports given IRIs of their own.
        A part that something outside the description points at too is shared, and stays: a named one,
        or a blank node one file gives two descriptions (``cbrs:hasQoSModel _:q`` on both), which went
        with the first description deregistered."""
        root = ox.NamedNode(iri)
        lookup = lookup or GraphReads(self._store, graph or self._graph)

        def quads_of(
            node: ox.NamedNode | ox.BlankNode | ox.Triple, skip: frozenset[object] = frozenset()
        ) -> list[ox.Quad]:
            return [] if node in skip else lookup.out(node)  # type: ignore[arg-type]

        found = closure([root], quads_of, parts=True)
        own = {q.subject for q in found}
        shared = frozenset(
            node
            for node in own
            if node != root and any(q.subject not in own for q in lookup.into(node))  # type: ignore[arg-type]
        )
        if not shared:
            return found
        return [q for q in closure([root], lambda node: quads_of(node, shared), parts=True) if q.subject not in shared]

    def owned_quads(self, iri: str, graph: ox.NamedNode | None = None) -> list[ox.Quad]:
        """What deregistering ``iri`` removes: its description (:meth:`description_quads`) and, for one
        ``cbrs load`` made from OWL-S, the OWL-S triples of its service as well (:func:`kb.owls_source.owls_source`),
        so that deregistering leaves the store as it was before the load. Each node's triples are read
        from the store once (a remote store answers each read with a request)."""
        return self._owned(iri, GraphReads(self._store, graph or self._graph))

    def _owned(self, iri: str, lookup: GraphReads) -> list[ox.Quad]:
        root = ox.NamedNode(iri)
        services = owls_services(root, lookup)
        if not services:
            return self.description_quads(iri, lookup.graph, lookup)
        return owls_source(root, services, lookup)

    def _loaded_already(self, quads: list[ox.Quad], source: str) -> str:
        """For an OWL-S file some of whose services are advertisements already, the commands that bring the
        store in line with it: ``cbrs load`` adds nothing for an unchanged file, and refuses one that
        differs from what is stored (a service edited, or deregistered while another stayed), so those
        go first; the load then converts every service of the file, in one transaction."""
        services = sorted(
            {
                q.subject.value
                for q in quads
                if q.predicate.value == RDF + "type"
                and isinstance(q.subject, ox.NamedNode)
                and isinstance(q.object, ox.NamedNode)
                and is_owls_service([q.object.value])
            }
        )
        loaded = [iri for iri in services if self.is_registered(iri)]
        if not loaded:
            return ""
        file = source if not source.startswith("<") else "FILE"
        return (
            f"; {_count(len(loaded), 'of its services is', 'of its services are')} loaded already "
            f"({', '.join(shorten(iri) for iri in loaded)}): cbrs register --update {file} replaces "
            f"{'it' if len(loaded) == 1 else 'them'} and registers the others, in one transaction"
        )

    def _parse(
        self, turtle: str | bytes, source: str, owls: bool = False, conversion: list[LoadReport] | None = None
    ) -> tuple[list[ox.Quad], list[str]]:
        """The input's quads, checked, and its advertisements' IRIs; with ``owls``, an OWL-S input is
        converted into advertisements (:func:`kb.loader.prepare_owls`) instead of refused, and the
        conversion's report is appended to ``conversion``."""
        try:
            return self._parse_checked(turtle, source, owls, conversion)
        except InvalidDescriptionError as error:
            if error.iri != source and not source.startswith("<") and Path(source).is_file():
                line = line_of(source, error.iri)  # a file of many descriptions: where this one is
                error.args = (f"{source}{f':{line}' if line else ''}: {error.args[0]}",)
            raise

    def _parse_checked(
        self, turtle: str | bytes, source: str, owls: bool, conversion: list[LoadReport] | None
    ) -> tuple[list[ox.Quad], list[str]]:
        raw = turtle.encode("utf-8") if isinstance(turtle, str) else turtle
        rdf_format = registration_format(source, raw)  # Turtle, unless the file's name or XML head says otherwise
        parsed = parse_bytes(raw, source, rdf_format, graph=GraphName.SERVICES, base_iri=_base(source))
        if is_owls(parsed.quads) and owls:
            report = prepare_owls(self._store, raw, source, rdf_format, _base(source))
            if conversion is not None:
                conversion.append(report)
            converted = report.files[0]
            assert converted.owls is not None
            return converted.quads, sorted({service.iri for service in converted.owls.services})
        if is_owls(parsed.quads):
            raise InvalidDescriptionError(
                source,
                [
                    "it is an OWL-S description, which registration converts only as an update (cbrs register "
                    "--update, kb.registry.sync): load it with cbrs load (kb.load), which turns each OWL-S service "
                    "into an advertisement" + self._loaded_already(parsed.quads, source)
                ],
            )
        elsewhere = sorted({str(q.graph_name) for q in parsed.quads if q.graph_name != GraphName.SERVICES.node})
        if elsewhere:
            graph = elsewhere[0]
            raise InvalidDescriptionError(
                source, [f"it names the graph {graph}; registration writes graph:services only (use cbrs load)"]
            )
        iris = _advertisements(self._store, parsed.quads)
        if not iris:
            check_descriptions(self._store, parsed.quads)  # a misspelt component kind gets its did-you-mean
            raise InvalidDescriptionError(source, [_no_advertisement(parsed.quads)])
        requirements = _requirements(parsed.quads)
        if requirements:
            raise InvalidDescriptionError(
                source,
                [
                    f"it describes the requirement {shorten(requirements[0])} besides advertisements; a requirement "
                    "goes into the requirements graph (cbrs load --graph requirements FILE), so register the "
                    "advertisements from a file of their own"
                ],
            )
        fields = _fields(parsed.quads)
        for iri in iris:
            problems = _problems(iri, fields)
            if problems:
                raise InvalidDescriptionError(iri, problems)
        check_descriptions(self._store, parsed.quads)  # SHACL shapes and declared terms (kb/shapes.py)
        self._refuse_foreign(parsed.quads, iris, source)
        return parsed.quads, iris

    @releases_results
    def _refuse_foreign(self, quads: list[ox.Quad], iris: list[str], source: str) -> None:
        """Refuse a statement, new to the store, about a term another graph than graph:services (and the
        derived graph:entailed) describes: a registration is read through the union graph by everyone, so
        one stray ``home:Cup rdfs:subClassOf home:Door`` would make every robot's cup a door, and stay
        after deregistration. Another advertisement is foreign too: a second device name stated for a
        camera by a kitchen light's registration renamed the camera and outlived the light. The
        advertisements, their own nodes, the devices they name (a lab's door motor placed in the map
        first) and the input's new terms (a lab's device kind) are its own; repeating what the store
        already holds changes nothing and passes."""
        own = {GraphName.SERVICES.node, GraphName.ENTAILED.node}
        ads = {ox.NamedNode(iri) for iri in iris}
        devices = {q.object for q in quads if q.subject in ads and q.predicate.value == CBRS.device}
        subjects = sorted(
            {q.subject for q in quads if isinstance(q.subject, ox.NamedNode)} - ads - devices,
            key=str,
        )
        for subject in subjects:
            if is_skolem(subject.value):
                continue
            graphs = sorted({q.graph_name for q in self._store.quads(subject, None, None, None)} - own, key=str)
            if not graphs and self.is_registered(subject.value):  # another advertisement: its own registration's
                graphs = [GraphName.SERVICES.node]
            if not graphs:
                continue
            for quad in quads:
                if quad.subject != subject or self._held_anywhere(quad):
                    continue
                terms = (quad.subject, quad.predicate, quad.object)
                shown = " ".join(written(t.value) if isinstance(t, ox.NamedNode) else str(t) for t in terms)
                graph = graphs[0]
                raise ForeignStatementError(source, subject.value, getattr(graph, "value", str(graph)), shown)

    def _held_anywhere(self, quad: ox.Quad) -> bool:
        """Whether the store holds ``quad``'s triple in any graph: matched by the store, which matches a
        literal as it keeps it ("0.50"^^xsd:decimal as "0.5"); a quoted triple, which a pattern cannot fix,
        compared."""
        assert isinstance(quad.subject, ox.NamedNode | ox.BlankNode)
        if isinstance(quad.object, ox.Triple):
            return any(held.object == quad.object for held in self._store.quads(quad.subject, quad.predicate))
        return next(self._store.quads(quad.subject, quad.predicate, quad.object), None) is not None


def _count(count: int, one: str, many: str) -> str:
    return f"{count} {one if count == 1 else many}"


def _base(source: str) -> str:
    """Relative IRIs (``<#Cam>``) of a file resolve against the file, as ``cbrs load`` resolves them, so
    that registering and loading one file name the same things; those of a text sent without a file name
    (``<registration>``) against cbrs's base."""
    path = Path(source)
    return path.resolve().as_uri() if not source.startswith("<") and path.is_file() else BASE


def _no_advertisement(quads: list[ox.Quad]) -> str:
    """Why no advertisement was found, with the fix when a subject looks like a description."""
    requirements = {
        q.subject for q in quads if q.predicate.value == RDF + "type" and q.object == ox.NamedNode(CBRS.Requirement)
    }
    described = sorted(
        {
            q.subject.value
            for q in quads
            if q.predicate.value in (CBRS.hasOWLSModel, CBRS.serviceName, CBRS.deviceName)
            and isinstance(q.subject, ox.NamedNode)
        }
    )
    for iri in described:
        if ox.NamedNode(iri) in requirements:
            return (
                f"it describes no advertisement: {shorten(iri)} is a requirement, which goes into the requirements "
                "graph: cbrs load --graph requirements FILE"
            )
    if described:
        return (
            f"it describes no advertisement: {shorten(described[0])} has no component kind; type it "
            f"{', '.join(shorten(k) for k in _KINDS[:-1])} or {shorten(_KINDS[-1])}"
        )
    return "it describes no advertisement (a subject typed with a cbrs component kind)"


_KINDS = (
    CBRS.DynamicPerceptionComponent,
    CBRS.StaticDataComponent,
    CBRS.PhysicalManipulationComponent,
    CBRS.MethodInvocationComponent,
)
_KIND_SET = frozenset({*_KINDS, CBRS.Advertisement})


def _requirements(quads: list[ox.Quad]) -> list[str]:
    """The requirements among ``quads``: registration wrote them into graph:services with the
    advertisements, where no deregistration looks for them."""
    kind = ox.NamedNode(CBRS.Requirement)
    return sorted(
        {
            q.subject.value
            for q in quads
            if q.predicate.value == RDF + "type" and q.object == kind and isinstance(q.subject, ox.NamedNode)
        }
    )


def _advertisements(store: Store, quads: Iterable[ox.Quad]) -> list[str]:
    quads = list(quads)
    stored = _advertisement_classes(store)
    kinds = stored | _declared_kinds(quads, stored)
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


@releases_results
def _advertisement_classes(store: Store) -> set[str]:
    result = store.query("SELECT ?c WHERE { ?c rdfs:subClassOf* cbrs:Advertisement }")
    assert isinstance(result, ox.QuerySolutions)
    return {row["c"].value for row in result} | {CBRS.Advertisement}


def _declared_kinds(quads: list[ox.Quad], kinds: set[str]) -> set[str]:
    """Classes the input itself declares under a component kind (``lab:DoorCamera rdfs:subClassOf
    cbrs:DynamicPerceptionComponent``), so that a description typed with one is an advertisement."""
    parents: dict[str, set[str]] = {}
    for q in quads:
        subject, parent = q.subject, q.object
        is_link = q.predicate.value == RDFS + "subClassOf"
        if is_link and isinstance(subject, ox.NamedNode) and isinstance(parent, ox.NamedNode):
            parents.setdefault(subject.value, set()).add(parent.value)
    found: set[str] = set()
    grew = True
    while grew:
        grew = False
        for child, above in parents.items():
            if child not in found and above & (kinds | found):
                found.add(child)
                grew = True
    return found


_Fields = dict[ox.NamedNode, dict[str, list[ox.NamedNode | ox.BlankNode | ox.Literal]]]


def _fields(quads: list[ox.Quad]) -> _Fields:
    """Each named subject's values by property: built once for all the descriptions of an input."""
    by_subject: _Fields = {}
    for q in quads:
        if isinstance(q.subject, ox.NamedNode) and not isinstance(q.object, ox.Triple):
            by_subject.setdefault(q.subject, {}).setdefault(q.predicate.value, []).append(q.object)
    return by_subject


def _problems(iri: str, by_subject: _Fields) -> list[str]:
    """What the six-tuple lacks: checked on the triples before anything is written. Nodes are named by
    their role (and a parameter by its name), not by the IRIs the loader made for them."""
    own = by_subject.get(ox.NamedNode(iri), {})
    problems = []
    for prop, label in ((CBRS.serviceName, "service name (SN)"), (CBRS.deviceName, "device name (DN)")):
        if len(own.get(prop, [])) != 1:
            problems.append(f"needs exactly one {label}, cbrs:{prop.rsplit('#', 1)[1]}")
    models = own.get(CBRS.hasOWLSModel, [])
    if len(models) != 1:
        return [*problems, "needs exactly one cbrs:hasOWLSModel"]
    model = by_subject.get(models[0], {}) if isinstance(models[0], ox.NamedNode) else {}
    if not model.get(CBRS.hasOutput) and not model.get(CBRS.hasEffect):
        problems.append("its OWLS model has neither an output nor an effect")
    for prop, role in ((CBRS.hasInput, "input"), (CBRS.hasOutput, "output")):
        for parameter in model.get(prop, []):
            fields = by_subject.get(parameter, {}) if isinstance(parameter, ox.NamedNode) else {}
            if not fields.get(CBRS.parameterType):
                hint = _slips(fields, [CBRS.parameterType])
                problems.append(f"{_node(role, parameter, fields)} has no cbrs:parameterType{hint}")
    for prop, role in ((CBRS.hasPrecondition, "precondition"), (CBRS.hasEffect, "effect")):
        for condition in model.get(prop, []):
            fields = by_subject.get(condition, {}) if isinstance(condition, ox.NamedNode) else {}
            legacy = [shorten(p) for p in LEGACY_PARTS if fields.get(p)]
            missing = [shorten(p) for p in CONDITION_PARTS if not fields.get(p)]
            if legacy:
                problems.append(
                    f"{_node(role, condition, fields)} uses {', '.join(legacy)}, the reified form of core 0.1.0 "
                    "(outside OWL 2 DL): write cbrs:conditionSubject, cbrs:conditionPredicate and cbrs:conditionObject"
                )
            elif missing:
                hint = _slips(fields, [p for p in CONDITION_PARTS if not fields.get(p)])
                problems.append(f"{_node(role, condition, fields)} lacks {', '.join(missing)}{hint}")
    return problems


_PARTS = frozenset((*CONDITION_PARTS, CBRS.parameterType, CBRS.parameterName, RDF + "type"))


def _slips(fields: dict[str, list[ox.NamedNode | ox.BlankNode | ox.Literal]], absent: Sequence[str]) -> str:
    """`` (it has cbrs:conditionPredicat: did you mean cbrs:conditionPredicate?)`` for a property of the node
    that reads as a misspelling of a part it lacks; empty when none does. A misspelt required part was
    reported as missing only, where a misspelt optional one got its did-you-mean from the shapes."""
    hints = []
    for prop in sorted(set(fields) - _PARTS):  # a part it has is no slip: conditionSubject is near conditionObject
        near = nearest_term(prop, absent, cutoff=0.8)
        if near is not None:
            hints.append(f"it has {shorten(prop)}: did you mean {shorten(near)}?")
    return f" ({'; '.join(hints)})" if hints else ""


def _node(role: str, node: object, fields: dict[str, list[ox.NamedNode | ox.BlankNode | ox.Literal]]) -> str:
    """``the input "markerColour"``, ``an effect`` or ``the output <iri>``: how a problem names a node."""
    names = fields.get(CBRS.parameterName, [])
    if names:
        return f'the {role} "{names[0].value}"'
    if isinstance(node, ox.NamedNode) and not is_skolem(node):
        return f"the {role} {shorten(node.value)}"
    return f"{'an' if role[0] in 'aeiou' else 'a'} {role}"


def _described_twice(iri: str, first: str, source: str) -> InvalidDescriptionError:
    return InvalidDescriptionError(
        source,
        [
            f"it describes {shorten(iri)}, which {first} describes too: registered together, the two "
            "descriptions would be read as one; keep one of them"
        ],
    )
