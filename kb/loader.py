"""Read RDF files into quads and load them all-or-nothing.

Every file of a load is parsed before anything is written; one that fails to parse aborts the
whole load with its name and line, and the store is left as it was.

OWL-S files are converted into cbrs descriptions (:mod:`kb.owls`) on the way in, and with a
:class:`~kb.catalog.Catalogue` the ontologies a load imports are parsed from local files and added in
the same transaction.

Blank nodes are skolemised (RDF 1.1, section 3.5) to IRIs under ``GENID`` that are derived from
the canonical form of the file (RDFC-1.0): loading the same file twice adds nothing the second
time (and writes nothing: a load writes only the triples the store lacks), and every stored node can be
named in an update.

A large plain data file (``BULK_BYTES`` or more of N-Triples or Turtle, loaded alone, without a
catalogue, into a graph that holds nothing yet) takes a faster way that keeps the same promise: a
first pass parses all of it and checks that it needs none of the processing above (no blank nodes, no
OWL-S, no service descriptions); only then does Oxigraph's bulk loader write it, straight into the
store's files without a transaction log. That writer is not one transaction, so if it fails (a full
disk) the graph, empty before, is dropped again. A file that needs more takes the full path.
"""

from __future__ import annotations

import codecs
import hashlib
import re
import subprocess
import sys
import xml.parsers.expat
from collections import defaultdict, deque
from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import pyoxigraph as ox

from cbrs.kb.catalog import Catalogue, Unresolved, is_built_in, ontology_iri
from cbrs.kb.errors import (
    DescribedElsewhereError,
    PartCycleError,
    RdfParseError,
    UnknownFormatError,
    UnknownGraphError,
)
from cbrs.kb.namespaces import CBRS, DUL, GENID, OWL, RDF, RDFS, GraphName, shorten
from cbrs.kb.owl_syntaxes import check_rdf
from cbrs.kb.owls import (
    Conversion,
    Role,
    Vocabulary,
    convert,
    is_owls,
    is_owls_ontology,
    owls_key,
    referenced_ontologies,
)
from cbrs.kb.placement import DECLARATION_TYPES, check_placement
from cbrs.kb.placement import MisplacedDescriptionError as MisplacedDescriptionError  # where it lived: re-exported
from cbrs.kb.shapes import check_loaded
from cbrs.kb.store import EmbeddedStore, Store
from cbrs.kb.superclasses import check_change, check_superclasses
from cbrs.kb.xml_limits import check_entities

FORMATS_BY_EXTENSION: dict[str, ox.RdfFormat] = {
    ".ttl": ox.RdfFormat.TURTLE,
    ".turtle": ox.RdfFormat.TURTLE,
    ".nt": ox.RdfFormat.N_TRIPLES,
    ".nq": ox.RdfFormat.N_QUADS,
    ".trig": ox.RdfFormat.TRIG,
    ".n3": ox.RdfFormat.N3,
    ".jsonld": ox.RdfFormat.JSON_LD,
    ".json": ox.RdfFormat.JSON_LD,
    ".rdf": ox.RdfFormat.RDF_XML,
    ".xml": ox.RdfFormat.RDF_XML,
    ".owl": ox.RdfFormat.RDF_XML,  # OWL files are RDF/XML unless their content says Turtle
    ".owls": ox.RdfFormat.RDF_XML,
}

_XML_ENCODING = re.compile(rb"""^(<\?xml[^>]*?encoding\s*=\s*["'])([A-Za-z0-9._-]+)(["'])""")
_XMLNS = re.compile(r"""xmlns:([A-Za-z_][\w.-]*)\s*=\s*(["'])(.*?)\2""")
_ENTITY = re.compile(r"""<!ENTITY\s+([\w.-]+)\s+(["'])(.*?)\2\s*>""", re.S)
_SINGLE_QUOTED_ENTITY = re.compile(rb"""<!ENTITY(\s+[\w.-]+\s+)'([^'"]*)'(\s*)>""")
_RDF_ID = re.compile(rb"""rdf:ID\s*=\s*(["'])(.*?)\1""")
# Oxigraph repeats the position at the head of its messages, in three spellings; the error carries it already.
_POSITION_PREFIX = re.compile(
    r"^Parser error (?:at|between) line \d+ (?:column \d+|between columns \d+ and \d+)(?: and line \d+ column \d+)?: "
)
_NCNAME = re.compile(r"^[A-Za-z_\u00c0-\uffff][\w.\-\u00b7\u00c0-\uffff]*$")

_JSON_LD_KEY = re.compile(rb'"@(?:context|id|graph|type|value|base|vocab)"\s*:')

BULK_BYTES = 16 * 1024 * 1024
"""The size from which a lone N-Triples or Turtle file is written by Oxigraph's bulk loader (see the
module's docstring): below it the full path costs little, above it a transaction holds every quad in
memory and writes them twice (log and tables)."""
_BULK_FORMATS = (ox.RdfFormat.N_TRIPLES, ox.RdfFormat.TURTLE)

Progress = Callable[[str, int, int], None]
"""Told how a load goes, for a person waiting on it: the stage (``reading``, ``reading imports``,
``converting OWL-S``, ``checking``, ``writing N triples``), how many of its items are done and of how
many (0 when it is not counted). A load of OWLS-TC takes half a minute, of a 100 MB file minutes."""


def _quiet(stage: str, done: int, total: int) -> None:
    """The progress of a load nobody watches."""


@dataclass(frozen=True)
class ParsedFile:
    """One parsed file: its quads, ready to store, and the graph its triples went to.

    ``owls`` is set for an OWL-S file (what was made from it); ``ontology`` for a file loaded because
    a catalogue resolved that ontology IRI to it; ``repairs`` lists what was mended to parse it.
    """

    source: str
    graph: str
    quads: list[ox.Quad] = field(repr=False)  # every quad: a notebook showing a report printed each one
    owls: Conversion | None = None
    ontology: str | None = None
    repairs: tuple[str, ...] = ()
    bulk: int | None = None  # a bulk-loaded file's triple count; its quads are not kept in memory
    added: dict[str, int] | None = None
    """Per graph IRI, how many of its triples the load added: the rest the store held already, or an
    earlier file of the same load (or the file itself) gave them. ``None`` when not counted (a parse
    without a load)."""

    @property
    def triples(self) -> int:
        """How many triples (quads) the file gave."""
        return len(self.quads) if self.bulk is None else self.bulk

    @property
    def added_triples(self) -> int | None:
        """How many triples the load added for this file (``None`` when not counted)."""
        return None if self.added is None else sum(self.added.values())


@dataclass(frozen=True)
class UnresolvedConcept:
    """A parameter type or statement term of a loaded description that no loaded ontology declares."""

    iri: str
    used_as: str  # "parameter type" or "statement term"
    used_by: str  # the description's IRI


