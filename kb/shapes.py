"""Service descriptions checked against the SHACL shapes in ``ontologies/shapes.ttl`` before they are written.

Two checks, each naming the description, the node, the property and the value at fault:

- the shapes (pySHACL): counts, datatypes, a SEA box whose minimum exceeds its maximum, a QoS value
  that is a word rather than a number;
- the terms: every class a description names (its types, parameter types, port data types, effective
  areas, condition subjects and objects) and every property it uses must be declared somewhere, in the
  store or in what is being written. An undeclared term one or two typing slips from a declared term
  of its namespace is refused with a did-you-mean (``home:MarkerColor`` -> ``home:MarkerColour``); one
  with none is taken for a new concept and let through, since matchmaking compares undeclared concepts
  by name (the paper's testbed relies on it, and OWL-S imports report theirs as unresolved). In the
  closed vocabularies (RDF, RDFS, OWL, XSD and the cbrs core) every undeclared term is refused.

Every way in calls :func:`check_descriptions` (the registry, the loader through :func:`check_loaded`,
:meth:`KnowledgeBase.update` through :func:`checked_update`). OWL-S imports are checked against the
shapes only: their unresolved concepts are reported by the loader, not refused.
"""

from __future__ import annotations

import datetime
import difflib
import functools
import logging
import re
from collections.abc import Iterable, Iterator, Sequence
from contextlib import AbstractContextManager, contextmanager, nullcontext
from dataclasses import dataclass
from decimal import Decimal
from pathlib import Path
from typing import TYPE_CHECKING, Any

import pyoxigraph as ox

from cbrs.kb import derived_prefixes
from cbrs.kb.errors import InvalidDescriptionError
from cbrs.kb.namespaces import GENID, OWL, RDF, RDFS, XSD, GraphName, active_store_names, shorten, store_names
from cbrs.kb.queries import QueryLibrary
from cbrs.kb.resources import ontology_dir, query_dir
from cbrs.kb.skolem import closure, is_skolem, quads_by_subject
from cbrs.kb.store import Store
from cbrs.kb.vocab import CBRS

if TYPE_CHECKING:
    from cbrs.kb.loader import LoadReport

SH = "http://www.w3.org/ns/shacl#"
SHAPES_FILE = "shapes.ttl"

# Where a description names a class (or an individual, or a property used as a concept).
_TERM_POSITIONS = frozenset(
    {
        RDF + "type",
        CBRS.parameterType,
        CBRS.dataType,
        CBRS.effectiveArea,
        CBRS.realizesAction,
        CBRS.forTask,
        CBRS.conditionSubject,
        CBRS.conditionObject,
    }
)
_PROPERTY_POSITION = CBRS.conditionPredicate  # a condition's predicate is a property


@dataclass(frozen=True)
class ShapeProblem:
    """One thing wrong with one description."""

    description: str
    message: str
    focus: str | None = None  # the node at fault when it is not the description itself
    path: str | None = None
    value: str | None = None
    suggestion: str | None = None

    def text(self) -> str:
        path = shorten(self.path) if self.path else None
        if self.value is not None:
            got = f"; got {path} {self.value}" if path else f"; got {self.value}"
        else:
            got = f" (as {path})" if path and path not in self.message else ""
        hint = f"; did you mean {self.suggestion}?" if self.suggestion else ""
        return f"{self.message}{got}{hint}"


class DescriptionShapeError(InvalidDescriptionError):
    """A description breaks a shape or names an undeclared term; nothing was written."""

    http_status = 400

    def __init__(self, problems: Sequence[ShapeProblem]) -> None:
        self.shape_problems = list(problems)
        first = self.shape_problems[0].description
        super().__init__(first, [p.text() for p in self.shape_problems if p.description == first])
        others = {p.description for p in self.shape_problems} - {first}
        if others:
            count = len(others)
            self.args = (f"{self.args[0]} (and {count} other description{'s' if count > 1 else ''} with problems)",)

    def __str__(self) -> str:
        return str(self.args[0])


# -- the ways in -----------------------------------------------------------------------------------


class _DerivedNames:
    """The prefixes derived for the store's namespaces and the input's (:mod:`cbrs.kb.derived_prefixes`),
    read when a message first names an IRI no declared prefix covers: a problem names ``lab6:TidyShelf``
    as ``cbrs`` prints it and the pages show it, not the whole IRI, wherever the library is called from
    (a Graph Store request, Python); a caller that set names of its own (the CLI) keeps them."""

    def __init__(self, store: Store, quads: Iterable[ox.Quad]) -> None:
        self._store = store
        self._quads = quads
        self._table: dict[str, str] | None = None

    @property
    def prefixes(self) -> dict[str, str]:
        if self._table is None:
            found = derived_prefixes.namespaces_in(self._store)
            for quad in self._quads:
                for term in (quad.subject, quad.predicate, quad.object):
                    if isinstance(term, ox.NamedNode) and (ns := derived_prefixes.namespace(term.value)) is not None:
                        found.add(ns)
            self._table = derived_prefixes.derive(found)
        return self._table

    def shorten(self, iri: str) -> str | None:
        ns = derived_prefixes.namespace(iri)
        prefix = next((p for p, n in self.prefixes.items() if n == ns), None) if ns is not None else None
        local = iri[len(ns) :] if ns is not None else ""
        if prefix is None or not local or not all(ch.isalnum() or ch in "_-." for ch in local):
            return None
        return f"{prefix}:{local}"

    def namespace_of(self, prefix: str) -> str | None:
        return self.prefixes.get(prefix)


