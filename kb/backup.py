"""Backups of a cbrs store as a file: every named graph exported as N-Quads or TriG, and restored all or nothing.

An export is the store's quads, graph by graph, then a **manifest**: a few statements in graph:export that
say it is a cbrs export, by which cbrs, from which store, when, and how many triples each graph held. It is
written last, so a file cut short (a full disk, a killed process) has none and is refused like any file that
is not an export; and the counts let a restore find a file that lost lines in the middle. The manifest is
data, not a comment, so it survives a conversion from one RDF format to another.

A restore replaces the store's contents with the file's in one transaction: the whole file is parsed and
checked first, so a parse error leaves the store as it was; then an embedded store runs one SPARQL update
(``DROP ALL`` and one ``INSERT DATA``), and a remote store stages the quads and publishes them with one
operation that also empties the graphs it replaces (:mod:`kb.staged_writes`), the only unit every server
keeps whole. The export names every node as the store does (cbrs skolemises blank nodes on load), so a
restore gives back the same quads; a blank node the store held comes back as a new one, linked the same way.

graph:liveness is the servers' present state, which no file holds: a restore that replaces it keeps the facts
of the components live when it begins (their session, their lease) and writes none of the file's leases as
live (:meth:`kb.liveness.Liveness.restored`).

A remote store's export leaves out the graphs its server keeps for itself (``ontologies/server_graphs.toml``:
Virtuoso's system graphs), and its restore leaves them alone. See docs/backup.md.
"""

from __future__ import annotations

import contextlib
import datetime
import gzip
import os
import sys
import tomllib
from collections import Counter
from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO

import pyoxigraph as ox

from cbrs import __version__
from cbrs.kb.errors import KnowledgeBaseError, RdfParseError, without_password
from cbrs.kb.liveness import Liveness, Restored
from cbrs.kb.loader import resolve_graph
from cbrs.kb.namespaces import BASE, GRAPH, PREFIXES, GraphName, shorten
from cbrs.kb.resources import ontology_dir
from cbrs.kb.staged_writes import STAGING, write_staged
from cbrs.kb.store import BULK_LOADING, EmbeddedStore, Store, data_block
from cbrs.kb.superclasses import check_change, check_whole

Progress = Callable[[str, int, int], None]
"""Told how an export or restore goes: the stage, items done, of how many (0: not counted; the stage's
text then says how far it is, ``exporting graph:services (2/5): 40000 triples``)."""

EXPORT_GRAPH = ox.NamedNode(GRAPH + "export")
"""The graph an export's manifest is in; never written to a store."""
EXPORT = BASE + "export#"
"""The manifest's vocabulary: ``export:Export``, ``export:cbrsVersion``, ``export:exportedAt``,
``export:source``, ``export:partial``, ``export:part`` (one node per graph) with ``export:graph`` and
``export:triples``, and ``export:defaultGraph true`` for the default graph's part."""
DEFAULT = ""
"""How counts name the default graph."""

FORMATS = {".nq": ox.RdfFormat.N_QUADS, ".trig": ox.RdfFormat.TRIG}
"""The export formats by file extension (either may end in ``.gz`` as well)."""

REQUIRED = (GraphName.ONTOLOGY, GraphName.SERVICES, GraphName.REQUIREMENTS, GraphName.MAP)
"""The graphs every seeded cbrs store holds data in: a whole restore refuses a file without them, unless
forced (without graph:ontology the next command reseeds the store; without graph:map it adds the bundled
map back). graph:entailed is derived: a restore of a file without it works it out afresh."""

_GZIP_MAGIC = b"\x1f\x8b"
_RDF_TYPE = ox.NamedNode("http://www.w3.org/1999/02/22-rdf-syntax-ns#type")
_PROGRESS_EVERY = 10_000  # quads between progress reports
LIVENESS = GraphName.LIVENESS


class BackupError(KnowledgeBaseError):
    """An export or restore that cannot be made; nothing was written."""

    http_status = 400


class NotAnExportError(BackupError):
    """A restore of a file that is not a whole cbrs export (``problems`` says why); ``--force`` takes it."""

    def __init__(self, source: str, problems: Sequence[str]) -> None:
        self.source = source
        self.problems = tuple(problems)
        forced = "cbrs restore --force takes it as it is, replacing the whole store"
        if not problems or not problems[0].startswith("not a cbrs export"):
            forced = "cbrs restore --force takes it as it is"
        else:  # a Turtle or N-Quads file of one's own is most often meant to be added
            forced += "; cbrs load FILE adds a file's triples to the store"
        super().__init__(f"{source}: {'; '.join(problems)}; nothing was restored ({forced})")