@dataclass
class LoadReport:
    """What one load read and what it added: the files asked for, the ontologies their imports
    brought in, what could not be resolved, and (:attr:`added`) what the store did not hold before.
    Iterating it gives the files asked for."""

    files: list[ParsedFile] = field(default_factory=list)
    imports: list[ParsedFile] = field(default_factory=list)
    already_loaded: list[str] = field(default_factory=list)
    """The ontologies imports named that no catalogue entry maps but the store declares already (a bundled one)."""
    unresolved_imports: list[Unresolved] = field(default_factory=list)
    unresolved_concepts: list[UnresolvedConcept] = field(default_factory=list)
    catalogue: Catalogue | None = None
    added: dict[str, int] = field(default_factory=dict)
    """Per graph IRI, how many triples the load added: :attr:`quads` counts what the files gave, and
    loading what the store holds already adds nothing, so a reload gives the same ``quads`` and no
    ``added``. Counted per triple, before the write, which then carries only what was added
    (:func:`_new_quads`)."""
    removed: dict[str, int] = field(default_factory=dict)
    """Per graph IRI, how many triples a replacing load took out (those of the graph the files did not give)."""
    kept: dict[str, int] = field(default_factory=dict)
    """Per graph IRI, how many triples of the graph a replacing load kept though the files did not give
    them (the robots' own descriptions, :mod:`kb.kept_robots`)."""
    kept_robots: tuple[str, ...] = ()
    """The robots whose descriptions a replacing load kept (their IRIs)."""

    def __iter__(self) -> Iterator[ParsedFile]:
        return iter(self.files)

    def __len__(self) -> int:
        return len(self.files)

    @property
    def quads(self) -> int:
        return sum(item.triples for item in (*self.files, *self.imports))

    @property
    def added_quads(self) -> int:
        """How many triples the load added to the store, over all graphs."""
        return sum(self.added.values())

    @property
    def already_present(self) -> int:
        """How many of the triples the files gave added nothing (held already, or given twice)."""
        return self.quads - self.added_quads


@dataclass
class _Raw:
    """A file parsed but not yet skolemised (an OWL-S file is converted first)."""

    source: str
    target: ox.NamedNode
    quads: list[ox.Quad]
    is_owls: bool
    prefixes: dict[str, str]
    repairs: tuple[str, ...]
    ontology: str | None = None


def parse_file(path: str | Path, graph: str | GraphName | None = None) -> ParsedFile:
    """Parse one file; ``graph`` (a graph name or IRI) overrides the graph chosen from its content.

    OWL-S files come back as their raw triples; :func:`load_files` is what converts them."""
    raw = _read(Path(path), graph)
    return ParsedFile(raw.source, raw.target.value, skolemise(raw.quads, raw.source), repairs=raw.repairs)


def parse_bytes(
    raw: bytes,
    source: str,
    rdf_format: ox.RdfFormat,
    graph: str | GraphName | None = None,
    base_iri: str | None = None,
) -> ParsedFile:
    """Parse serialised RDF from memory; ``source`` names it in errors."""
    data = _as_utf8(raw, source)
    check_rdf(data, source)
    parsed, _, repairs = _parse_quads(data, source, rdf_format, _base_for(source, base_iri))
    target = resolve_graph(graph) if graph is not None else _graph_for(parsed)
    return ParsedFile(source, target.value, skolemise(_into(parsed, target), source), repairs=repairs)


@dataclass(frozen=True)
class ReadFiles:
    """The files of one load, parsed but not yet converted or written (:func:`read_files`): what a caller
    that checks a load first (:meth:`KnowledgeBase.load` into graph:map) reads once and hands on to
    :func:`load_files`, which would otherwise parse every file again."""

    paths: tuple[Path, ...]
    raws: tuple[_Raw, ...]

    def quads(self) -> list[ox.Quad]:
        """Every quad the files gave, skolemised as a load writes them (OWL-S files unconverted)."""
        return [quad for raw in self.raws for quad in skolemise(raw.quads, raw.source)]


def read_files(
    paths: Sequence[str | Path],
    graph: str | GraphName | None = None,
    catalogue: Catalogue | None = None,
    progress: Progress | None = None,
) -> ReadFiles:
    """Parse the files of a load (a directory stands for its RDF files) as :func:`load_files` does."""
    tell = progress or _quiet
    files = expand_paths(paths)
    raws = []
    for done, path in enumerate(files):
        tell("reading", done, len(files))
        raws.append(_read(path, graph, base_iri=catalogue.iri_for(path) if catalogue is not None else None))
    return ReadFiles(tuple(files), tuple(raws))


def load_files(
    store: Store,
    paths: Sequence[str | Path],
    graph: str | GraphName | None = None,
    catalogue: Catalogue | None = None,
    progress: Progress | None = None,
    read: ReadFiles | None = None,
    replacing: GraphName | None = None,
    kept: Sequence[ox.Quad] = (),
) -> LoadReport:
    """Parse every file (and, with a catalogue, every ontology they import), convert OWL-S files,
    then add everything in one transaction; nothing is written if any file fails to parse.
    ``progress`` is told each stage as it goes. With ``replacing``, that graph's triples the files do not
    give are taken out in the same transaction: the files become the graph, with the stored quads ``kept``
    (of that graph) left in it.

    OWL-S files (``.owls``, or any file describing an OWL-S service or profile) keep their own
    triples and gain the cbrs description made from them, in the same graph: the requirements graph
    and the requirement role when ``graph`` is ``requirements``, else the services graph (or
    ``graph``) and the advertisement role. ``read`` is these files read already (:func:`read_files`,
    with the same ``graph`` and ``catalogue``): they are not read again, nor bulk-loaded.
    """
    tell = progress or _quiet
    if read is None:
        files = expand_paths(paths)
        if len(files) == 1 and catalogue is None and isinstance(store, EmbeddedStore):
            tell("reading", 0, 1)
            bulk = _bulk_load(store, files[0], graph, tell)
            if bulk is not None:
                return bulk
        read = read_files(files, graph, catalogue, tell)
    raws = [replace(raw, quads=list(raw.quads)) for raw in read.raws]  # an OWL-S conversion extends its quads
    report = LoadReport(catalogue=catalogue)
    imported: list[_Raw] = []
    if catalogue is not None:
        imported = _resolve_imports(store, raws, catalogue, report, tell)
    held = _prepare(store, raws, imported, report, graph, tell=tell)
    new = _new_quads(held, report)
    if getattr(store, "rewrites_held", False):  # its reads may lag its writes: write every quad, as a load did
        new = list(dict.fromkeys(quad for item in (*report.files, *report.imports) for quad in item.quads))
    if replacing is not None:
        given = ox.Store()  # compared as a store compares: "2.30"^^xsd:decimal is the stored "2.3"
        given.extend(quad for item in (*report.files, *report.imports) for quad in item.quads)
        given.extend(ox.Quad(q.subject, q.predicate, q.object, replacing.node) for q in kept)
        old = [quad for quad in store.quads(graph=replacing.node) if quad not in given]
        _check_replaced_declarations(store, old, new, [item.source for item in report.files], replacing)
        report.removed[replacing.iri] = len(old)
        if kept:
            report.kept[replacing.iri] = len(kept)
        if old or new:
            tell(f"writing {len(new)} triples, taking out {len(old)}", 0, 0)
            store.replace(old, new)
        return report
    if new:  # a reload of what the store holds writes nothing (and leaves an embedded store's generation)
        tell(f"writing {len(new)} triples", 0, 0)
        store.add(new)
    return report