def _names(store: Store, quads: Iterable[ox.Quad]) -> AbstractContextManager[None]:
    """Within the block, problems name IRIs by the derived prefixes (:class:`_DerivedNames`), unless the
    caller set names of its own."""
    return nullcontext() if active_store_names() is not None else store_names(_DerivedNames(store, quads))


def check_descriptions(store: Store, quads: Iterable[ox.Quad], terms: bool = True) -> None:
    """Raise :class:`DescriptionShapeError` when a description among ``quads`` breaks a shape or (with
    ``terms``) names a class or property declared neither in ``store`` nor in ``quads``."""
    incoming = list(quads)
    closures = _closures(incoming)
    if not closures:
        return
    with _names(store, incoming):
        problems = _shape_problems(closures)
        if terms:
            problems += _term_problems(store, closures, incoming)
    if problems:
        raise DescriptionShapeError(problems)


def check_loaded(store: Store, report: LoadReport) -> None:
    """The loader's check before it writes: RDF files in full, OWL-S conversions against the shapes only.
    A description the store holds already is checked as it will be after the load, its stored triples
    and the new ones together: a load adds, so a changed file loaded again would give it a second OWLS
    model (the blank nodes of a changed file get other names) unless refused."""
    owls = [q for item in report.files if item.owls is not None for q in item.quads]
    plain = [q for item in (*report.files, *report.imports) if item.owls is None for q in item.quads]
    context = plain + owls
    stored_plain = _stored(store, plain)  # an OWL-S service the store holds already: the loader refuses it sooner
    try:
        if _closures(plain):
            _check_with_context(store, _as_stored(plain) + stored_plain if stored_plain else plain, context)
        check_descriptions(store, owls, terms=False)
    except DescriptionShapeError as error:
        if error.iri in {q.subject.value for q in stored_plain if isinstance(q.subject, ox.NamedNode)}:
            error.args = (
                f"{error.args[0]}; <{error.iri}> is in the store already and a load adds to it: replace an "
                "advertisement with cbrs register --update (kb.registry.update), or remove the description first "
                "(cbrs deregister IRI, which removes a requirement too) and load the file again",
            )
        _name_the_source(error, report)
        raise


def _stored(store: Store, quads: list[ox.Quad]) -> list[ox.Quad]:
    """The stored quads of the descriptions ``quads`` add to, in the graphs they add to (none when they
    are all new: one lookup). A copy in another graph (a task file loaded into the map and the
    requirements) is another description's business."""
    closures = _closures(quads)
    if not closures:
        return []
    model = ox.NamedNode(CBRS.hasOWLSModel)
    stored = {
        (q.subject.value, q.graph_name) for q in store.quads(None, model, None) if isinstance(q.subject, ox.NamedNode)
    }
    found: list[ox.Quad] = []
    for root, own in sorted(closures.items()):
        for graph in sorted({q.graph_name for q in own if (root, q.graph_name) in stored}, key=str):
            named = graph if isinstance(graph, ox.NamedNode) else None

            def quads_of(node: Any, graph: ox.NamedNode | None = named) -> list[ox.Quad]:
                return list(store.quads(node, None, None, graph))

            found += closure([ox.NamedNode(root)], quads_of, _is_inner, parts=True)
    return found


def _as_stored(quads: list[ox.Quad]) -> list[ox.Quad]:
    """``quads`` with their literals in the form the store keeps (``"0.0"^^xsd:decimal`` is stored as
    ``"0"``): beside stored quads, the same value in two spellings would count as two values."""
    memory = ox.Store()
    memory.extend(quads)
    return list(memory)


def _name_the_source(error: InvalidDescriptionError, report: LoadReport) -> None:
    """Put the name of the file the description came from before the error's message."""
    node = ox.NamedNode(error.iri)  # a description, or a node of one (a parameter) that may have no triples
    items = [*report.files, *report.imports]
    sources = [item.source for item in items if any(node in (q.subject, q.object) for q in item.quads)]
    if not sources and len(items) == 1:
        sources = [items[0].source]
    if sources:
        line = line_of(sources[0], error.iri)
        error.args = (f"{sources[0]}{f':{line}' if line else ''}: {error.args[0]}",)


