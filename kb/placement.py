"""Where a lab's task and a component's advertisement go among the graphs it loads into: a task (a
``cbrs:Requirement``) into graph:requirements, an advertisement into graph:services. Every way a file comes in
asks :func:`check_placement` before anything is written (``cbrs load --graph``, the Graph Store's ``PUT`` and
``POST``, the Load a file page); it lived in :mod:`kb.loader`, which re-exports both names.
"""

from __future__ import annotations

import re
from collections import defaultdict
from collections.abc import Mapping, Sequence

import pyoxigraph as ox

from cbrs.kb.errors import KnowledgeBaseError
from cbrs.kb.namespaces import CBRS, OWL, RDF, RDFS, GraphName, written
from cbrs.kb.store import Store

__all__ = ["DECLARATION_TYPES", "MisplacedDescriptionError", "check_placement"]

DECLARATION_TYPES = {OWL + "Class", RDFS + "Class", OWL + "ObjectProperty", OWL + "DatatypeProperty"}
"""The types that declare a class or a property: a file stating one is an ontology's."""
_NCNAME = re.compile(r"^[A-Za-z_\u00c0-\uffff][\w.\-\u00b7\u00c0-\uffff]*$")


class MisplacedDescriptionError(KnowledgeBaseError):
    """A task (a ``cbrs:Requirement``) written into another of the graphs a lab loads into than
    graph:requirements, or a component's advertisement (a ``cbrs:Advertisement`` or a kind of it) into another
    than graph:services. A lab's file says in its header where it goes, and ``--graph map`` or a list on a page
    is easy to pick wrong; loaded, the task sat in the map without a word. Nothing was written."""

    http_status = 400
    kind = "bad-request"  # the JSON error's name, as the Graph Store's other 400s

    def __init__(
        self, source: str, subject: str, kind: str, graph: str, belongs: GraphName, prefixes: Mapping[str, str]
    ) -> None:
        self.source = source
        self.subject = subject
        self.described_as = kind
        self.graph = graph
        self.belongs = belongs
        named = f"{_written(subject, prefixes)}, a {_written(kind, prefixes)}"
        super().__init__(
            f"{source} describes {self.what} ({named}): {self.rule}, not {written(graph)}; nothing was loaded"
        )

    @property
    def what(self) -> str:
        return "a task" if self.belongs is GraphName.REQUIREMENTS else "a component's advertisement"

    @property
    def rule(self) -> str:
        """Where such a description goes: ``tasks go into graph:requirements``."""
        plural = "tasks" if self.belongs is GraphName.REQUIREMENTS else "advertisements"
        return f"{plural} go into graph:{self.belongs.value}"


_PLACED = (GraphName.ONTOLOGY, GraphName.MAP, GraphName.SERVICES, GraphName.REQUIREMENTS)
"""The graphs a lab loads its files into, of which a task and an advertisement each belong in one; a graph of
another name (a lab's own, the default graph) is not judged."""


def check_placement(store: Store, quads: Sequence[ox.Quad], source: str, prefixes: Mapping[str, str] = {}) -> None:
    """Refuse ``quads`` that put a task anywhere among :data:`_PLACED` but graph:requirements, or an
    advertisement anywhere among them but graph:services (:class:`MisplacedDescriptionError`, naming the
    first). Every way in passes here: ``cbrs load --graph`` (:func:`load_files`), the Graph Store's ``POST``
    and ``PUT`` (:mod:`cbrs.graph_store`) and so the Load a file page. A node typed both is judged an
    advertisement, as :func:`_graph_for_types` places it. graph:ontology takes either when the same quads declare
    a class or property there (a two-level task's action classes with their requirements, evening_routine.ttl):
    such a file goes into one graph, and ``cbrs load`` without ``--graph`` puts it into the ontology. The refusal
    names the description by the ``prefixes`` its text declares when cbrs's table has none for it
    (lab10:SwitchOnTheReadingLamp)."""
    judged = {g.node: g for g in _PLACED}
    rdf_type = RDF + "type"
    typed: dict[tuple[str, ox.NamedNode], list[str]] = defaultdict(list)
    declaring = {
        q.graph_name
        for q in quads
        if q.predicate.value == rdf_type and isinstance(q.object, ox.NamedNode) and q.object.value in DECLARATION_TYPES
    }
    for quad in quads:
        if quad.predicate.value != rdf_type or quad.graph_name not in judged:
            continue
        if isinstance(quad.subject, ox.NamedNode) and isinstance(quad.object, ox.NamedNode):
            assert isinstance(quad.graph_name, ox.NamedNode)
            typed[(quad.subject.value, quad.graph_name)].append(quad.object.value)
    if not typed:
        return
    advertised = _advertisement_kinds(store, quads)
    for (subject, node), kinds in typed.items():
        graph = judged[node]
        if graph is GraphName.ONTOLOGY and node in declaring:
            continue
        kind = next((k for k in kinds if k in advertised), None)
        if kind is not None:
            if graph is not GraphName.SERVICES:
                raise MisplacedDescriptionError(source, subject, kind, node.value, GraphName.SERVICES, prefixes)
        elif CBRS + "Requirement" in kinds and graph is not GraphName.REQUIREMENTS:
            requirement = CBRS + "Requirement"
            raise MisplacedDescriptionError(source, subject, requirement, node.value, GraphName.REQUIREMENTS, prefixes)


def _written(iri: str, prefixes: Mapping[str, str]) -> str:
    """``iri`` as cbrs writes it, or by a prefix of ``prefixes`` when cbrs has none for its namespace."""
    shown = written(iri)
    if shown.startswith("<"):
        for name, namespace in prefixes.items():
            local = iri[len(namespace) :]
            if name and iri.startswith(namespace) and _NCNAME.match(local):
                return f"{name}:{local}"
    return shown


def _advertisement_kinds(store: Store, quads: Sequence[ox.Quad]) -> set[str]:
    """``cbrs:Advertisement`` and every class under it, in the store or in ``quads`` (a lab's own kind)."""
    sub_class = ox.NamedNode(RDFS + "subClassOf")
    given: defaultdict[str, set[str]] = defaultdict(set)
    for quad in quads:
        if (
            quad.predicate == sub_class
            and isinstance(quad.subject, ox.NamedNode)
            and isinstance(quad.object, ox.NamedNode)
        ):
            given[quad.object.value].add(quad.subject.value)
    kinds = {CBRS + "Advertisement"}
    frontier = list(kinds)
    while frontier:
        kind = frontier.pop()
        stored = {
            q.subject.value
            for q in store.quads(None, sub_class, ox.NamedNode(kind))
            if isinstance(q.subject, ox.NamedNode)
        }
        for found in (stored | given[kind]) - kinds:
            kinds.add(found)
            frontier.append(found)
    return kinds