def _check_replaced_declarations(
    store: Store, old: Sequence[ox.Quad], new: Sequence[ox.Quad], sources: Sequence[str], replaced: GraphName
) -> None:
    """Refuse a replacing load that leaves a class under a term of cbrs's own vocabularies declared nowhere
    (:func:`kb.superclasses.check_change`, as a Graph Store ``PUT`` of the graph is checked): a statement
    about the term held only in the graph it replaces goes (``RemovedDeclarationError``), or the files put
    a class under a term only that graph declared (``UndeclaredSuperclassError``). The check of each file's
    classes before (:func:`_prepare`) reads the store as it is, with the old graph in it."""
    files = ", ".join(sources) or "the files"
    undone = f"nothing was loaded and graph:{replaced.value} is as it was"
    check_change(store, old, new, f"the load of {files} replacing graph:{replaced.value}", undone)


def prepare_owls(store: Store, raw: bytes, source: str, rdf_format: ox.RdfFormat, base_iri: str) -> LoadReport:
    """One OWL-S file given in memory, parsed, converted into advertisements for graph:services and
    checked as :func:`load_files` checks it, but not written: what the registry puts in place of the
    advertisements an earlier version of the file gave (``cbrs register --update FILE``), in one
    transaction. Unlike a load it does not refuse a service the store holds already (replacing it is
    the point): the caller decides which services it replaces. The report's one file is the converted
    file; the report carries what a load of the file notes too (unresolved concepts, conversion notes,
    mended parts), for the caller to say as ``cbrs load`` says it."""
    data = _as_utf8(raw, source)
    quads, prefixes, repairs = _parse_quads(data, source, rdf_format, base_iri)
    if not is_owls(quads):
        raise RdfParseError(source, "describes no OWL-S service or profile")
    target = GraphName.SERVICES.node
    report = LoadReport()
    _prepare(store, [_Raw(source, target, _into(quads, target), True, prefixes, repairs)], [], report, None, False)
    return report


def _prepare(
    store: Store,
    raws: list[_Raw],
    imported: list[_Raw],
    report: LoadReport,
    graph: str | GraphName | None,
    refuse_merges: bool = True,
    tell: Progress = _quiet,
) -> Held:
    """Convert the OWL-S files among ``raws``, skolemise everything, and check it all against the store
    (part cycles, shapes, and with ``refuse_merges`` an OWL-S service the store holds described
    otherwise): what a load does before it writes, filling ``report``'s files and imports. Returns
    which of their quads the store holds (:func:`_held`), what the merge check and the write ask."""
    ontology = GraphName.ONTOLOGY.node
    vocabulary: Vocabulary | None = None
    if any(raw.is_owls for raw in raws):
        vocabulary = Vocabulary.from_quads(store.quads(None, None, None, ontology))
        vocabulary.add(q for raw in (*raws, *imported) if raw.target == ontology for q in raw.quads)
    requirements = graph is not None and resolve_graph(graph) == GraphName.REQUIREMENTS.node
    role: Role = "requirement" if requirements else "advertisement"
    owls = sum(raw.is_owls for raw in raws)
    converted = 0
    for raw in raws:
        conversion = None
        if raw.is_owls:
            tell("converting OWL-S", converted, owls)
            converted += 1
            conversion = convert(raw.quads, raw.source, role, raw.target, vocabulary, raw.prefixes)
            _check_whole(conversion, raw.source)
            raw.quads.extend(conversion.quads)
            assert vocabulary is not None
            report.unresolved_concepts.extend(_unresolved(conversion, vocabulary))
        parsed = ParsedFile(
            raw.source, raw.target.value, skolemise(raw.quads, raw.source), conversion, repairs=raw.repairs
        )
        report.files.append(parsed)
    report.imports = [
        ParsedFile(
            raw.source, raw.target.value, skolemise(raw.quads, raw.source), ontology=raw.ontology, repairs=raw.repairs
        )
        for raw in imported
    ]
    if graph is not None:  # chosen by the person loading; a graph the loader picks follows the file's types
        for raw in raws:
            check_placement(store, raw.quads, raw.source, raw.prefixes)
    tell("checking", 0, 0)
    held = _held(store, report) if refuse_merges else store.contains  # not asked without a merge check
    if refuse_merges:
        for parsed in report.files:
            if parsed.owls is not None:
                _check_not_merged(store, parsed, held)
            else:
                _check_not_described_elsewhere(store, parsed)
    _check_part_cycles(store, [*raws, *imported])
    check_superclasses(store, [(raw.source, raw.quads) for raw in (*raws, *imported)])
    check_loaded(store, report)  # descriptions against the SHACL shapes, and their terms (kb/shapes.py)
    return held


Held = Callable[[ox.Quad], bool]
"""Whether the store held a quad of the load before it was written."""


def _held(store: Store, report: LoadReport) -> Held:
    """Which quads of ``report`` the store holds: an embedded store is asked per quad when needed
    (:meth:`EmbeddedStore.contains`, 0.4 us), a remote one once for them all (:meth:`Store.contains_each`,
    a query per chunk), since a request per quad took a reload of OWLS-TC 4 minutes."""
    if isinstance(store, EmbeddedStore):
        return store.contains
    unique = list(dict.fromkeys(quad for item in (*report.files, *report.imports) for quad in item.quads))
    found = {quad for quad, held in zip(unique, store.contains_each(unique), strict=True) if held}
    return found.__contains__


def _new_quads(held: Held, report: LoadReport) -> list[ox.Quad]:
    """The quads of ``report`` the store does not hold, each once, in the files' order: what the load
    writes. A load only adds, and the loader names every node from its file's content (skolemisation),
    so writing these alone leaves the store as writing them all would; a reload of OWLS-TC 4 wrote its
    143,268 triples again, seconds of work that changed nothing (docs/architecture.md), and on a remote
    store as many quads sent again (docs/remote-store.md).

    It also fills in what each file adds, before the write: the files' own counts would tell a user a
    reload changed something. ``held`` says whether the store held a quad (:func:`_held`); a triple an
    earlier file of the load gave counts for that file only.
    """
    items = (*report.files, *report.imports)
    new: list[ox.Quad] = []
    seen: set[ox.Quad] = set()
    total: defaultdict[str, int] = defaultdict(int)
    counted: list[ParsedFile] = []
    for item in items:
        added: defaultdict[str, int] = defaultdict(int)
        for quad in item.quads:
            if quad in seen or held(quad):
                continue
            seen.add(quad)
            new.append(quad)
            added[_graph_of(quad, item.graph)] += 1
        for graph, count in added.items():
            total[graph] += count
        counted.append(replace(item, added=dict(added)))
    report.files, report.imports = counted[: len(report.files)], counted[len(report.files) :]
    report.added = dict(total)
    return new