_PREFIX_LINE = re.compile(r"""(?:@prefix|PREFIX)\s+([\w.-]*):\s*<([^>]*)>""", re.IGNORECASE)
_XMLNS = re.compile(r"""xmlns:([\w.-]+)\s*=\s*["']([^"']*)["']""")
LOCATE_BYTES = 8 * 1024 * 1024
"""Files up to this size are searched for the line of a refused description; a larger one is named alone."""


def line_of(source: str, iri: str) -> int | None:
    """The line of the file ``source`` where ``iri`` is first written as a subject (at the start of a
    line, as Turtle, N-Triples, RDF/XML and JSON-LD put one), else first written at all; None when the
    file cannot be read or never spells it (an OWL-S service's description is made, not written)."""
    path = Path(source)
    try:
        if not path.is_file() or path.stat().st_size > LOCATE_BYTES:
            return None
        text = path.read_text(encoding="utf-8", errors="replace")
    except OSError:
        return None
    cut = max(iri.rfind("#"), iri.rfind("/"))
    namespace, local = iri[: cut + 1], iri[cut + 1 :]
    spellings = [re.escape(f"<{iri}>"), re.escape(f'"{iri}"')]
    if local:
        prefixes = {p for p, ns in (*_PREFIX_LINE.findall(text), *_XMLNS.findall(text)) if ns == namespace}
        spellings += [rf"(?<![\w.:-]){re.escape(p)}:{re.escape(local)}(?![\w.-])" for p in prefixes]
        spellings += [rf'rdf:(?:about|ID)\s*=\s*["\']#?{re.escape(local)}["\']']
    mention = re.compile("|".join(spellings))
    first = None
    for number, line in enumerate(text.splitlines(), start=1):
        found = mention.search(line)
        if found is None:
            continue
        before = line[: found.start()].strip()
        if before in ("", "<rdf:Description", "{", '{"@id":', '"@id":') or before.endswith(
            ("<rdf:Description", '"@id":')
        ):
            return number
        first = first or number
    return first


def _check_with_context(store: Store, quads: list[ox.Quad], context: list[ox.Quad]) -> None:
    closures = _closures(quads)
    with _names(store, context):
        problems = _shape_problems(closures) + _term_problems(store, closures, context)
    if problems:
        raise DescriptionShapeError(problems)


_DESCRIBED = (GraphName.SERVICES.node, GraphName.REQUIREMENTS.node)
CHECKED_GRAPHS: tuple[ox.NamedNode | ox.DefaultGraph, ...] = (*_DESCRIBED, ox.DefaultGraph())
"""The graphs :func:`checked_update` reads: an update that writes none of them needs no check. The default
graph too: an update that names no graph writes its descriptions there, and a task is found in any graph
(a ``GRAPH`` block left out ran a requirement nothing had checked: docs/tasks.md, "A seventh round"). cbrs's
own writes name their graphs (a load, the registry, the belief), so only an update puts anything there."""


@contextmanager
def checked_update(store: Store, whole: bool = False) -> Iterator[None]:
    """Run the enclosed update, then check the descriptions it changed in the services and requirements
    graphs and the default graph; when one is broken, undo the update's changes to those graphs and raise.
    With ``whole``, the whole store is kept beforehand and a refused update is undone everywhere (the caller
    cannot know what else it wrote: :func:`may_write_descriptions`)."""
    graphs = CHECKED_GRAPHS
    everything = set(store.quads()) if whole else None
    if everything is not None:  # the two graphs are in it: no second read
        before = {q for q in everything if q.graph_name in graphs}
    else:
        before = {q for graph in graphs for q in store.quads(graph=graph)}
    yield
    after = {q for graph in graphs for q in store.quads(graph=graph)}
    added, removed = after - before, before - after
    if not added and not removed:
        return
    closures = _closures(after)
    changed = {q.subject for q in (*added, *removed)}
    touched = {root: quads for root, quads in closures.items() if changed & {q.subject for q in quads}}
    with _names(store, added):
        problems = _shape_problems(touched) + _term_problems(store, touched, [])
    if problems:
        if everything is not None:
            now = set(store.quads())
            added, removed = now - everything, everything - now
        _undo(store, added, removed)
        raise DescriptionShapeError(problems)


_MAY_REACH = re.compile(
    "|".join(re.escape(graph.value.rsplit("/", 1)[-1]) for graph in _DESCRIBED)  # their names' last words
    + r"|prefix|base|\\u|GRAPH(?:\s|#[^\n]*\n)*[?$]|\b(?:ALL|NAMED|DEFAULT)\b"
    + r"|\bcbrs:|/cbrs/core#",  # a description's own terms, which it may write into the default graph
    re.IGNORECASE,
)