class UnknownExportFormatError(BackupError):
    """A file name whose extension names no export format."""

    def __init__(self, name: str) -> None:
        self.name = name
        known = ", ".join(f"{ext}, {ext}.gz" for ext in FORMATS)
        suffix = Path(name).suffix.lower()
        other = f" (a {suffix} file is no cbrs export: cbrs load adds it to the store)" if suffix in _RDF_FILES else ""
        super().__init__(f"{name}: cannot tell the format from the name; use one of {known} (or --format){other}")


_RDF_FILES = frozenset({".ttl", ".nt", ".n3", ".rdf", ".owl", ".xml", ".jsonld"})
"""Extensions of RDF files that cbrs load reads and an export never has."""


@dataclass(frozen=True)
class Manifest:
    """What an export says of itself (graph:export): written last, read first."""

    cbrs_version: str
    exported_at: str
    source: str
    triples: dict[str, int]
    """Triples per graph IRI (:data:`DEFAULT` for the default graph), as exported."""
    partial: bool = False
    """Whether only some graphs were exported (``--graph``)."""

    def quads(self) -> list[ox.Quad]:
        """The manifest as statements in :data:`EXPORT_GRAPH`."""
        export = ox.NamedNode(EXPORT + "this")
        rows: list[tuple[ox.NamedNode, str, ox.NamedNode | ox.Literal]] = [
            (export, "cbrsVersion", ox.Literal(self.cbrs_version)),
            (export, "exportedAt", ox.Literal(self.exported_at, datatype=ox.NamedNode(_XSD + "dateTime"))),
            (export, "source", ox.Literal(self.source)),
            (
                export,
                "partial",
                ox.Literal("true" if self.partial else "false", datatype=ox.NamedNode(_XSD + "boolean")),
            ),
        ]
        for number, (graph, count) in enumerate(sorted(self.triples.items()), 1):
            part = ox.NamedNode(f"{EXPORT}part-{number}")
            rows.append((export, "part", part))
            if graph == DEFAULT:
                rows.append((part, "defaultGraph", ox.Literal("true", datatype=ox.NamedNode(_XSD + "boolean"))))
            else:
                rows.append((part, "graph", ox.NamedNode(graph)))
            rows.append((part, "triples", ox.Literal(str(count), datatype=ox.NamedNode(_XSD + "integer"))))
        found = [ox.Quad(export, _RDF_TYPE, ox.NamedNode(EXPORT + "Export"), EXPORT_GRAPH)]
        found += [ox.Quad(s, ox.NamedNode(EXPORT + p), o, EXPORT_GRAPH) for s, p, o in rows]
        return found

    @classmethod
    def read(cls, quads: Iterable[ox.Quad]) -> Manifest | None:
        """The manifest in ``quads`` (those of :data:`EXPORT_GRAPH`), or None when they hold none."""
        values: dict[tuple[str, str], list[ox.NamedNode | ox.BlankNode | ox.Literal | ox.Triple]] = {}
        for quad in quads:
            values.setdefault((str(quad.subject), quad.predicate.value), []).append(quad.object)
        this = str(ox.NamedNode(EXPORT + "this"))
        if ox.NamedNode(EXPORT + "Export") not in values.get((this, _RDF_TYPE.value), []):
            return None

        def one(subject: str, name: str) -> str:
            found = values.get((subject, EXPORT + name), [])
            return found[0].value if found and isinstance(found[0], ox.Literal | ox.NamedNode) else ""

        triples: dict[str, int] = {}
        for part in values.get((this, EXPORT + "part"), []):
            graph = DEFAULT if one(str(part), "defaultGraph") == "true" else one(str(part), "graph")
            count = one(str(part), "triples")
            triples[graph] = int(count) if count.isdigit() else -1
        return cls(
            one(this, "cbrsVersion"),
            one(this, "exportedAt"),
            one(this, "source"),
            triples,
            one(this, "partial") == "true",
        )


_XSD = "http://www.w3.org/2001/XMLSchema#"