def _graph_of(quad: ox.Quad, default: str) -> str:
    return quad.graph_name.value if isinstance(quad.graph_name, ox.NamedNode) else default


@dataclass
class _Scan:
    """What the first pass over a bulk candidate found: its size and what decides its graph."""

    triples: int = 0
    types: set[str] = field(default_factory=set)
    part_shape: list[ox.Quad] = field(default_factory=list)  # what the part-cycle check reads


def _bulk_load(store: EmbeddedStore, path: Path, graph: str | GraphName | None, tell: Progress) -> LoadReport | None:
    """Load one large plain file with Oxigraph's bulk loader, all or nothing; ``None`` when the file
    must take the full path (too small, another format, something to convert, or a graph in use)."""
    rdf_format = FORMATS_BY_EXTENSION.get(path.suffix.lower())
    if rdf_format not in _BULK_FORMATS:
        return None
    try:
        if path.stat().st_size < BULK_BYTES:
            return None
    except OSError:
        return None  # the full path reports it
    possible = [resolve_graph(graph)] if graph is not None else [g.node for g in _DEFAULT_TARGETS]
    if all(next(iter(store.quads(graph=target)), None) is not None for target in possible):
        return None  # every graph it could go to holds data (a seeded store's do): the scan would be wasted
    source = str(path)
    base = _base_for(source, None)
    scan = _scan(path, rdf_format, base)
    if scan is None:
        return None
    target = resolve_graph(graph) if graph is not None else _graph_for_types(scan.types)
    if next(iter(store.quads(graph=target)), None) is not None:
        return None  # a failed bulk write could not be undone without undoing what was there
    _check_part_cycles(store, [_Raw(source, target, scan.part_shape, False, {}, ())])
    tell(f"writing {scan.triples} triples", 0, 0)
    store.bulk_load(path, rdf_format, target, base)
    added = {target.value: store.count(target)}  # the graph was empty; a file may give a triple twice
    return LoadReport(files=[ParsedFile(source, target.value, [], bulk=scan.triples, added=added)], added=added)


def _scan(path: Path, rdf_format: ox.RdfFormat, base: str) -> _Scan | None:
    """Parse the whole file once, keeping nothing but what decides its graph; ``None`` when it has
    anything the full path must handle (blank nodes, quoted triples, OWL-S, service descriptions) or
    does not parse as it is (the full path then names the error, or mends the encoding)."""
    found = _Scan()
    rdf_type, has_model = RDF + "type", CBRS + "hasOWLSModel"
    try:
        for quad in ox.parse(path=str(path), format=rdf_format, base_iri=base):
            found.triples += 1
            subject, predicate, obj = quad.subject, quad.predicate.value, quad.object
            if not isinstance(subject, ox.NamedNode) or isinstance(obj, ox.BlankNode | ox.Triple):
                return None
            if predicate == rdf_type and isinstance(obj, ox.NamedNode):
                found.types.add(obj.value)
            elif predicate in _PART_SHAPE:
                found.part_shape.append(quad)
            elif predicate == has_model:
                return None
    except (SyntaxError, ValueError, OSError):
        return None
    if any(owls_key(kind) in ("Service:Service", "Profile:Profile") for kind in found.types):
        return None
    return found


def _check_whole(conversion: Conversion, source: str) -> None:
    """An OWL-S file must describe a service by a profile or a process; one that lacks a part is named
    in the conversion's notes, so a load never passes a partial description off as whole."""
    if not conversion.services:
        raise RdfParseError(
            source, "the OWL-S file describes no service with an IRI (Service:Service or Profile:Profile)"
        )
    for converted in conversion.services:
        if "profile" in converted.missing and "process" in converted.missing:
            raise RdfParseError(
                source,
                f"OWL-S service <{converted.service}> has neither a profile nor a process: nothing describes what "
                "it takes or gives; nothing was loaded",
            )
        if converted.missing:
            conversion.notes.append(
                f"{source}: OWL-S service <{converted.service}> has no {' and no '.join(converted.missing)}; its "
                "description was made from the rest"
            )


def _check_not_merged(store: Store, parsed: ParsedFile, held: Held) -> None:
    """Refuse an OWL-S file whose service the store describes otherwise, rather than merge the two
    descriptions: in the graph the file goes to (the same file again adds nothing, its nodes being named
    from its content), or as a cbrs description in another graph (:func:`_describes`), since queries
    read the union of the graphs. A graph that holds only the OWL-S triples of the IRI (a request copy
    of the service, loaded into graph:requirements as the requirement ``<IRI>-request``: OWLS-TC's query
    files are copies of service files) describes another resource and does not stop the load
    (docs/owls.md)."""
    assert parsed.owls is not None
    rdf_type = ox.NamedNode(RDF + "type")
    for converted in parsed.owls.services:
        node = ox.NamedNode(converted.iri)
        types: defaultdict[str, set[str]] = defaultdict(set)
        for quad in store.quads(node, rdf_type):
            if isinstance(quad.graph_name, ox.NamedNode) and isinstance(quad.object, ox.NamedNode):
                types[quad.graph_name.value].add(quad.object.value)
        if parsed.graph in types and not all(held(q) for q in parsed.quads):
            # the advice first: the parser errors' one-line form keeps 240 characters, and OWL-S IRIs are long
            advice = "cbrs deregister IRI first, or give the new one another IRI"
            if parsed.graph == GraphName.SERVICES.iri:  # an advertisement: the registry replaces it in one transaction
                advice = f"cbrs register --update FILE replaces it (or {advice})"
            raise RdfParseError(
                parsed.source,
                f"<{converted.iri}> is already in the store, described differently in {shorten(parsed.graph)}; a "
                f"load would merge the two: {advice}",
            )
        for graph, kinds in sorted(types.items()):
            if graph != parsed.graph and any(_describes(kind) for kind in kinds):
                raise RdfParseError(
                    parsed.source,
                    f"<{converted.iri}> is described in {shorten(graph)} already, and queries read all graphs as "
                    f"one: loading it into {shorten(parsed.graph)} too would merge the two descriptions; "
                    f"cbrs deregister IRI first, or give the new one another IRI",
                )


def _check_not_described_elsewhere(store: Store, parsed: ParsedFile) -> None:
    """Refuse a file that describes (``cbrs:hasOWLSModel``) a service or requirement the store describes in
    another graph: queries read all graphs as one, and a file's nodes are named from its content and its
    graph, so the two models would merge into one description with each input, precondition and effect
    twice. The ninth round loaded a file of a class and a task into graph:ontology, for the class, and
    graph:requirements, for the task: the task had six inputs, two goals and four preconditions, and the plan
    said it did without "book#2", as if no component took a book. The same file into the same graph again
    adds nothing, and is not refused."""
    model = ox.NamedNode(CBRS + "hasOWLSModel")
    described = {quad.subject for quad in parsed.quads if quad.predicate == model}
    for subject in sorted(described, key=str):
        if not isinstance(subject, ox.NamedNode):
            continue
        elsewhere = sorted(
            {quad.graph_name.value for quad in store.quads(subject, model) if isinstance(quad.graph_name, ox.NamedNode)}
            - {parsed.graph}
        )
        if elsewhere:
            raise DescribedElsewhereError(
                parsed.source, subject.value, parsed.graph, elsewhere[0], _is_requirement(parsed, subject)
            )