def may_write_descriptions(text: str) -> bool:
    """Whether the SPARQL update ``text`` might write graph:services, graph:requirements or a description
    into the default graph: it names one of them (or a word of theirs), declares a prefix or a base that
    could spell them, has an escape, a variable graph, CLEAR/DROP ALL/NAMED or DEFAULT, or a term of the
    cbrs core (a description's, by the ``cbrs:`` prefix every update is given, or spelt out). Deliberately
    loose: it decides whether :func:`checked_update` keeps the whole store to undo a refused update
    everywhere, and whether an update that is not data is checked at all (KnowledgeBase: an update it says
    cannot reach them, and no LOAD, is not)."""
    return _MAY_REACH.search(text) is not None


def _undo(store: Store, added: set[ox.Quad], removed: set[ox.Quad]) -> None:
    if not any(isinstance(t, ox.BlankNode) for q in (*added, *removed) for t in (q.subject, q.object)):
        store.replace(added, removed)  # one transaction
        return
    # A data block cannot name a blank node: empty the graphs the update touched, then restore them.
    graphs = {q.graph_name for q in (*added, *removed)}
    kept = [q for q in store.quads() if q.graph_name in graphs and q not in added]
    for graph in graphs:
        if isinstance(graph, ox.NamedNode):
            store.clear_graph(graph)
    store.add([*kept, *removed])


# -- descriptions and their nodes ------------------------------------------------------------------


def _closures(quads: Iterable[ox.Quad]) -> dict[str, list[ox.Quad]]:
    """Each description (a subject with an OWLS model) with its own quads and those of the nodes hanging
    off it: blank or skolemised, and its parts (models, parameters, conditions, ports) given IRIs of their
    own, which an update must write (it may not insert blank nodes) and the shapes must see."""
    quads = list(quads)
    roots = {
        quad.subject
        for quad in quads
        if quad.predicate.value == CBRS.hasOWLSModel
        and isinstance(quad.subject, ox.NamedNode)
        and not _is_inner(quad.subject)
    }
    if not roots:
        return {}  # a file of plain data: no index of its quads to build (2.6 s for 600,000)
    quads_of = quads_by_subject(quads)
    return {
        root.value: closure([root], quads_of, _is_inner, parts=True)
        for root in sorted(roots, key=lambda node: node.value)
    }


def _iri(term: Any) -> str:
    return term.value if isinstance(term, ox.NamedNode) else ""


def _is_inner(term: object) -> bool:
    return isinstance(term, ox.BlankNode) or is_skolem(term)


# -- the SHACL shapes ------------------------------------------------------------------------------


@functools.cache
def _shapes_graph() -> Any:
    """The shapes file as pySHACL reads it, an rdflib graph, parsed once a process. Oxigraph parses it
    in a quarter of rdflib's time (48 -> 13 ms, in every command that checks a description)."""
    parser = ox.parse(path=ontology_dir() / SHAPES_FILE, format=ox.RdfFormat.TURTLE)
    graph = _rdflib_graph(ox.Triple(q.subject, q.predicate, q.object) for q in parser)
    for prefix, namespace in parser.prefixes.items():  # known once the file is read
        graph.bind(prefix, namespace)
    return graph


def _shape_problems(closures: dict[str, list[ox.Quad]]) -> list[ShapeProblem]:
    if not closures:
        return []
    import rdflib
    from pyshacl import validate

    _quiet_ill_typed_literals()
    owner = {q.subject: root for root, quads in closures.items() for q in quads}
    triples = [ox.Triple(q.subject, q.predicate, q.object) for quads in closures.values() for q in quads]
    data = _rdflib_graph(triples)
    conforms, results, _ = validate(data, shacl_graph=_shapes_for(data), inference="none", allow_warnings=True)
    if conforms:
        return []
    problems = []
    sh = rdflib.Namespace(SH)
    reports = list(results.subjects(rdflib.RDF.type, sh.ValidationReport))
    for result in (r for report in reports for r in results.objects(report, sh.result)):  # not sh:detail
        focus = results.value(result, sh.focusNode)
        path = results.value(result, sh.resultPath)
        value = results.value(result, sh.value)
        message = results.value(result, sh.resultMessage)
        component = results.value(result, sh.sourceConstraintComponent)
        if component == sh.LessThanOrEqualsConstraintComponent and not _is_number(value):
            continue  # a bound that is no number is reported as such; "reversed" would be a second, wrong reason
        if isinstance(value, rdflib.URIRef) and _is_inner(ox.NamedNode(str(value))):
            value = None  # the node itself (a model the loader named): "got genid:..." says nothing to its author
        focus_term = _ox_term(focus)
        root = owner.get(focus_term, focus_term.value if focus_term is not None else "")
        problems.append(
            ShapeProblem(
                description=str(root),
                message=str(message) if message is not None else "breaks a shape",
                focus=None if focus_term is None or str(root) == focus_term.value else _node_text(focus_term),
                path=str(path) if isinstance(path, rdflib.URIRef) else None,
                value=_literal_text(value),
            )
        )
    return sorted(set(problems), key=lambda p: (p.description, p.path or "", p.message))