@dataclass(frozen=True)
class Backup:
    """An export file read whole: its quads by graph, and its manifest (None: the file has none)."""

    source: str
    quads: dict[str, list[ox.Quad]]
    """The file's quads by graph IRI (:data:`DEFAULT` for the default graph), the manifest's left out."""
    manifest: Manifest | None

    @property
    def triples(self) -> dict[str, int]:
        return {graph: len(quads) for graph, quads in self.quads.items()}

    def problems(self, graphs: Sequence[str] | None = None) -> list[str]:
        """Why the file is not a whole cbrs export (for ``graphs``: one that holds them), or nothing."""
        found: list[str] = []
        if self.manifest is None:  # what else it lacks is said too: --force would restore it as it is
            found.append(
                "not a cbrs export: it has no manifest (graph:export, which cbrs export writes last; "
                "a file cut short lacks it too)"
            )
        said = self.manifest.triples if self.manifest is not None else {}
        for graph in sorted(set(said) | set(self.quads)) if self.manifest is not None else ():
            held, expected = len(self.quads.get(graph, ())), said.get(graph)
            if expected is None:
                found.append(f"{_name(graph)} holds {held} triples the manifest does not list")
            elif held != expected:
                found.append(f"{_name(graph)} holds {held} triples, the manifest says {expected} (lines lost?)")
        if graphs:
            missing = [_iri(g) for g in graphs if _iri(g) not in self.quads and _iri(g) not in said]
        else:
            missing = [g.iri for g in REQUIRED if not self.quads.get(g.iri)]
        if missing:
            what = "the graphs asked for" if graphs else "cbrs's own graphs"
            found.append(f"it lacks {what} {', '.join(map(_name, missing))}")
        return found


@dataclass(frozen=True)
class ExportReport:
    """What an export wrote: triples per graph (:data:`DEFAULT`: the default graph)."""

    target: str
    rdf_format: ox.RdfFormat
    triples: dict[str, int]

    @property
    def total(self) -> int:
        return sum(self.triples.values())


@dataclass(frozen=True)
class RestoreReport:
    """What a restore replaced: the store's triples per graph before, and what it holds of the file's now."""

    source: str
    before: dict[str, int]
    restored: dict[str, int]
    entailed_refreshed: bool = False
    skipped: dict[str, int] = field(default_factory=dict)
    """Graphs of the file left out (``graphs`` chosen), by triple count."""
    live_kept: tuple[str, ...] = ()
    """Components live when the restore began, whose liveness (session, lease) it kept, not the file's."""
    live_ended: tuple[str, ...] = ()
    """Components the file held as available that no session holds now: written unavailable."""


# -- choosing graphs and formats ------------------------------------------------------------------


def export_format(name: str, given: str | None = None) -> ox.RdfFormat:
    """The format of an export file ``name`` (``-``: N-Quads unless ``given``): by its extension, a
    ``.gz`` after it allowed; ``given`` (``nquads`` or ``trig``) overrides."""
    if given is not None:
        return {"nquads": ox.RdfFormat.N_QUADS, "trig": ox.RdfFormat.TRIG}[given]
    if name == "-":
        return ox.RdfFormat.N_QUADS
    suffixes = [s.lower() for s in Path(name).suffixes]
    if suffixes and suffixes[-1] == ".gz":
        suffixes.pop()
    if not suffixes or suffixes[-1] not in FORMATS:
        raise UnknownExportFormatError(name)
    return FORMATS[suffixes[-1]]


def server_graphs(store: Store) -> frozenset[str]:
    """The graphs the server behind ``store`` keeps for itself (``ontologies/server_graphs.toml``)."""
    kind = getattr(store, "server", None)
    if kind is None:
        return frozenset()
    listed = tomllib.loads((ontology_dir() / "server_graphs.toml").read_text(encoding="utf-8"))
    return frozenset(listed.get(kind, {}).get("graphs", ()))


def store_graphs(store: Store) -> list[str]:
    """The graphs an export of the whole store takes: every named graph but the server's own, inert
    staging graphs a failed remote write left (:mod:`kb.staged_writes`), a bulk load's note and
    graph:export; then the default graph (:data:`DEFAULT`) if it holds anything."""
    own = server_graphs(store) | {EXPORT_GRAPH.value, BULK_LOADING.value}
    found = [g for g in store.graphs() if g not in own and not g.startswith(STAGING)]
    if _has_default_quads(store):
        found.append(DEFAULT)
    return found