def _is_requirement(parsed: ParsedFile, subject: ox.NamedNode) -> bool:
    kind = ox.NamedNode(CBRS + "Requirement")
    return any(quad.subject == subject and quad.object == kind for quad in parsed.quads)


def _describes(kind: str) -> bool:
    """Whether a type makes its node a description (a component kind, cbrs:Requirement, a lab's class), as
    an OWL-S class (``service:Service``) or OWL's and RDF's own (``owl:NamedIndividual``, which editors
    add to every individual) do not."""
    return owls_key(kind) is None and not kind.startswith((OWL, RDFS, RDF))


def expand_paths(paths: Sequence[str | Path]) -> list[Path]:
    """The files to load: each file as given, and for a directory the files directly inside it with an
    RDF extension, sorted by name. A ``.xml`` file in a directory counts only when it mentions the RDF
    namespace near its start, so an OASIS catalogue or other XML beside the ontologies is passed over; a
    ``.json`` file only when it has a JSON-LD keyword (``"@context"``, ``"@id"``, ``"@graph"``...) near its
    start, so a ``package.json`` or a robot's configuration is passed over too (``.jsonld`` always counts)."""
    files: list[Path] = []
    for given in paths:
        path = Path(given)
        if not path.is_dir():
            files.append(path)
            continue
        found = len(files)
        for child in sorted(path.iterdir()):
            suffix = child.suffix.lower()
            if not child.is_file() or suffix not in FORMATS_BY_EXTENSION:
                continue
            if suffix == ".xml" and RDF.encode("ascii") not in _as_utf8(child.read_bytes()[:4096], str(child), False):
                continue
            if suffix == ".json" and not _JSON_LD_KEY.search(child.read_bytes()[:65536]):
                continue  # a configuration or data file beside the RDF, not JSON-LD
            files.append(child)
        if len(files) == found:
            known = ", ".join(sorted(FORMATS_BY_EXTENSION))
            raise RdfParseError(
                str(path), f"a directory with no RDF file in it (extensions {known}); nothing was loaded"
            )
    return files


def resolve_graph(graph: str | GraphName) -> ox.NamedNode:
    """A graph given as a cbrs graph name (``services``) or a full IRI."""
    if isinstance(graph, GraphName):
        return graph.node
    try:
        return GraphName(graph).node
    except ValueError:
        pass
    if "://" in graph or graph.startswith("urn:"):
        try:
            return ox.NamedNode(graph)
        except ValueError:
            pass
    raise UnknownGraphError(graph, [g.value for g in GraphName])


def skolemise(quads: Iterable[ox.Quad], source: str = "the input") -> list[ox.Quad]:
    """Replace blank nodes with IRIs derived from the canonical form of ``quads``.

    RDFC-1.0 tries every order of blank nodes it cannot tell apart, which is exponential: twelve
    blank nodes all linked to each other take minutes and gigabytes. A graph with such look-alikes is
    canonicalised in a child process bounded by ``CANONICAL_SECONDS`` and ``CANONICAL_BYTES``; one
    that does not finish is refused (``RdfParseError`` naming ``source``), never left to hang a load."""
    quads = list(quads)
    if not any(isinstance(t, ox.BlankNode) for q in quads for t in (q.subject, q.object)):
        return quads
    if _has_look_alikes(quads):
        canonical = _canonical_in_child(quads, source)
    else:
        dataset = ox.Dataset(quads)
        dataset.canonicalize(ox.CanonicalizationAlgorithm.RDFC_1_0)
        canonical = sorted(dataset, key=str)
    digest = hashlib.sha256("".join(f"{q} .\n" for q in canonical).encode("utf-8")).hexdigest()[:16]

    def named(term: Any) -> Any:
        if isinstance(term, ox.BlankNode):
            return ox.NamedNode(f"{GENID}{digest}-{term.value}")
        return term

    return [ox.Quad(named(q.subject), q.predicate, named(q.object), q.graph_name) for q in canonical]


CANONICAL_SECONDS = 10.0
CANONICAL_BYTES = 2 << 30  # address space of the child that canonicalises a hard graph
_CANONICALISE = """
import resource, sys
import pyoxigraph as ox
limit = int(sys.argv[1])
try:
    resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
except (ValueError, OSError):
    pass
dataset = ox.Dataset(ox.parse(sys.stdin.buffer.read(), format=ox.RdfFormat.N_QUADS))
dataset.canonicalize(ox.CanonicalizationAlgorithm.RDFC_1_0)
sys.stdout.buffer.write(ox.serialize(list(dataset), format=ox.RdfFormat.N_QUADS) or b"")
"""


def _has_look_alikes(quads: list[ox.Quad]) -> bool:
    """Whether RDFC-1.0 would have to permute: a blank node with two or more blank neighbours that
    share their link (direction, predicate) and look alike (the same first-degree hash). Lists,
    OWL restrictions and service description trees have none."""
    around: dict[ox.BlankNode, list[ox.Quad]] = defaultdict(list)
    for q in quads:
        for term in {q.subject, q.object}:
            if isinstance(term, ox.BlankNode):
                around[term].append(q)

    def shape(q: ox.Quad, node: ox.BlankNode) -> tuple[str, ...]:
        return tuple(
            "_:a" if t == node else "_:z" if isinstance(t, ox.BlankNode) else str(t)
            for t in (q.subject, q.predicate, q.object, q.graph_name)
        )

    first = {node: hash(tuple(sorted(shape(q, node) for q in links))) for node, links in around.items()}
    for node, links in around.items():
        seen: set[tuple[str, str, int]] = set()
        for q in links:
            for end, other in (("subject", q.subject), ("object", q.object)):
                if isinstance(other, ox.BlankNode) and other != node:
                    key = (end, q.predicate.value, first[other])
                    if key in seen:
                        return True
                    seen.add(key)
    return False


def _canonical_in_child(quads: list[ox.Quad], source: str) -> list[ox.Quad]:
    data = ox.serialize(quads, format=ox.RdfFormat.N_QUADS) or b""
    command = [sys.executable, "-c", _CANONICALISE, str(CANONICAL_BYTES)]
    blank = len({t for q in quads for t in (q.subject, q.object) if isinstance(t, ox.BlankNode)})
    refusal = (
        f"{blank} blank nodes, many alike, that RDF canonicalisation could not name within "
        f"{CANONICAL_SECONDS:g} s and {CANONICAL_BYTES >> 20} MiB; give some of them IRIs"
    )
    try:
        done = subprocess.run(command, input=data, capture_output=True, timeout=CANONICAL_SECONDS, check=False)
    except subprocess.TimeoutExpired as error:
        raise RdfParseError(source, refusal) from error
    if done.returncode != 0:
        raise RdfParseError(source, refusal)
    return sorted(ox.parse(done.stdout, format=ox.RdfFormat.N_QUADS), key=str)