@dataclass(frozen=True)
class _DatatypeChoice:
    """A node shape whose one test is an ``sh:or`` of bare ``sh:datatype`` branches (shape:Number's
    numeric types, shape:Text's string types), and the properties whose objects include every value it
    is given (through ``sh:node`` from property shapes with those paths, directly or by way of other
    node shapes such as shape:Name)."""

    shape: Any
    datatypes: frozenset[str]
    properties: frozenset[Any]


@functools.cache
def _datatype_choices() -> tuple[_DatatypeChoice, ...]:
    """The datatype choices of the shapes file that a check may settle before pySHACL runs
    (:func:`_shapes_for`). A shape reached in any other way (a target of its own, an ``sh:or`` member,
    a path other than a property or a choice of properties) is left to pySHACL."""
    import rdflib

    graph = _shapes_graph()
    either = rdflib.URIRef(SH + "or")
    choices = []
    for shape in sorted(set(graph.subjects(either, None)), key=str):
        branches = list(graph.objects(shape, either))
        datatypes = _bare_datatypes(graph, branches[0]) if len(branches) == 1 else None
        properties = _reached_through(graph, shape, frozenset())
        if datatypes and properties is not None:
            choices.append(_DatatypeChoice(shape, datatypes, properties))
    return tuple(choices)


def _bare_datatypes(graph: Any, branches: Any) -> frozenset[str] | None:
    """The datatypes of an ``sh:or`` list each of whose members is a blank node saying ``sh:datatype``
    and nothing else; None for any other list."""
    import rdflib

    datatypes = set()
    for member in graph.items(branches):
        said = list(graph.predicate_objects(member))
        if not isinstance(member, rdflib.BNode) or len(said) != 1 or said[0][0] != rdflib.URIRef(SH + "datatype"):
            return None
        datatypes.add(str(said[0][1]))
    return frozenset(datatypes) or None


_TARGETS = ("target", "targetNode", "targetClass", "targetSubjectsOf", "targetObjectsOf")


def _reached_through(graph: Any, shape: Any, seen: frozenset[Any]) -> frozenset[Any] | None:
    """The properties whose objects include every value ``shape`` is checked on, or None when it is
    reached otherwise than by ``sh:node`` (or has targets of its own, or is a class: an implicit target)."""
    import rdflib

    if shape in seen or any(graph.value(shape, rdflib.URIRef(SH + t)) is not None for t in _TARGETS):
        return None
    if any((shape, rdflib.RDF.type, kind) in graph for kind in (rdflib.RDFS.Class, rdflib.OWL.Class)):
        return None
    properties: set[Any] = set()
    for referrer, link in graph.subject_predicates(shape):
        if link != rdflib.URIRef(SH + "node"):
            return None
        path = graph.value(referrer, rdflib.URIRef(SH + "path"))
        found = _reached_through(graph, referrer, seen | {shape}) if path is None else _path_properties(graph, path)
        if found is None:
            return None
        properties |= found
    return frozenset(properties)


def _path_properties(graph: Any, path: Any) -> frozenset[Any] | None:
    """The properties of a path that is one property or an ``sh:alternativePath`` of properties; else None."""
    import rdflib

    if isinstance(path, rdflib.URIRef):
        return frozenset({path})
    said = list(graph.predicate_objects(path))
    if len(said) != 1 or said[0][0] != rdflib.URIRef(SH + "alternativePath"):
        return None
    properties = list(graph.items(said[0][1]))
    return frozenset(properties) if properties and all(isinstance(p, rdflib.URIRef) for p in properties) else None


def _shapes_for(data: Any) -> Any:
    """The shapes to check ``data`` against: the shapes file, less each datatype choice that every value
    it could be given in ``data`` already passes. pySHACL tries every branch of an ``sh:or`` and builds
    a report for each one that fails, to throw it away: 15 for every number against shape:Number's 16
    types, 70% of the paper testbed's check. A choice is left out only when no value of its properties
    could fail it, so no verdict changes; with one value that might (a word, "abc"^^xsd:double, an
    IRI), that choice is checked by pySHACL for the whole input, as before."""
    settled = frozenset(
        choice.shape
        for choice in _datatype_choices()
        if all(_has_datatype(value, choice.datatypes) for p in choice.properties for value in data.objects(None, p))
    )
    return _shapes_without(settled) if settled else _shapes_graph()