def _has_default_quads(store: Store) -> bool:
    """Whether the default graph holds a triple of its own; asked of an embedded store and of an Oxigraph
    server only (Virtuoso's default graph is its named graphs' union, and the query a scan of them all)."""
    if getattr(store, "server", "oxigraph") != "oxigraph":
        return False
    return next(store.quads(graph=ox.DefaultGraph()), None) is not None


def _iri(graph: str) -> str:
    """A graph given as a cbrs graph name (``services``), ``graph:services``, a full IRI, or :data:`DEFAULT`."""
    if graph == DEFAULT:
        return DEFAULT
    if graph.startswith("graph:"):
        graph = GRAPH + graph.removeprefix("graph:")
    return resolve_graph(graph).value


def _name(graph: str) -> str:
    return shorten(graph) if graph else "the default graph"


def _node(graph: str) -> ox.NamedNode | ox.DefaultGraph:
    return ox.DefaultGraph() if graph == DEFAULT else ox.NamedNode(graph)


# -- export ---------------------------------------------------------------------------------------


def export_store(
    store: Store,
    target: str | Path,
    rdf_format: ox.RdfFormat | None = None,
    graphs: Sequence[str] | None = None,
    progress: Progress | None = None,
) -> ExportReport:
    """Write the store (or only ``graphs``: names, IRIs or :data:`DEFAULT`) to ``target`` (``-``: standard
    output), then the manifest. A file is written beside its name and moved into place once whole, so a
    failed export leaves no file that looks like a backup."""
    name = str(target)
    rdf_format = rdf_format or export_format(name)
    chosen = [_iri(g) for g in graphs] if graphs else store_graphs(store)
    if graphs:
        held = set(store.graphs())
        unknown = [g for g in chosen if g != DEFAULT and g not in held]
        if unknown:
            raise BackupError(f"the store has no graph {', '.join(_name(g) for g in unknown)}; nothing was exported")
    counts: Counter[str] = Counter()
    tell = progress or _quiet
    checked = not isinstance(store, EmbeddedStore)  # a server may cut an answer short: its count says so

    def quads() -> Iterator[ox.Quad]:
        for number, graph in enumerate(chosen, 1):
            stage = f"exporting {_name(graph)} ({number}/{len(chosen)})"
            tell(stage, 0, 0)
            for quad in store.quads(graph=_node(graph)):
                counts[graph] += 1
                if counts[graph] % _PROGRESS_EVERY == 0:
                    tell(f"{stage}: {counts[graph]} triples", 0, 0)
                yield quad
            if checked and graph != DEFAULT and store.count(ox.NamedNode(graph)) != counts[graph]:
                raise BackupError(
                    f"{store.location} sent {counts[graph]} of the {store.count(ox.NamedNode(graph))} triples of "
                    f"{_name(graph)} (it cuts answers short, or the store changed meanwhile); nothing was exported"
                )
        exported = {graph: counts[graph] for graph in chosen}
        stamp = datetime.datetime.now(datetime.UTC).replace(microsecond=0).isoformat().replace("+00:00", "Z")
        yield from Manifest(__version__, stamp, without_password(store.location), exported, bool(graphs)).quads()

    with _output(name) as out:
        try:
            ox.serialize(quads(), out, rdf_format, prefixes=PREFIXES if rdf_format == ox.RdfFormat.TRIG else None)
        except BrokenPipeError as error:  # `cbrs export - | head`: the reader stopped
            where = "standard output" if name == "-" else name
            raise BackupError(
                f"{where} was closed before the export ended (its reader stopped): what it got is no whole export"
            ) from error
        except OSError as error:
            raise BackupError(f"{name}: cannot write: {error.strerror or error}") from error
    return ExportReport(name, rdf_format, {graph: counts[graph] for graph in chosen})


@contextlib.contextmanager
def _output(name: str) -> Iterator[IO[bytes]]:
    """Standard output, or a file written under a temporary name and moved to ``name`` when whole."""
    if name == "-":
        yield sys.stdout.buffer
        sys.stdout.buffer.flush()
        return
    path = Path(name)
    partial = path.with_name(f".{path.name}.partial-{os.getpid()}")
    try:
        raw = partial.open("wb")
    except OSError as error:
        raise BackupError(f"{name}: cannot write: {error.strerror or error}") from error
    try:
        with raw:
            out: IO[bytes] = raw
            if path.suffix.lower() == ".gz":
                out = gzip.GzipFile(fileobj=raw, mode="wb")  # type: ignore[assignment]
            with out:
                yield out
        os.replace(partial, path)
    finally:
        partial.unlink(missing_ok=True)