def _read(path: Path, graph: str | GraphName | None, base_iri: str | None = None, ontology: str | None = None) -> _Raw:
    try:
        raw = path.read_bytes()
    except OSError as error:
        raise RdfParseError(str(path), f"cannot read: {error.strerror or error}") from error
    source = str(path)
    if not raw.strip():
        raise RdfParseError(source, "the file is empty" if not raw else "the file holds only white space")
    check_rdf(_as_utf8(raw[:65536], source, strict=False), source)  # Protégé's OWL/XML, saved as .owl too
    rdf_format = _format_for(path, raw)
    data = _as_utf8(raw, source)
    quads, prefixes, repairs = _parse_quads(data, source, rdf_format, _base_for(source, base_iri))
    owls = path.suffix.lower() == ".owls" or is_owls(quads)
    if graph is not None:
        target = resolve_graph(graph)
    elif owls:
        target = GraphName.SERVICES.node  # OWL-S files often declare stub classes; they are not ontologies
    else:
        target = _graph_for(quads)
    return _Raw(source, target, _into(quads, target), owls, prefixes, repairs, ontology)


def _base_for(source: str, base_iri: str | None) -> str:
    return base_iri or (Path(source).resolve().as_uri() if "://" not in source else source)


def _into(quads: list[ox.Quad], target: ox.NamedNode) -> list[ox.Quad]:
    return [
        ox.Quad(q.subject, q.predicate, q.object, target if isinstance(q.graph_name, ox.DefaultGraph) else q.graph_name)
        for q in quads
    ]


def _parse_quads(
    data: bytes, source: str, rdf_format: ox.RdfFormat, base: str
) -> tuple[list[ox.Quad], dict[str, str], tuple[str, ...]]:
    """The file's quads, its namespace prefixes, and the repairs it needed to parse.

    RDF/XML in the wild breaks a few rules that cost nothing to mend: entity declarations in single
    quotes, ``rdf:ID`` values that are not XML names (``rdf:ID="1CAR"``), the same ``rdf:ID`` given
    twice. Such a file is mended and parsed again, leniently, with every IRI then checked; any other
    error stands.
    """
    if rdf_format == ox.RdfFormat.RDF_XML:
        check_entities(data, source)  # before Oxigraph expands them: a kilobyte can expand to gigabytes
    try:
        parser = ox.parse(input=data, format=rdf_format, base_iri=base)
        quads = list(parser)
    except SyntaxError as error:
        mended = _mend_rdfxml(data, str(error)) if rdf_format == ox.RdfFormat.RDF_XML else None
        if mended is None:
            raise _located(error, source, data, rdf_format) from error
        fixed, repairs = mended
        try:
            quads = _checked(ox.parse(input=fixed, format=rdf_format, base_iri=base, lenient=True))
        except (SyntaxError, ValueError):
            raise _located(error, source, data, rdf_format) from error
        _check_well_formed(fixed, source)
        return quads, _xml_prefixes(fixed), repairs
    except ValueError as error:
        raise RdfParseError(source, str(error)) from error
    if rdf_format == ox.RdfFormat.RDF_XML:
        _check_well_formed(data, source)
        return quads, _xml_prefixes(data), ()
    return quads, dict(parser.prefixes), ()


def _mend_rdfxml(data: bytes, message: str) -> tuple[bytes, tuple[str, ...]] | None:
    repairs = []
    fixed = _SINGLE_QUOTED_ENTITY.sub(rb'<!ENTITY\g<1>"\g<2>"\g<3>>', data)
    if fixed != data:
        repairs.append("entity declarations in single quotes")

    def about(match: re.Match[bytes]) -> bytes:
        value = match.group(2)
        if _NCNAME.match(value.decode("utf-8", "replace")):
            return match.group(0)
        return b'rdf:about="#' + value.replace(b'"', b"&quot;") + b'"'

    renamed = _RDF_ID.sub(about, fixed)
    if renamed != fixed:
        repairs.append("rdf:ID values that are not XML names, read as rdf:about")
    identifiers = [m.group(2) for m in _RDF_ID.finditer(renamed)]
    if "already been used as rdf:ID" in message or len(identifiers) != len(set(identifiers)):
        repairs.append("an rdf:ID given twice")
    return (renamed, tuple(repairs)) if repairs else None


def _checked(quads: Iterable[ox.Quad]) -> list[ox.Quad]:
    """Quads from a lenient parse, with every IRI validated as a strict parse would have."""
    checked = list(quads)
    for q in checked:
        for term in (q.subject, q.predicate, q.object):
            if isinstance(term, ox.NamedNode):
                ox.NamedNode(term.value)  # raises ValueError for an invalid IRI
    return checked


def _xml_prefixes(data: bytes) -> dict[str, str]:
    """The ``xmlns:`` prefixes an RDF/XML file declares, with its DTD entities expanded."""
    text = data[:65536].decode("utf-8", "replace")
    entities = {name: value for name, _, value in _ENTITY.findall(text)}

    def expand(value: str) -> str:
        return re.sub(r"&([\w.-]+);", lambda m: entities.get(m.group(1), m.group(0)), value)

    prefixes: dict[str, str] = {}
    for prefix, _, namespace in _XMLNS.findall(text):
        prefixes.setdefault(prefix, expand(namespace))
    return prefixes


def _resolve_imports(
    store: Store, raws: list[_Raw], catalogue: Catalogue, report: LoadReport, tell: Progress = _quiet
) -> list[_Raw]:
    """Parse, once each, the ontologies the files import (and, for OWL-S files, those their concepts'
    namespaces name), transitively, from local files only; what the catalogue cannot resolve is
    reported, not fatal, except an OWL-S upper ontology (a researcher's own collection without copies of
    them was told its every file had 3 unresolved imports)."""
    pending: deque[tuple[str, str, str]] = deque()
    for raw in raws:
        if raw.is_owls:
            references = referenced_ontologies(raw.quads)
        else:
            references = [(iri, "owl:imports") for iri in _imports(raw.quads)]
        pending.extend((iri, raw.source, reason) for iri, reason in references)
    seen = {ontology for raw in raws for ontology in _ontologies(raw.quads)}  # given in this load
    loaded = {Path(raw.source).resolve() for raw in raws}
    imported: list[_Raw] = []
    while pending:
        iri, needed_by, reason = pending.popleft()
        document = ontology_iri(iri)
        if document in seen or is_built_in(document):
            continue
        seen.add(document)
        path = catalogue.resolve(document)
        if path is None:
            if holds_ontology(store, document):  # a bundled ontology (home), or one an earlier load brought
                report.already_loaded.append(document)
            elif not is_owls_ontology(document):  # read by the OWL-S reader itself: nothing is missing
                report.unresolved_imports.append(Unresolved(document, needed_by, reason))
            continue
        if path.resolve() in loaded:
            continue
        loaded.add(path.resolve())
        tell("reading imports", len(imported), 0)
        raw = _read(path, GraphName.ONTOLOGY, base_iri=document, ontology=document)
        imported.append(raw)
        pending.extend((target, raw.source, "owl:imports") for target in _imports(raw.quads))
    return imported