# The Python value rdflib gives a well-typed literal of a datatype that SHACL's sh:datatype test of
# pySHACL also checks the value of; for any other datatype, not being ill-typed is enough.
_PYTHON_VALUES: dict[str, type | tuple[type, ...]] = {
    XSD + "string": str,
    RDF + "langString": str,
    XSD + "integer": int,
    XSD + "float": float,
    XSD + "decimal": Decimal,
    XSD + "boolean": bool,
    XSD + "date": datetime.date,
    XSD + "time": datetime.time,
    XSD + "dateTime": datetime.datetime,
}


def _has_datatype(value: Any, datatypes: frozenset[str]) -> bool:
    """Whether ``value`` passes ``sh:datatype`` for one of ``datatypes``: a literal of that datatype, not
    ill-typed ("abc"^^xsd:double is no xsd:double); a literal without a tag is an xsd:string, one with a
    language tag an rdf:langString. Saying no when unsure costs time, not a verdict: pySHACL decides."""
    import rdflib

    if not isinstance(value, rdflib.Literal) or value.ill_typed:
        return False
    datatype = RDF + "langString" if value.language else str(value.datatype or XSD + "string")
    return datatype in datatypes and isinstance(value.value, _PYTHON_VALUES.get(datatype, object))


@functools.cache
def _shapes_without(settled: frozenset[Any]) -> Any:
    """The shapes graph without the ``sh:or`` of the ``settled`` choices, and without the ``sh:node``
    links to a shape then left with no test (shape:Text): an empty shape passes every value."""
    import rdflib

    graph = _shapes_graph()
    either = rdflib.URIRef(SH + "or")
    dropped = set()
    for shape in settled:
        for branches in graph.objects(shape, either):
            dropped.add((shape, either, branches))
            cells = [branches]
            while cells[-1] != rdflib.RDF.nil:
                cells.append(graph.value(cells[-1], rdflib.RDF.rest))
            for cell in cells[:-1]:
                dropped |= set(graph.triples((cell, None, None)))
                dropped |= set(graph.triples((graph.value(cell, rdflib.RDF.first), None, None)))
    untested = {rdflib.RDF.type, rdflib.RDFS.comment, rdflib.RDFS.label}
    for shape in settled:
        if {p for p, _ in graph.predicate_objects(shape)} <= untested | {either}:
            dropped |= set(graph.triples((None, rdflib.URIRef(SH + "node"), shape)))
    lighter = rdflib.Graph()
    for prefix, namespace in graph.namespaces():
        lighter.bind(prefix, namespace)
    for triple in graph:
        if triple not in dropped:
            lighter.add(triple)
    return lighter


def _rdflib_graph(triples: Iterable[ox.Triple]) -> Any:
    """The triples as an rdflib graph for pySHACL, term by term: rdflib's N-Triples parser takes time
    quadratic in a line's length (a 5 MB rdfs:comment took 95 s to check), building the terms does not."""
    import rdflib

    def term(node: Any) -> Any:
        if isinstance(node, ox.NamedNode):
            return rdflib.URIRef(node.value)
        if isinstance(node, ox.BlankNode):
            return rdflib.BNode(node.value)
        if isinstance(node, ox.Literal):
            if node.language:
                return rdflib.Literal(node.value, lang=node.language)
            if node.datatype.value == XSD + "string":
                return rdflib.Literal(node.value)  # as rdflib's parsers read "text"
            return rdflib.Literal(node.value, datatype=rdflib.URIRef(node.datatype.value))
        raise TypeError(f"no rdflib term for {node!r}")  # an RDF-star triple: the parsers cbrs uses give none

    graph = rdflib.Graph()
    for triple in triples:
        graph.add((term(triple.subject), term(triple.predicate), term(triple.object)))
    return graph


def _ox_term(term: Any) -> Any:
    import rdflib

    if isinstance(term, rdflib.URIRef):
        return ox.NamedNode(str(term))
    if isinstance(term, rdflib.BNode):
        return ox.BlankNode(str(term))
    return None


def _node_text(term: Any) -> str:
    return "a blank node" if isinstance(term, ox.BlankNode) else shorten(term.value)


def _quoted(text: str) -> str:
    """A string as Turtle writes it, escapes and all: an error stays on one line and shows the quotes."""
    escaped = text.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n").replace("\r", "\\r")
    return f'"{escaped}"'


def _is_number(value: Any) -> bool:
    import rdflib

    return isinstance(value, rdflib.Literal) and not value.ill_typed and isinstance(value.value, int | float | Decimal)


@functools.cache
def _quiet_ill_typed_literals() -> None:
    """rdflib logs a warning with a traceback for every ill-typed literal it reads ("abc"^^xsd:double);
    the problem is reported as a shape problem instead, so the log would only print a traceback at the user."""
    logging.getLogger("rdflib.term").addFilter(
        lambda record: not record.getMessage().startswith("Failed to convert Literal lexical form")
    )