def _quiet(stage: str, done: int, total: int) -> None:
    """The progress of an export or restore nobody watches."""


# -- restore --------------------------------------------------------------------------------------


def read_backup(path: str | Path, rdf_format: ox.RdfFormat | None = None, progress: Progress | None = None) -> Backup:
    """Parse an export file whole (gzip unpacked, whatever its name): nothing is written, and a parse error
    names the file and line."""
    source = str(path)
    rdf_format = rdf_format or export_format(source)
    tell = progress or _quiet
    by_graph: dict[str, list[ox.Quad]] = {}
    manifest: list[ox.Quad] = []
    seen: set[ox.Quad] = set()
    try:
        with open(source, "rb") as raw:
            data: IO[bytes] = raw
            if raw.read(2) == _GZIP_MAGIC:  # by content, not name: `cbrs export - > lab.nq.gz` is plain text
                data = gzip.GzipFile(fileobj=raw)  # type: ignore[assignment]
            raw.seek(0)
            for number, quad in enumerate(ox.parse(data, rdf_format), 1):
                if number % _PROGRESS_EVERY == 0:
                    tell(f"reading {source}: {number} quads", 0, 0)
                if quad.graph_name == EXPORT_GRAPH:
                    manifest.append(quad)
                elif quad not in seen:
                    seen.add(quad)
                    graph = quad.graph_name.value if isinstance(quad.graph_name, ox.NamedNode) else DEFAULT
                    by_graph.setdefault(graph, []).append(quad)
    except FileNotFoundError as error:
        raise RdfParseError(source, "no such file") from error
    except SyntaxError as error:  # args[0] is the parser's words alone (str() adds "(line N)" again)
        said = str(error.args[0]) if error.args else str(error)
        raise RdfParseError(source, f"{said}; nothing was restored") from error
    except (OSError, EOFError) as error:  # a broken gzip stream as well
        raise RdfParseError(source, f"cannot read: {error}; nothing was restored") from error
    return Backup(source, by_graph, Manifest.read(manifest))


def restore_store(
    store: Store,
    backup: Backup,
    graphs: Sequence[str] | None = None,
    force: bool = False,
    progress: Progress | None = None,
) -> RestoreReport:
    """Replace the store's contents with ``backup``'s in one transaction (only ``graphs``, names or IRIs,
    when given: those graphs are replaced by the file's, the rest left as they are). A file that is not a
    whole cbrs export (:meth:`Backup.problems`) is refused unless ``force``. The caller reads the store
    afresh afterwards (:meth:`KnowledgeBase.restore` does)."""
    problems = backup.problems(graphs)
    if problems and not force:
        raise NotAnExportError(backup.source, problems)
    tell = progress or _quiet
    wanted = [_iri(g) for g in graphs] if graphs else list(backup.quads)
    quads = [quad for graph in wanted for quad in backup.quads.get(graph, ())]
    embedded = isinstance(store, EmbeddedStore)
    if not embedded and (DEFAULT in wanted):
        raise BackupError(
            f"{backup.source}: the file has triples in the default graph, and a remote store is restored into "
            "named graphs only (restore the named graphs with --graph NAME); nothing was restored"
        )
    if not force:
        tell("checking the classes under cbrs's terms", 0, 0)
        check_declarations(store, backup, graphs)
    tell("counting what the store holds", 0, 0)
    present = wanted if graphs else store_graphs(store)
    # a remote store's own default-graph triples cannot be told apart in an update on a union server: left
    before = {graph: _size(store, graph) for graph in present if embedded or graph != DEFAULT}
    replacing = wanted if graphs else list(before)
    liveness = None
    if LIVENESS.iri in wanted or LIVENESS.iri in replacing:
        liveness = _liveness(store, backup, graphs)
        quads = [quad for quad in quads if quad.graph_name != LIVENESS.node] + liveness.quads
    tell(f"writing {len(quads)} triples", 0, 0)
    if isinstance(store, EmbeddedStore):  # (embedded, for the type checker)
        _replace_embedded(store, replacing, quads, whole=not graphs)
        store.flush()  # on disk before it is reported: a full disk failed the flush after "restored ..." was said
    else:
        _replace_remote(store, replacing, quads, tell)
    restored = {graph: len(backup.quads.get(graph, ())) for graph in wanted}
    skipped = {graph: len(q) for graph, q in backup.quads.items() if graph not in wanted}
    if liveness is None:
        return RestoreReport(backup.source, before, restored, skipped=skipped)
    if liveness.quads or LIVENESS.iri in wanted:
        restored[LIVENESS.iri] = len(liveness.quads)
    return RestoreReport(
        backup.source, before, restored, skipped=skipped, live_kept=liveness.kept, live_ended=liveness.ended
    )