_SUBCLASS, _SUBPROPERTY = RDFS + "subClassOf", RDFS + "subPropertyOf"
_ON_PROPERTY, _SOME_VALUES = OWL + "onProperty", OWL + "someValuesFrom"
_PART_SHAPE = (_SUBCLASS, _SUBPROPERTY, _ON_PROPERTY, _SOME_VALUES)


def _check_part_cycles(store: Store, raws: Sequence[_Raw]) -> None:
    """Refuse a load whose hasPart restrictions would close a cycle with themselves or the store's.

    Parts are read as ``queries/concept_parts.rq`` reads them (restrictions on dul:hasPart or a
    subproperty, inherited along rdfs:subClassOf, a class's own restriction narrowing an inherited
    one on the same property), so what is refused is what would make a part tree endless. A cycle
    the store already holds is not this load's doing and does not stop it."""
    added = [(q, raw.source) for raw in raws for q in raw.quads if q.predicate.value in _PART_SHAPE]
    if not added:
        return
    stored = [q for name in _PART_SHAPE for q in store.quads(None, ox.NamedNode(name))]
    before = _part_edges(stored)
    after = _part_edges([*stored, *(q for q, _ in added)])
    for whole in sorted(after):
        for part in sorted(after[whole] - before.get(whole, set())):
            path = _part_path(after, part, whole)
            if path is None:
                continue
            cycle = [whole, *path]
            sources = sorted(
                {src for q, src in added if isinstance(q.subject, ox.NamedNode) and q.subject.value in cycle}
            )
            raise PartCycleError(sources or sorted({source for _, source in added}), cycle)


def _part_edges(quads: Iterable[ox.Quad]) -> dict[str, set[str]]:
    """Each named class and the parts its part tree would list (own or inherited)."""
    parents: dict[Any, set[Any]] = defaultdict(set)
    super_properties: dict[Any, set[Any]] = defaultdict(set)
    on_property: dict[Any, Any] = {}
    some_values: dict[Any, Any] = {}
    for q in quads:
        name = q.predicate.value
        if name == _SUBCLASS:
            parents[q.subject].add(q.object)
        elif name == _SUBPROPERTY:
            super_properties[q.subject].add(q.object)
        elif name == _ON_PROPERTY:
            on_property[q.subject] = q.object
        elif name == _SOME_VALUES:
            some_values[q.subject] = q.object
    has_part = ox.NamedNode(DUL + "hasPart")
    own: dict[Any, dict[Any, set[str]]] = defaultdict(lambda: defaultdict(set))
    for owner, supers in parents.items():
        for restriction in supers:
            prop, part = on_property.get(restriction), some_values.get(restriction)
            if (
                isinstance(part, ox.NamedNode)
                and not part.value.startswith(GENID)
                and prop is not None
                and has_part in _closure(prop, super_properties)
            ):
                own[owner][prop].add(part.value)
    edges: dict[str, set[str]] = {}
    for concept in parents:
        if not isinstance(concept, ox.NamedNode) or concept.value.startswith(GENID):
            continue
        inherited: dict[Any, set[str]] = defaultdict(set)
        for owner in _closure(concept, parents):
            for prop, parts in own.get(owner, {}).items():
                inherited[prop] |= parts
        found = {part for prop, parts in inherited.items() for part in own.get(concept, {}).get(prop, parts)}
        if found:
            edges[concept.value] = found
    return edges


def _closure(start: Any, links: dict[Any, set[Any]]) -> set[Any]:
    """``start`` and everything reachable from it along ``links``."""
    seen = {start}
    queue = deque([start])
    while queue:
        for nxt in links.get(queue.popleft(), ()):
            if nxt not in seen:
                seen.add(nxt)
                queue.append(nxt)
    return seen


def _part_path(edges: dict[str, set[str]], start: str, goal: str) -> list[str] | None:
    """The shortest chain of parts from ``start`` down to ``goal`` (both included), or None."""
    previous: dict[str, str | None] = {start: None}
    queue = deque([start])
    while queue:
        node = queue.popleft()
        if node == goal:
            path = [node]
            while (back := previous[path[-1]]) is not None:
                path.append(back)
            return path[::-1]
        for nxt in sorted(edges.get(node, ())):
            if nxt not in previous:
                previous[nxt] = node
                queue.append(nxt)
    return None


def holds_ontology(store: Store, iri: str) -> bool:
    """Whether ``store`` declares ``iri`` an ``owl:Ontology``, in any graph: an import of it needs no file."""
    declared = store.quads(ox.NamedNode(iri), ox.NamedNode(RDF + "type"), ox.NamedNode(OWL + "Ontology"))
    return next(iter(declared), None) is not None


def _ontologies(quads: Iterable[ox.Quad]) -> set[str]:
    """The IRIs ``quads`` declare ``owl:Ontology``s."""
    rdf_type, ontology = RDF + "type", OWL + "Ontology"
    return {
        q.subject.value
        for q in quads
        if q.predicate.value == rdf_type
        and isinstance(q.subject, ox.NamedNode)
        and isinstance(q.object, ox.NamedNode)
        and q.object.value == ontology
    }


def _imports(quads: Iterable[ox.Quad]) -> list[str]:
    imports = OWL + "imports"
    return [q.object.value for q in quads if q.predicate.value == imports and isinstance(q.object, ox.NamedNode)]


def _unresolved(conversion: Conversion, vocabulary: Vocabulary) -> list[UnresolvedConcept]:
    found = []
    for service in conversion.services:
        for concept in service.parameter_types:
            if not vocabulary.declares(concept):
                found.append(UnresolvedConcept(concept, "parameter type", service.iri))
        for term in service.statement_terms:
            if not vocabulary.declares(term):
                found.append(UnresolvedConcept(term, "statement term", service.iri))
    return found


def registration_format(source: str, raw: bytes) -> ox.RdfFormat:
    """The format of a description given to the registry: by the source's extension when it names a
    file of a known RDF format (``camera.rdf``, ``camera.jsonld``), else Turtle unless the text opens
    as RDF/XML. A registration sent as text (``<registration>``) is Turtle."""
    suffix = Path(source).suffix.lower() if not source.startswith("<") else ""
    if suffix in FORMATS_BY_EXTENSION:
        return _format_for(Path(source), raw)
    head = _as_utf8(raw[:4096], source, strict=False).lstrip()
    return ox.RdfFormat.RDF_XML if head.startswith((b"<?xml", b"<rdf:RDF")) else ox.RdfFormat.TURTLE