def _literal_text(value: Any) -> str | None:
    import rdflib

    if value is None:
        return None
    if isinstance(value, rdflib.Literal):
        datatype = str(value.datatype) if value.datatype else None
        if value.ill_typed:
            return f"{_quoted(str(value))}^^{shorten(datatype or '')} (not a valid {shorten(datatype or '')})"
        if datatype in (XSD + "decimal", XSD + "integer", XSD + "double", XSD + "float"):
            return str(value)
        typed = f"^^{shorten(datatype)}" if datatype and datatype != XSD + "string" else ""
        return _quoted(str(value)) + typed + (f"@{value.language}" if value.language else "")
    if isinstance(value, rdflib.BNode):
        return "a blank node"
    return shorten(str(value))


# -- declared terms --------------------------------------------------------------------------------


def _term_problems(store: Store, closures: dict[str, list[ox.Quad]], context: Sequence[ox.Quad]) -> list[ShapeProblem]:
    """Classes and properties the descriptions use that nothing declares, each with a near spelling."""
    # (description, the property the term is a value of, the term, whether it is used as a property)
    uses: list[tuple[str, str | None, ox.NamedNode, bool]] = []
    for root, quads in closures.items():
        for quad in quads:
            uses.append((root, None, quad.predicate, True))
            if not isinstance(quad.object, ox.NamedNode) or _is_inner(quad.object):
                continue
            if quad.predicate.value in _TERM_POSITIONS:
                uses.append((root, quad.predicate.value, quad.object, False))
            elif quad.predicate.value == _PROPERTY_POSITION:
                uses.append((root, quad.predicate.value, quad.object, True))
    described = {q for quads in closures.values() for q in quads}
    declared_here = {_iri(q.subject) for q in (*context, *described)}
    closed_namespaces, closed_terms = _w3c_terms()
    unknown = {term.value for _, _, term, _ in uses} - declared_here - closed_terms
    unknown -= _declared_in_store(store, unknown)
    candidates: dict[str, list[str]] = {}
    problems = []
    for root, position, term, is_property in uses:
        if term.value not in unknown or term.value.startswith(GENID):
            continue
        namespace = _namespace(term.value)
        if namespace not in candidates:
            candidates[namespace] = _candidates(store, namespace, declared_here)
        near = nearest_term(term.value, candidates[namespace])
        if near is None or not _misspelt(term.value, near):
            near = _slip_of(term.value, candidates[namespace]) or near
        if namespace not in closed_namespaces and (near is None or not _misspelt(term.value, near)):
            # A new concept, not a misspelt one: matchmaking compares undeclared concepts by name.
            continue
        problems.append(
            ShapeProblem(
                description=root,
                message=f"{'the property ' if is_property else ''}{shorten(term.value)} is declared nowhere "
                "in the store or in this input",
                path=position,
                suggestion=shorten(near) if near else None,
            )
        )
    problems += _individuals(store, closures, context)
    return sorted(set(problems), key=lambda p: (p.description, p.message))


_CLASS_POSITIONS = frozenset({CBRS.parameterType, CBRS.conditionSubject, CBRS.conditionObject})
_CLASS_MARKS = frozenset({OWL + "Class", RDFS + "Class"})
_NO_CLASS = frozenset({OWL + "NamedIndividual", OWL + "Thing"})


def _individuals(store: Store, closures: dict[str, list[ox.Quad]], context: Sequence[ox.Quad]) -> list[ShapeProblem]:
    """A component's input, output or condition that names a thing of the map where a class belongs (an
    effect (lab10:ReadingLamp1, home:hasStatus, home:SwitchedOn) for the lamp's class): registered, the
    component met no task's goal about the class and no answer named it (docs/tasks.md, "A tenth round").
    A task's are named when it is planned (actions.unmet), as the fourth round's goal naming the trolley."""
    problems = []
    for root, quads in closures.items():
        if any(q.predicate.value == RDF + "type" and q.object == ox.NamedNode(CBRS.Requirement) for q in quads):
            continue
        for quad in quads:
            if quad.predicate.value not in _CLASS_POSITIONS or not isinstance(quad.object, ox.NamedNode):
                continue
            classes = _individual_of(store, context, quad.object)
            if not classes:
                continue
            problems.append(
                ShapeProblem(
                    description=root,
                    message=f"{shorten(quad.object.value)} is a thing of the map (an individual of "
                    f"{' and '.join(map(shorten, classes))}), not a class: a component's inputs, outputs, "
                    "preconditions and effects name classes, and a run finds the things of those classes",
                    path=quad.predicate.value,
                    suggestion=shorten(classes[0]) if len(classes) == 1 else None,
                )
            )
    return problems