def _liveness(store: Store, backup: Backup, graphs: Sequence[str] | None) -> Restored:
    """graph:liveness as the restore of ``backup`` writes it: the components live now keep their present
    facts, the file's leases are not taken for live ones (:meth:`kb.liveness.Liveness.restored`). A live
    component keeps them if the store describes it after the restore: in the file's graph:services when the
    restore replaces that graph, else in the store's."""
    services = GraphName.SERVICES
    if not graphs or services.iri in {_iri(graph) for graph in graphs}:
        held = {
            quad.subject.value for quad in backup.quads.get(services.iri, ()) if isinstance(quad.subject, ox.NamedNode)
        }
        described: Callable[[str], bool] = held.__contains__
    else:

        def described(iri: str) -> bool:
            return next(store.quads(ox.NamedNode(iri), graph=services.node), None) is not None

    return Liveness(store).restored(backup.quads.get(LIVENESS.iri, ()), described)


def check_declarations(store: Store | None, backup: Backup, graphs: Sequence[str] | None = None) -> None:
    """Refuse a restore of ``backup`` (only ``graphs``, when given) into ``store`` (None: there is none
    yet) that would leave a class under a term of cbrs's own vocabularies declared nowhere
    (:mod:`kb.superclasses`), as a load or an update that left the same store would be refused. A whole
    restore puts the file in place of the store: the file is checked by itself, since nothing of the store
    stays. One of some ``graphs`` replaces those alone: it is checked as the change it makes to the store,
    as a Graph Store ``PUT`` of each is (:func:`kb.superclasses.check_change`). :func:`restore_store` calls
    it unless forced; a caller may call it first, before it makes a store to restore into."""
    undone = "nothing was restored (cbrs restore --force takes the file as it is)"
    said = f"the restore of {backup.source}"
    if not graphs:
        check_whole(store, (quad for quads in backup.quads.values() for quad in quads), said, undone)
        return
    if store is None:
        return  # some graphs go into a store seeded first: checked against it, by restore_store
    wanted = [_iri(graph) for graph in graphs]
    quads = [quad for graph in wanted for quad in backup.quads.get(graph, ())]
    given = set(quads)
    replaced = [quad for graph in wanted for quad in store.quads(graph=_node(graph)) if quad not in given]
    check_change(store, replaced, quads, said, undone)


def _size(store: Store, graph: str) -> int:
    if graph == DEFAULT:
        return sum(1 for _ in store.quads(graph=ox.DefaultGraph()))
    return store.count(ox.NamedNode(graph))


def _replace_embedded(store: EmbeddedStore, graphs: Sequence[str], quads: Sequence[ox.Quad], whole: bool) -> None:
    """One SPARQL update, one transaction: the graphs dropped (all of them for a whole restore), the quads
    inserted. Blank nodes in one ``INSERT DATA`` keep their links."""
    drops = (
        ["DROP ALL"]
        if whole
        else ["DROP DEFAULT" if graph == DEFAULT else f"DROP SILENT GRAPH {ox.NamedNode(graph)}" for graph in graphs]
    )
    block = data_block(quads, blank_nodes=True)
    text = " ;\n".join(drops) + (" ;\nINSERT DATA {\n" + block + "}" if block else "")
    store._apply_own_update(text)  # ground data written by pyoxigraph's serialiser: no guard needed


def _replace_remote(store: Store, graphs: Sequence[str], quads: Sequence[ox.Quad], tell: Progress) -> None:
    """Staged, and published by one operation that empties ``graphs`` too (:mod:`kb.staged_writes`)."""
    if getattr(store, "server", None) == "virtuoso":
        from cbrs.kb.remote_store import decimal_kept  # only a remote store needs httpx

        quads = [decimal_kept(quad) for quad in quads]
    batch = getattr(store, "batch", 250)
    write_staged(
        store.location,
        quads,
        batch,
        store._apply_own_update,
        replacing=[ox.NamedNode(graph) for graph in graphs],
        progress=lambda done, total: tell("writing batch", done, total),
    )