def _format_for(path: Path, raw: bytes) -> ox.RdfFormat:
    head = _as_utf8(raw[:4096], str(path), strict=False).lstrip()
    looks_turtle = head.startswith((b"@prefix", b"@base", b"PREFIX", b"BASE", b"prefix"))
    looks_xml = head.startswith((b"<?xml", b"<rdf:RDF"))
    known = FORMATS_BY_EXTENSION.get(path.suffix.lower())
    if known == ox.RdfFormat.RDF_XML and looks_turtle:
        return ox.RdfFormat.TURTLE  # OWL files in the wild are Turtle too; the content decides
    if known is not None:
        return known
    if looks_xml:
        return ox.RdfFormat.RDF_XML
    if looks_turtle:
        return ox.RdfFormat.TURTLE
    raise UnknownFormatError(str(path), sorted(FORMATS_BY_EXTENSION))


def _as_utf8(raw: bytes, source: str, strict: bool = True) -> bytes:
    """Re-encode UTF-16/32 or legacy-encoded XML as UTF-8, which the parsers expect."""
    for bom, codec in (
        (codecs.BOM_UTF32_LE, "utf-32"),
        (codecs.BOM_UTF32_BE, "utf-32"),
        (codecs.BOM_UTF8, "utf-8-sig"),
        (codecs.BOM_UTF16_LE, "utf-16"),
        (codecs.BOM_UTF16_BE, "utf-16"),
    ):
        if raw.startswith(bom):
            return _redeclare(_decode(raw, codec, source, strict).encode("utf-8"))
    declared = _XML_ENCODING.match(raw)
    if declared and declared.group(2).lower().replace(b"_", b"-") not in {b"utf-8", b"utf8"}:
        codec = declared.group(2).decode("ascii")
        return _redeclare(_decode(raw, codec, source, strict).encode("utf-8"))
    if strict and b"\x00" in raw[:4096]:
        raise RdfParseError(source, _nul_bytes(raw[:4096]))
    return raw


def _nul_bytes(head: bytes) -> str:
    """Why a file with NUL bytes cannot be read: UTF-16 without its byte-order mark (every other
    byte NUL), or not text at all. Either way the parsers would report a misleading syntax error."""
    for name, zeros in (("UTF-16LE", head[1::2]), ("UTF-16BE", head[0::2])):
        if len(zeros) > 1 and zeros.count(0) >= 0.9 * len(zeros):
            return f"looks like {name} without a byte-order mark; save it as UTF-8 (or UTF-16 with the mark)"
    return "holds NUL bytes: binary data, not RDF text"


def _decode(raw: bytes, codec: str, source: str, strict: bool) -> str:
    try:
        return raw.decode(codec, errors="strict" if strict else "replace")
    except LookupError as error:
        raise RdfParseError(source, f"unknown character encoding {codec!r}") from error
    except UnicodeDecodeError as error:
        raise RdfParseError(source, f"not valid {codec}: byte {error.start} ({error.reason})") from error


def _redeclare(data: bytes) -> bytes:
    return _XML_ENCODING.sub(rb"\g<1>UTF-8\g<3>", data, count=1)


def _located(error: SyntaxError, source: str, data: bytes, rdf_format: ox.RdfFormat) -> RdfParseError:
    message = str(error.args[0]) if error.args else str(error)
    position = error.args[1] if len(error.args) > 1 and isinstance(error.args[1], tuple) else ()
    line = position[1] if len(position) > 1 else None
    column = position[2] if len(position) > 2 else None
    message = _POSITION_PREFIX.sub("", message)
    not_utf8 = re.search(r"invalid utf-8|cannot decode input using utf-8", message, re.IGNORECASE) is not None
    if line is None and rdf_format == ox.RdfFormat.RDF_XML:
        malformed = _xml_error(data)
        if malformed is not None:
            reason, line, column = malformed
            if not (message.startswith("ill-formed") or not_utf8):  # Oxigraph's own words are clear then
                message = f"malformed XML, {reason} ({message})"
        else:
            line, column = _position_of(data, message)
    if not_utf8:
        declare = " or declare its encoding in <?xml ... encoding=...?>" if rdf_format == ox.RdfFormat.RDF_XML else ""
        message += f"; the file is not UTF-8: save it as UTF-8{declare}"
    if rdf_format == ox.RdfFormat.JSON_LD and "LoadDocumentCallback" in message:
        # Oxigraph's words for a remote @context ("https://schema.org/"), which cbrs never fetches
        remote = re.search(rb'"@context"\s*:\s*\[?\s*"([^"]+)"', data)
        named = f" ({remote.group(1).decode('utf-8', 'replace')})" if remote else ""
        message = (
            f"the JSON-LD @context{named} is a remote document, and cbrs fetches nothing from the network: "
            "put the context's terms in the file (an inline @context object) or convert the file to Turtle"
        )
    return RdfParseError(source, message, line, column)


def _position_of(data: bytes, message: str) -> tuple[int | None, int | None]:
    """Where the value a well-formed RDF/XML file's error quotes (an IRI, a prefix) first occurs."""
    quoted = re.search(r"'([^']+)'", message) or re.search(r"Unknown prefix (\S+:)", message)
    if quoted is None:
        return None, None
    needle = quoted.group(1).encode("utf-8")
    if quoted.re.pattern.startswith("Unknown"):
        needle = b"<" + needle
    at = data.find(needle)
    if at < 0:
        return None, None
    line_start = data.rfind(b"\n", 0, at) + 1
    return data.count(b"\n", 0, at) + 1, at - line_start + 1


def _check_well_formed(data: bytes, source: str) -> None:
    """Oxigraph's RDF/XML parser takes a document that ends before its elements are closed (a
    truncated download) and returns the triples read so far; expat does not, so that file loads nothing."""
    malformed = _xml_error(data)
    if malformed is not None:
        reason, line, column = malformed
        raise RdfParseError(source, f"malformed XML, {reason}", line, column)


def _xml_error(data: bytes) -> tuple[str, int, int] | None:
    """Expat's reason and position when the XML is malformed (Oxigraph's RDF/XML errors carry no position)."""
    parser = xml.parsers.expat.ParserCreate()
    try:
        parser.Parse(data, True)
    except xml.parsers.expat.ExpatError as error:
        reason = xml.parsers.expat.errors.messages[error.code] if error.code else str(error)
        if reason == "no element found" and error.lineno > 1:
            reason = "the document ends before its elements are closed"
        return reason, error.lineno, error.offset + 1
    return None


def _graph_for(quads: list[ox.Quad]) -> ox.NamedNode:
    """The graph for a file's triples when none is given: declarations go to the ontology graph,
    requirements to the requirements graph, everything else to the services graph."""
    return _graph_for_types(
        {q.object.value for q in quads if q.predicate.value == RDF + "type" and isinstance(q.object, ox.NamedNode)}
    )


_DEFAULT_TARGETS = (GraphName.ONTOLOGY, GraphName.REQUIREMENTS, GraphName.SERVICES)
"""The graphs :func:`_graph_for_types` chooses from."""


def _graph_for_types(types: set[str]) -> ox.NamedNode:
    if types & DECLARATION_TYPES:
        return GraphName.ONTOLOGY.node
    if CBRS + "Requirement" in types and CBRS + "Advertisement" not in types:
        return GraphName.REQUIREMENTS.node
    return GraphName.SERVICES.node