def _individual_of(store: Store, context: Sequence[ox.Quad], term: ox.NamedNode) -> list[str]:
    """The classes ``term`` is stated an individual of, in the store or ``context``; none for a class."""
    here = [q for q in context if q.subject == term]
    stated = [
        *here,
        *store.quads(term, ox.NamedNode(RDF + "type")),
        *store.quads(term, ox.NamedNode(RDFS + "subClassOf")),
    ]
    types = {q.object.value for q in stated if q.predicate.value == RDF + "type" and isinstance(q.object, ox.NamedNode)}
    if types & _CLASS_MARKS or any(q.predicate.value == RDFS + "subClassOf" for q in stated):
        return []
    return sorted(types - _NO_CLASS)


def _namespace(iri: str) -> str:
    for separator in ("#", "/"):
        if separator in iri:
            return iri.rsplit(separator, 1)[0] + separator
    return iri


def _declared_in_store(store: Store, iris: set[str]) -> set[str]:
    if not iris:
        return set()
    return {iri for iri in iris if next(iter(store.quads(ox.NamedNode(iri))), None) is not None}


def _candidates(store: Store, namespace: str, declared_here: set[str]) -> list[str]:
    w3c_namespaces, w3c_terms = _w3c_terms()
    if namespace in w3c_namespaces:
        return sorted(t for t in w3c_terms if t.startswith(namespace))
    rows = _queries().select(store, "namespace_terms", {"namespace": namespace})
    return sorted({row["term"].value for row in rows} | {t for t in declared_here if t.startswith(namespace)})


def did_you_mean(store: Store, iri: str, declared_here: Iterable[str] = ()) -> str | None:
    """The declared term of ``iri``'s namespace (in ``store`` or ``declared_here``) it reads as a slip of,
    else the nearest by spelling, else None: the did-you-mean of the description checks, for other checks."""
    candidates = _candidates(store, _namespace(iri), set(declared_here))
    near = nearest_term(iri, candidates)
    if near is None or not _misspelt(iri, near):
        near = _slip_of(iri, candidates) or near
    return near


def nearest_term(iri: str, candidates: Iterable[str], cutoff: float = 0.75) -> str | None:
    """The candidate of ``iri``'s namespace whose local name is closest to ``iri``'s, if any is close
    (``difflib``'s ratio at least ``cutoff``, case aside): the did-you-mean of a misspelt term."""
    namespace = _namespace(iri)
    local = iri[len(namespace) :]
    names = {c[len(namespace) :].lower(): c for c in candidates if c.startswith(namespace)}
    close = difflib.get_close_matches(local.lower(), list(names), n=1, cutoff=cutoff)
    return names[close[0]] if close else None


def _misspelt(iri: str, near: str) -> bool:
    """Whether ``iri`` reads as a slip of ``near`` (two typing slips at most, case aside) rather than
    another name: MarkerColor for MarkerColour, but not IndoorTemperature for OutdoorTemperature."""
    import jellyfish

    a, b = _local(iri).lower(), _local(near).lower()
    return jellyfish.damerau_levenshtein_distance(a, b) <= min(2, max(1, len(b) // 4))


def _slip_of(iri: str, candidates: Iterable[str]) -> str | None:
    """The candidate ``iri`` is a slip of by :func:`_misspelt` (the fewest edits, then the first by name),
    where :func:`nearest_term`'s ratio misses it: two letters swapped in a short name (``home:Pne`` for
    ``home:Pen`` has a ratio of 0.67, below the cutoff, and an edit distance of 1)."""
    import jellyfish

    namespace, local = _namespace(iri), _local(iri).lower()
    near = (c for c in candidates if c.startswith(namespace) and c != iri and abs(len(_local(c)) - len(local)) <= 2)
    slips = [c for c in near if _misspelt(iri, c)]  # a slip changes the length by two letters at most
    return min(slips, key=lambda c: (jellyfish.damerau_levenshtein_distance(local, _local(c).lower()), c), default=None)


def _local(iri: str) -> str:
    return iri[len(_namespace(iri)) :]


@functools.cache
def _w3c_terms() -> tuple[frozenset[str], frozenset[str]]:
    """The closed RDF, RDFS, OWL and XSD vocabularies and the cbrs core, known without a declaration in the store."""
    from rdflib.namespace import OWL as R_OWL
    from rdflib.namespace import RDF as R_RDF
    from rdflib.namespace import RDFS as R_RDFS
    from rdflib.namespace import XSD as R_XSD

    spaces = {RDF: R_RDF, RDFS: R_RDFS, OWL: R_OWL, XSD: R_XSD}
    terms = {ns + name for ns, vocabulary in spaces.items() for name in vocabulary.__annotations__}
    core = {value for name, value in vars(CBRS).items() if name != "NS" and isinstance(value, str)}
    return frozenset({*spaces, CBRS.NS}), frozenset(terms | core)


@functools.cache
def _queries() -> QueryLibrary:
    return QueryLibrary(query_dir())
