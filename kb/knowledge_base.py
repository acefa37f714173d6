"""The one object behind every cbrs command and page: a store with its queries and readers."""

from __future__ import annotations

import dataclasses
import functools
import logging
import re
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import AbstractContextManager, contextmanager, nullcontext
from pathlib import Path
from typing import TYPE_CHECKING, Literal

import pyoxigraph as ox

from cbrs.kb import derived_prefixes, sorting_updates
from cbrs.kb.backup import Backup, ExportReport, RestoreReport, export_store, read_backup, restore_store
from cbrs.kb.catalog import Catalogue
from cbrs.kb.descriptions import DescriptionReader
from cbrs.kb.engine_faults import sorts
from cbrs.kb.errors import QuerySyntaxError, ReplaceError, StoreError, UndeclaredSuperclassError
from cbrs.kb.graph_slips import refuse_slips
from cbrs.kb.liveness import Liveness
from cbrs.kb.loader import (
    LoadReport,
    ParsedFile,
    Progress,
    ReadFiles,
    load_files,
    parse_file,
    read_files,
    resolve_graph,
)
from cbrs.kb.model import Advertisement, PartNode, Requirement, ServiceDescription
from cbrs.kb.namespaces import GraphName
from cbrs.kb.queries import QueryLibrary
from cbrs.kb.query_guard import QueryGuard
from cbrs.kb.registry import ComponentRegistry
from cbrs.kb.resources import bundled_files, query_dir
from cbrs.kb.seed_cache import SeedCache, bundle_digest
from cbrs.kb.shapes import CHECKED_GRAPHS, DescriptionShapeError, checked_update, may_write_descriptions
from cbrs.kb.sparql_hints import explain_syntax_error
from cbrs.kb.standard_terms import PendingUpdate, Refresh, StandardTerms
from cbrs.kb.store import MEMORY, EmbeddedStore, QueryResult, Store, Term, is_remote
from cbrs.kb.superclasses import (
    Watch,
    check_data_update,
    check_watched,
    may_add_subclasses,
    may_remove_declarations,
    watch_update,
)
from cbrs.kb.update_delta import DataUpdate
from cbrs.kb.update_report import GraphChange, UpdateReport, exact_changes, graph_sizes, net_changes, refuse_split
from cbrs.kb.upgrade import StoreCheck, UpgradeReport, check_store, upgrade_store

if TYPE_CHECKING:
    from cbrs.kb.kept_robots import KeptRobots

_log = logging.getLogger(__name__)
_TYPE = ox.NamedNode("http://www.w3.org/1999/02/22-rdf-syntax-ns#type")
# An update that might write graph:map, read loosely (its name, an escape, a variable graph, ALL or NAMED):
# only such an update, and a data update that names a quad in it, has the map checked afterwards.
_MAY_WRITE_MAP = re.compile(r"map|\\[uU]|GRAPH(?:\s|#[^\n]*\n)*[?$]|\b(?:ALL|NAMED)\b", re.IGNORECASE)
# A LOAD of a quad format may write any graph the file names.
_LOADS = re.compile(r"\bLOAD\b", re.IGNORECASE)
# The graphs whose descriptions kb.shapes.checked_update checks (tests/test_standard_terms_updates.py pins
# it): a data update naming no quad in them leaves them as they are, so it skips the check, which reads
# both graphs whole twice (1.5 s a write on a store of OWLS-TC's services).


class KnowledgeBase:
    """A cbrs knowledge base. ``KnowledgeBase.open(":memory:")`` gives a seeded in-memory one."""

    def __init__(self, store: Store, queries: QueryLibrary | None = None) -> None:
        self.store = store
        self.queries = queries or QueryLibrary(query_dir())
        self.standard_terms = StandardTerms(store)
        self.registry = ComponentRegistry(store, self.standard_terms)
        self._reader = DescriptionReader(store, self.queries)
        self._map_read: tuple[int, bool] | None = None  # (store generation, whether the map read then)
        self.upgraded: UpgradeReport | None = None
        """What the last :meth:`upgrade` that changed the store did (:meth:`open` upgrades an old store and
        returns the knowledge base alone; a command says what it did)."""

    def __repr__(self) -> str:
        """Where the store is and which kind it is: a notebook showing ``kb`` said only its address in
        memory, and two stores open side by side (in memory, on disk) could not be told apart."""
        return f"<KnowledgeBase {self.store.location!r} ({type(self.store).__name__})>"

    def __enter__(self) -> KnowledgeBase:
        return self

    def __exit__(self, *exc: object) -> None:
        """:meth:`close` when the block ends, failed or not: an on-disk store's lock is held until then, so
        a notebook cell that raised between open and close left the directory locked, and opening it again
        was refused (``StoreInUseError``) until the kernel restarted."""
        self.close()

    @classmethod
    def open(
        cls,
        location: str | Path,
        seed: bool = True,
        remote_timeout: float | None = None,
        check_timeout: float | None = None,
        remote_access: tuple[str, ...] = (),
        remote_token: str | None = None,
        remote_batch: int | None = None,
        seed_cache: SeedCache | None = None,
    ) -> KnowledgeBase:
        """Open the store at ``location`` (a directory, ``:memory:`` or an endpoint URL), seeding it on first use.

        ``check_timeout`` bounds how long an embedded store's query guard checks a long text (see
        :mod:`kb.query_guard`); ``remote_access`` lists the IRI prefixes a SERVICE or LOAD may reach
        (:mod:`kb.remote_access`; none by default). ``remote_token`` goes with every request to a remote
        store, as a bearer token: a ``cbrs serve``'s update token. ``remote_batch`` is the most quads one
        write request to a remote store carries (None: chosen by the server); larger writes are staged
        (:mod:`kb.staged_writes`). A new embedded store is seeded from ``seed_cache``'s copy when it
        holds one for this bundle (:mod:`kb.seed_cache`; None: :meth:`SeedCache.default`).
        """
        remote_options = (remote_timeout, remote_token, remote_batch)
        if is_remote(str(location)) and any(option is not None for option in remote_options):
            from cbrs.kb.remote_store import DEFAULT_TIMEOUT, RemoteStore  # only a remote store needs httpx

            timeout = remote_timeout if remote_timeout is not None else DEFAULT_TIMEOUT
            store: Store = RemoteStore.open(location, timeout, remote_token, remote_batch)
        else:
            store = Store.open(location)
        store.remote_access = tuple(remote_access)
        if check_timeout is not None and isinstance(store, EmbeddedStore) and check_timeout != store.guard.timeout:
            store.guard = QueryGuard(timeout=check_timeout)
        kb = cls(store)
        if not seed:
            return kb
        check = check_store(store, kb.queries)  # one request to a remote store: seeded, upgrade, entailed
        if not check.seeded:
            kb._seed_kept(seed_cache or SeedCache.default())
            if not isinstance(store, EmbeddedStore):  # an empty server shows its default graph only now
                try:
                    store.query("ASK { ?s ?p ?o }")
                except BaseException:
                    store.close()
                    raise
        elif not kb.upgrade(check).changed and GraphName.ENTAILED not in check.holding:
            kb._entail()  # a store seeded before the alignments existed
        return kb

    def _check_map_load(
        self, paths: Sequence[str | Path], catalogue: Catalogue | None, progress: Progress | None = None
    ) -> ReadFiles | None:
        """Refuse a load into graph:map that would leave a readable semantic map unreadable (a support that
        names nothing, a misspelt property: kb.semantic_map's checks), before anything is written. Those
        checks ran only when a task read the map; by then the load was in, every run failed on it, and
        nothing but a SPARQL update could take it out again. A map that was unreadable before is no
        load's fault, and is left to the reader's error; an empty one may be built a file at a time.
        Returns the files read, for the load to write without parsing them again (None: not read)."""
        if next(iter(self.store.quads(graph=GraphName.MAP.node)), None) is None:
            return None  # a map being built from nothing may be partial until its last file
        read = read_files(paths, GraphName.MAP, catalogue, progress)
        if not self._stored_map_reads():
            return read
        problem = self._map_problem(read.quads())
        if problem is not None:
            problem.add_note(
                f"nothing was loaded from {', '.join(map(str, read.paths))} (a load into graph:map is checked as "
                "a task reads the map)"
            )
            raise problem
        return read

    def _check_new_home(
        self, paths: Sequence[str | Path], catalogue: Catalogue | None, progress: Progress | None = None
    ) -> tuple[ReadFiles, KeptRobots]:
        """Refuse files that would not make a whole home as graph:map (a load with ``replace``): the map
        they make, with the robots they keep of the stored one (:func:`kb.kept_robots.kept_robots`: all
        of them when the files describe none, placed where the files say), must read as a task reads it
        and hold what the simulated home is built from (:func:`kb.home_check.check_home`), or nothing is
        written. Unlike a load that adds, the map is whole at once, so an empty or partial one is no step
        of a build: an emptied map is the bundled one again on the next open."""
        from cbrs.kb.kept_robots import kept_robots
        from cbrs.kb.semantic_map import HOME, MapError  # it imports this module

        read = read_files(paths, GraphName.MAP, catalogue, progress)
        given = read.quads()
        kept = kept_robots(self.store.quads(graph=GraphName.MAP.node), given)
        problem = self._home_problem([*given, *kept.quads])
        if kept.unplaced is not None:  # files that give no rooms are no home at all: that is said first
            whole = self._home_problem([*given, *kept.quads, *kept.stood])
            rooms = isinstance(whole, MapError) and whole.thing == HOME + "Room"
            problem = whole if rooms else kept.unplaced
        if problem is not None:
            problem.add_note(
                f"nothing was loaded from {', '.join(map(str, read.paths))} and the map is as it was (a map "
                "that replaces the home is checked as the simulation builds it)"
            )
            raise problem
        return read, kept

    def _home_problem(self, home: Sequence[ox.Quad]) -> Exception | None:
        """Why ``home``, as the whole of graph:map, is no home the simulation can build (None: it is one),
        read with the store's ontology and the classes its things have in other graphs."""
        from cbrs.kb.home_check import check_home
        from cbrs.kb.semantic_map import MapError, SemanticMap  # they import this module

        scratch = ox.Store()
        for graph in (GraphName.ONTOLOGY, GraphName.ENTAILED):
            scratch.extend(self.store.quads(graph=graph.node))
        scratch.extend(ox.Quad(q.subject, q.predicate, q.object, GraphName.MAP.node) for q in home)
        for subject in {quad.subject for quad in home if isinstance(quad.subject, ox.NamedNode)}:
            # the class a thing of the map has where it is described (a robot's, in graph:services)
            stated = self.store.quads(subject, _TYPE, None, None)
            scratch.extend(quad for quad in stated if quad.graph_name != GraphName.MAP.node)
        try:
            check_home(SemanticMap.read(KnowledgeBase(EmbeddedStore(scratch, MEMORY), self.queries)))
        except MapError as problem:
            return problem
        return None

    def check_map_write(self, added: Sequence[ox.Quad], replaces_map: bool = False) -> None:
        """Refuse a write of ``added`` that would leave a readable semantic map unreadable, with the map
        reader's error, before anything is written: ``added`` joins the store, or (``replaces_map``) its
        quads become graph:map. A write that names no quad of graph:map, and one into an empty or already
        unreadable map, pass unread, as a load into graph:map does (:meth:`_check_map_load`). For writes
        that do not go through :meth:`load` or :meth:`update` (the Graph Store Protocol's PUT and POST)."""
        if not any(quad.graph_name == GraphName.MAP.node for quad in added):
            return  # (a map emptied by a PUT is left as an emptied one is: the next open puts the bundled one back)
        if replaces_map:  # the whole home at once, as a load with replace (:meth:`_check_new_home`)
            problem = self._home_problem([quad for quad in added if quad.graph_name == GraphName.MAP.node])
            if problem is not None:
                problem.add_note(
                    "nothing was written (a map that replaces the home is checked as the simulation builds it)"
                )
                raise problem
            return
        if next(iter(self.store.quads(graph=GraphName.MAP.node)), None) is None or not self._stored_map_reads():
            return
        problem = self._map_problem(list(added))
        if problem is not None:
            problem.add_note("nothing was written (a write into graph:map is checked as a task reads the map)")
            raise problem

    def _stored_map_reads(self) -> bool:
        """Whether the stored map reads without error, as a task reads it. An embedded store counts its
        writes (:attr:`EmbeddedStore.generation`), so the answer is kept until the next one: a load refused
        for its map, then retried with the file mended, reads the stored map once; a remote store has no
        such count, and is read each time."""
        known = self._known_map_reads()
        if known is not None:
            return known
        generation = getattr(self.store, "generation", None)
        readable = self._map_error() is None
        if generation is not None:
            self._map_read = (generation, readable)
        return readable

    def _known_map_reads(self) -> bool | None:
        """:meth:`_stored_map_reads`'s kept answer, if the store has not been written since (None: unknown)."""
        generation = getattr(self.store, "generation", None)
        if generation is not None and self._map_read is not None and self._map_read[0] == generation:
            return self._map_read[1]
        return None

    def _map_problem(self, added: list[ox.Quad]) -> Exception | None:
        """What reading the semantic map says would be wrong with it with ``added`` in the store, or None:
        read from a scratch copy, in memory, of the graphs the reader asks (ontology, map, entailed)."""
        from cbrs.kb.semantic_map import MapError, SemanticMap  # it imports this module

        scratch = ox.Store()
        for graph in (GraphName.ONTOLOGY, GraphName.MAP, GraphName.ENTAILED):
            scratch.extend(self.store.quads(graph=graph.node))
        scratch.extend(added)
        try:
            SemanticMap.read(KnowledgeBase(EmbeddedStore(scratch, MEMORY), self.queries))
        except MapError as error:
            return error
        return None

    def refresh_standard_terms(self) -> Refresh:
        """Rewrite graph:entailed: what the alignments entail in standard vocabularies (:mod:`kb.standard_terms`).
        Every write method here calls it; call it after writing to the store by other means."""
        return self.standard_terms.refresh()

    def replace_graph(self, graph: ox.NamedNode, quads: Sequence[ox.Quad]) -> None:
        """Make ``graph`` hold exactly ``quads``, in one transaction, then bring what is derived from the
        store up to date as every write here does (descriptions read again, graph:entailed): for a graph
        whose contents a caller works out itself (:mod:`kb.inferred`'s HermiT conclusions)."""
        self.store.replace_graph(graph, quads)
        self._reader.clear_cache()
        self._map_read = None
        self._entail()

    def _entail(self, update: PendingUpdate | None = None) -> Refresh | None:
        """After a write that stands: bring graph:entailed up to date, or say why it lags (None). After an
        update :meth:`StandardTerms.prepare` read, from the nodes it changed; otherwise from the whole store."""
        try:
            if update is None:
                return self.standard_terms.refresh()
            return self.standard_terms.updated(update)
        except StoreError as error:
            _log.warning("graph:entailed not brought up to date (it lags until the next write): %s", error)
            return None

    def upgrade(self, check: StoreCheck | None = None) -> UpgradeReport:
        """Bring a store seeded by an older cbrs up to the bundled ontologies and map (:mod:`kb.upgrade`):
        its conditions out of the reified form, the core vocabulary replaced, the other ontologies and the
        map merged (what the lab said of them stays, what it deleted stays deleted), the headers replaced,
        an emptied map given the bundled one. ``check``: what :func:`kb.upgrade.check_store` just found."""
        report = upgrade_store(self.store, self.queries, check)
        if report.changed:
            self.upgraded = report
            self._reader.clear_cache()
            self._map_read = None
            self._entail()
        return report

    def seed(self) -> list[ParsedFile]:
        """Load the bundled ontologies, advertisements and requirements in one transaction."""
        parsed = [parse_file(item.path, item.graph) for item in bundled_files()]
        self.store.add(quad for item in parsed for quad in item.quads)
        self._reader.clear_cache()
        self._entail()
        return parsed

    def _seed_kept(self, cache: SeedCache) -> None:
        """Seed from ``cache``'s copy of this bundle's seed, else in full and keep the result. A remote
        store is always seeded in full: its server works graph:entailed out for itself; so is a store that
        holds something already (a lab's graph loaded unseeded): its graph:entailed is worked out over what
        it holds, and what it holds is not the bundle's seed to keep (kept, it went into every later
        ``:memory:`` store of the process)."""
        if not isinstance(self.store, EmbeddedStore) or next(self.store.quads(), None) is not None:
            self.seed()
            return
        digest = bundle_digest()
        if cache.restore(digest, self.store):
            self._reader.clear_cache()
            return
        self.seed()
        cache.keep(digest, self.store)

    def load(
        self,
        paths: Sequence[str | Path],
        graph: str | GraphName | None = None,
        catalogue: Catalogue | str | Path | None = None,
        progress: Progress | None = None,
        replace: bool = False,
    ) -> LoadReport:
        """Load RDF and OWL-S files (or every RDF file of a directory) all-or-nothing; ``progress`` is told
        each stage as it goes (:data:`kb.loader.Progress`). With ``replace`` (graph:map only) the files
        become the semantic map, a lab's own home in place of the bundled one (:meth:`_check_new_home`),
        with the stored map's robots when the files describe none (:mod:`kb.kept_robots`); it may not take
        out the last statement about a term of cbrs's own a class stays under (``RemovedDeclarationError``).

        OWL-S files are converted into cbrs advertisements, or requirements when ``graph`` is
        ``requirements`` (see :mod:`kb.owls`). With a ``catalogue`` (a :class:`Catalogue`, a folder or
        a catalogue file) the ontologies the files import are loaded too, from local files only.

        ``paths`` is a list even for one file: a lone path is refused with a ``TypeError`` naming it (a
        string is a sequence too, so ``kb.load("lab.ttl")`` was read character by character and refused
        for its first one, ``"/": a directory with no RDF file in it``, a ``Path`` as not iterable).
        """
        if isinstance(paths, str | Path):
            raise TypeError(f"load takes a list of paths, not one {type(paths).__name__}: kb.load([{str(paths)!r}])")
        if catalogue is not None and not isinstance(catalogue, Catalogue):
            catalogue = Catalogue.open(catalogue)
        read = None
        into_map = graph is not None and resolve_graph(graph) == GraphName.MAP.node
        if replace and not into_map:
            raise ReplaceError(str(graph))
        kept = None
        if replace:
            read, kept = self._check_new_home(paths, catalogue, progress)
        elif into_map:
            read = self._check_map_load(paths, catalogue, progress)
        report = load_files(
            self.store,
            paths,
            graph,
            catalogue,
            progress,
            read,
            GraphName.MAP if replace else None,
            kept.quads if kept is not None else (),
        )
        if kept is not None and kept.robots:
            report.kept_robots = kept.robots
        if isinstance(self.store, EmbeddedStore) and not any(report.added.values()):
            return report  # a reload of what the store holds wrote nothing: nothing to read or entail afresh
        self._reader.clear_cache()
        if progress is not None:
            progress("updating graph:entailed", 0, 0)
        self._entail()
        return report

    def export(
        self,
        target: str | Path,
        rdf_format: ox.RdfFormat | None = None,
        graphs: Sequence[str] | None = None,
        progress: Progress | None = None,
    ) -> ExportReport:
        """Write the store (every named graph, or ``graphs``) to the file ``target`` (``-``: standard
        output) as N-Quads or TriG by its extension, with a manifest that makes it a cbrs export
        (:mod:`kb.backup`)."""
        return export_store(self.store, target, rdf_format, graphs, progress)

    def restore(
        self,
        backup: Backup | str | Path,
        graphs: Sequence[str] | None = None,
        force: bool = False,
        progress: Progress | None = None,
    ) -> RestoreReport:
        """Replace the store's contents (or only ``graphs``) with an export's, all or nothing
        (:mod:`kb.backup`); a file that is not a whole cbrs export, or that would leave a class under a term
        of cbrs's own vocabularies declared nowhere (:func:`kb.backup.check_declarations`), is refused unless
        ``force``.
        graph:entailed comes from the file, or is worked out afresh when the file does not give all of it."""
        if not isinstance(backup, Backup):
            backup = read_backup(backup, progress=progress)
        entailed = GraphName.ENTAILED
        refresh = bool(graphs) or not backup.quads.get(entailed.iri)
        was = self.store.count(entailed.node) if refresh and entailed.iri in self.store.graphs() else None
        report = restore_store(self.store, backup, graphs, force, progress)
        self._reader.clear_cache()
        self._map_read = None
        if refresh:
            if progress is not None:
                progress("updating graph:entailed", 0, 0)
            self._entail()
            # the report's graph:entailed is what it holds now, worked out afresh, and held before
            before = report.before if was is None else {**report.before, entailed.iri: was}
            now = {**report.restored, entailed.iri: self.store.count(entailed.node)}
            report = dataclasses.replace(report, before=before, restored=now, entailed_refreshed=True)
        return report

    def query(self, text: str, bindings: Mapping[str, Term] | None = None) -> QueryResult:
        """Run a SPARQL query over the union of the graphs, the table prefixes declared (``home:``,
        ``svc:``..., :data:`PREFIXES`), so a query need not know which graph holds a fact. ``bindings``
        are values for its variables, bound by the store rather than pasted into the text (nothing a user
        typed is parsed as SPARQL). Gives pyoxigraph's solutions (read them once), a boolean or triples;
        a bad text is a :class:`QuerySyntaxError` keeping the text, explained as ``cbrs query`` and the
        endpoint explain it (:func:`~cbrs.kb.sparql_hints.explain_syntax_error`: an undeclared prefix and the
        nearest, a query sent as an update...)."""
        with self._explained(text, "query"):
            return self.store.query(text, bindings)

    def update(self, text: str, check_map: bool = True) -> None:
        """Run a SPARQL update in one transaction; the cached descriptions are read afresh afterwards, and
        graph:entailed follows (node by node after a data update: :meth:`StandardTerms.prepare`).

        An update that leaves a readable semantic map unreadable is put back and refused with the map
        reader's error (:class:`kb.semantic_map.MapError`), as a load into graph:map is: else it stays in
        and every task fails on it. Only an update that may write graph:map is checked; the rest pay
        nothing for it.
        ``check_map=False`` skips the check, for a caller that builds or breaks a map on purpose (a test
        of the map reader's errors): the map's reader then says what is wrong when a task reads it.
        A bad text is a :class:`QuerySyntaxError` explained as :meth:`query`'s."""
        with self._explained(text, "update"):
            self._update(text, self._data_update(text), check_map)

    def update_counted(self, text: str) -> UpdateReport:
        """:meth:`update`, saying what it changed graph by graph (:mod:`kb.update_report`): quad by quad for
        a data update, else each graph's net change, which costs counting the graphs before and after. An
        update of several operations is refused on a store that does not run a request whole (Virtuoso), and
        one that leaves the semantic map unreadable is put back and refused, as :meth:`update` does."""
        refuse_split(self.store, text)
        with self._explained(text, "update"):
            data = self._data_update(text)
            before = graph_sizes(self.store) if data is None else None
            entailed = self._update(text, data, check_map=True)
        iri = GraphName.ENTAILED.iri
        refreshed = (
            GraphChange(iri, entailed.added - entailed.removed, entailed.added, entailed.removed)
            if entailed is not None
            else GraphChange(iri, 0, 0, 0)
        )
        if before is not None:
            after = graph_sizes(self.store)
            changes, exact = net_changes(before, after), False
            if after[iri] - before[iri] != refreshed.net:  # the update wrote it too (CLEAR ALL): its net alone
                refreshed = GraphChange(iri, after[iri] - before[iri])
        else:
            assert data is not None
            delta = data.delta(self.store)
            changes, exact = (exact_changes(*delta), True) if delta is not None else ([], False)
        if refreshed.net or refreshed.added or refreshed.removed:
            changes.append(refreshed)
        return UpdateReport(tuple(changes), exact, counted=before is not None or exact)

    @contextmanager
    def _explained(self, text: str, expected: Literal["query", "update"]) -> Iterator[None]:
        """A syntax error of ``text`` (a library caller's) explained as the endpoint explains it, the store's
        derived prefixes offered for an undeclared one (read only then). Only an embedded store's: its
        parser's words are Oxigraph's, which the explanations read; a remote store's are its server's (a
        cbrs serve's explained already)."""
        try:
            yield
        except QuerySyntaxError as error:
            if not isinstance(self.store, EmbeddedStore):
                raise
            explained = explain_syntax_error(error, text, expected, offered=lambda: derived_prefixes.for_store(self))
            if explained is error:
                raise
            raise explained from error

    def _data_update(self, text: str) -> DataUpdate | None:
        """``text`` read as an update of ground data about to run (:mod:`kb.update_delta`), on an embedded
        store; None for any other update or store."""
        return DataUpdate.read(text, self.store) if isinstance(self.store, EmbeddedStore) else None

    def _update(
        self, text: str, data: DataUpdate | None, check_map: bool, run: Callable[[], None] | None = None
    ) -> Refresh | None:
        """:meth:`update` of ``text``, read as ``data``, with the semantic map checked (``check_map``) as well
        as the descriptions; returns what graph:entailed's refresh changed (None: it lags). ``run`` carries
        it out instead of the store's own update, on a copy of a remote store that is checked and thrown
        away (:mod:`kb.remote_updates`): graph:entailed is then left alone."""
        from cbrs.kb.semantic_map import MapError  # it imports this module

        if not isinstance(self.store, EmbeddedStore):
            return self._update_remote(text, check_map)
        if data is not None:  # a class put under a home: term nobody declares (or left so), as a load refuses it
            refuse_slips(quad.graph_name for quad in data.named)  # graph#map for graph/map: kb/graph_slips.py
            check_data_update(self.store, data.operations)
        pending = self.standard_terms.prepare(data) if run is None else None
        checking: AbstractContextManager[None] = nullcontext()
        before = self._map_before_update(text, data) if check_map else None
        old_map = before.quads if before is not None else None
        everything: set[ox.Quad] | None = None  # the store before, kept here to put back whatever it wrote
        watch: Watch | None = None  # its superclasses, when the update may change them (kb/superclasses.py)
        keep = data is not None  # whether a refused update is undone whole (a data update undoes itself)
        if data is None:  # what else it writes is unknown: keep the whole store if it might be refused
            described = may_write_descriptions(text) or _LOADS.search(text) is not None
            embedded = isinstance(self.store, EmbeddedStore)
            if embedded:  # checked once it ran: kb/superclasses.py
                watch = watch_update(self.store, text)
            keep = embedded and (old_map is not None or described or watch is not None)
            if keep and (old_map is not None or watch is not None):  # one copy for every check
                everything = set(self.store.quads())
            if described:  # else it cannot reach them: the check read both graphs twice for nothing
                checking = checked_update(self.store, keep and everything is None)  # kb/shapes.py puts back
        elif data.names_graph(CHECKED_GRAPHS):
            checking = checked_update(self.store)
        try:
            with checking:
                (run or self._runner(text, data))()
            if watch is not None:
                check_watched(self.store, watch)
            if old_map is not None:
                self._check_updated_map(old_map)
        except UndeclaredSuperclassError:
            self._put_back(everything, None)  # all it wrote: its message says nothing was
            raise
        except (DescriptionShapeError, MapError) as error:
            unasked = isinstance(error, MapError) and before is not None and not before.read
            after = set(self.store.quads()) if unasked and data is None else None  # to redo it, if it stands
            if data is not None:
                data.undo(self.store)  # its writes to the other graphs go too: all or nothing
            else:
                self._put_back(everything, old_map)
            if not unasked or self._stored_map_reads():
                error.add_note(_refused(isinstance(error, MapError)))
                raise
            self._redo(text, data, everything, after)  # the map did not read before either: the update stands
        finally:
            self._reader.clear_cache()
        return self._entail(pending) if run is None else None

    def _runner(self, text: str, data: DataUpdate | None) -> Callable[[], None]:
        """What runs ``text`` on the embedded store: its own update, or, for a text that may sort, a child
        process on a copy of it whose effect is written here as data (:mod:`kb.sorting_updates`), since the
        engine aborts the process on some sorts. A data update has no ``WHERE`` to sort in."""
        assert isinstance(self.store, EmbeddedStore)
        if data is None and sorts(text):
            return functools.partial(sorting_updates.update, self.store, text)
        return functools.partial(self.store.update, text)

    def _update_remote(self, text: str, check_map: bool) -> Refresh | None:
        """:meth:`_update` on a remote store: an update the embedded store would check is carried out first
        on a copy of the store, through the same checks, and only the change it made there is sent; a
        refused one sends nothing (:mod:`kb.remote_updates`). Any other is sent as it is, and so is every
        update to a ``cbrs serve`` that says it checks them (:attr:`RemoteStore.checks_updates`): it runs the
        same checks on its own store, all or nothing, refuses in the same words (:mod:`kb.served_updates`)
        and brings graph:entailed up to date itself, so a copy of the store would be read for nothing."""
        from cbrs.kb.remote_store import RemoteStore
        from cbrs.kb.remote_updates import CheckedCopy

        assert isinstance(self.store, RemoteStore)
        if self.store.checks_updates:
            try:
                self.store.update(text)
            finally:
                self._reader.clear_cache()
            return None
        data = DataUpdate.read(text, EmbeddedStore(ox.Store(), MEMORY))  # only read: which quads it names
        if data is not None:
            on_map = check_map and data.names_graph((GraphName.MAP.node,))
            checked = on_map or data.names_graph(CHECKED_GRAPHS)
            if not checked:  # no copy needed: the superclasses are read from the store itself
                check_data_update(self.store, data.operations)
        else:
            on_map = check_map and _MAY_WRITE_MAP.search(text) is not None
            checked = on_map or may_write_descriptions(text) or _LOADS.search(text) is not None
            checked = checked or may_add_subclasses(text) or may_remove_declarations(self.store, text)
        try:
            if not checked:
                self.store.update(text)
            else:
                copy = CheckedCopy(self.store)
                scratch, read = KnowledgeBase(copy.store, self.queries), DataUpdate.read(text, copy.store)
                scratch._update(text, read, check_map, run=functools.partial(copy.run, text))
                copy.send(self.store, text, read)
        finally:
            self._reader.clear_cache()
        return self._entail(None)

    def _redo(
        self, text: str, data: DataUpdate | None, before: set[ox.Quad] | None, after: set[ox.Quad] | None
    ) -> None:
        """Write again an update undone for the map it left unreadable, once the map proved unreadable before
        it too: a data update by running it again, another by putting back what it left (``after``)."""
        if data is not None:
            self.store.update(text)
        elif before is not None and after is not None:
            self.store.replace(before - after, after - before)

    def _map_before_update(self, text: str, data: DataUpdate | None) -> _MapBefore | None:
        """graph:map before an update that may write it (an update is checked as a load into graph:map is:
        :meth:`_check_map_load`); None: nothing to check, the map being empty (being built) or known not to
        read (left to the reader's error). Whether it reads is asked only if the update leaves it unreadable
        (the update undone first, and redone if the map did not read before either), so an update that leaves
        it readable reads it once, not twice."""
        may = data.names_graph((GraphName.MAP.node,)) if data is not None else bool(_MAY_WRITE_MAP.search(text))
        if not may:
            return None
        quads = set(self.store.quads(graph=GraphName.MAP.node))
        if not quads:
            return None
        known = self._known_map_reads()
        return None if known is False else _MapBefore(quads, read=known is True)

    def _check_updated_map(self, old_map: set[ox.Quad]) -> None:
        """Raise the semantic map's error when the update just run left graph:map unreadable (an emptied map
        is left: the next open puts the bundled one back)."""
        now = set(self.store.quads(graph=GraphName.MAP.node))
        if now == old_map or not now:
            return
        problem = self._map_error()
        if problem is not None:
            if stranded := _stranded(old_map, now):
                problem.add_note(stranded)
            raise problem

    def _map_error(self) -> Exception | None:
        """What reading the stored map says is wrong with it, read as a task reads it (a scratch copy of its
        graphs, as a load's check makes, took 0.4 s of the 0.45 s on a store of OWLS-TC's size), or None."""
        from cbrs.kb.semantic_map import MapError, SemanticMap  # it imports this module

        try:
            SemanticMap.read(self)
        except MapError as error:
            return error
        return None

    def _put_back(self, everything: set[ox.Quad] | None, old_map: set[ox.Quad] | None) -> None:
        """Undo a refused update that was not data: all it wrote when the store was kept (``everything``),
        else graph:map's part (kb/shapes.py has put back the descriptions' part)."""
        graphs: tuple[ox.NamedNode, ...] | None = None if everything is not None else (GraphName.MAP.node,)
        before = everything if everything is not None else old_map
        if before is None:
            return
        now = set(self.store.quads()) if graphs is None else set(self.store.quads(graph=graphs[0]))
        if now != before:
            self.store.replace(now - before, before - now)  # one transaction

    def run(self, name: str, values: Mapping[str, Term | str | int | float] | None = None) -> QueryResult:
        """Run the named query ``queries/<name>.rq`` with ``values`` bound to its parameters."""
        return self.queries.run(self.store, name, values)

    def select(self, name: str, values: Mapping[str, Term | str | int | float] | None = None) -> list[dict[str, Term]]:
        """:meth:`run`'s solutions as a list of dicts, variable name to term: read as often as needed,
        unlike the store's solutions. ``values`` are checked against the query's declared parameters (an
        unknown name or a value of the wrong kind is a :class:`BindingError`, an unknown query an
        :class:`UnknownQueryError` listing the known ones); ``kb.queries.names()`` lists them."""
        return self.queries.select(self.store, name, values)

    def select_each(
        self, names: Sequence[str], values: Mapping[str, Term | str | int | float] | None = None
    ) -> list[list[dict[str, Term]]]:
        """:meth:`select` of each of ``names`` with the same ``values`` (none: every value), asked for at
        once: one request to a remote store instead of one per query."""
        return self.queries.select_each(self.store, [(name, values or {}) for name in names])

    def description(self, iri: str) -> ServiceDescription:
        """The six-tuple of the advertisement or requirement ``iri`` (a full IRI) as typed values, read
        through the named queries and cached until the store changes; a :class:`NotFoundError` when the
        store describes no such service."""
        return self._reader.read(iri)

    def advertisements(self, include_unavailable: bool = False) -> list[Advertisement]:
        """The advertisements; those of live components that cannot be invoked now (their session
        closed or their lease lapsed, :mod:`kb.liveness`) only with ``include_unavailable``."""
        found = self._reader.advertisements()
        if include_unavailable:
            return found
        gone = self.liveness.unavailable()
        return [ad for ad in found if ad.iri not in gone] if gone else found

    @property
    def liveness(self) -> Liveness:
        """The live components' availability and leases."""
        return Liveness(self.store)

    def requirements(self) -> list[Requirement]:
        """Every requirement (a robot's request or a task) the store describes, as typed values."""
        return self._reader.requirements()

    def action_requirement(self, action: str, label: str | None = None) -> Requirement:
        """The inputs, outputs, preconditions and effects of an action class, as a requirement."""
        return self._reader.read_action(action, label)

    def part_tree(self, concept: str) -> PartNode:
        """The hasPart tree of ``concept`` (its own and inherited parts), as advertisements carry them."""
        return self._reader.part_tree(concept)

    def statistics(self) -> dict[str, int]:
        """Triples per named graph."""
        return {row["graph"].value: int(row["triples"].value) for row in self.select("graph_statistics")}

    def describes(self, iri: str) -> bool:
        """Whether ``iri`` occurs in the store at all."""
        node = ox.NamedNode(iri)
        return any(True for _ in self.store.quads(node)) or any(True for _ in self.store.quads(None, None, node))

    def close(self) -> None:
        """Release the store: an on-disk one is flushed and its lock freed, so that another process (or a
        later :meth:`open` here) can open it; using this object afterwards raises :class:`StoreError`.
        Closing twice does nothing. ``with KnowledgeBase.open(...) as kb:`` closes it when the block ends."""
        self.store.close()


@dataclasses.dataclass(frozen=True)
class _MapBefore:
    """graph:map's quads before an update, and whether they were read (and read without error) then."""

    quads: set[ox.Quad]
    read: bool


_LOCATED_ON = ox.NamedNode("https://w3id.org/cbrs/home#isLocatedOn")


def _stranded(before: set[ox.Quad], after: set[ox.Quad]) -> str:
    """What an update that deleted every statement of a thing the map's things stand on left standing on
    it, said after the reader's error (which can only call the support nothing in the map, and guess a name
    near it): a lab replacing a piece of furniture must re-point them in the same update."""
    left = {quad.subject for quad in after}
    gone = {quad.subject for quad in before} - left
    on: dict[str, list[str]] = {}
    for quad in after:
        if quad.predicate == _LOCATED_ON and quad.object in gone and isinstance(quad.object, ox.NamedNode):
            subject = quad.subject.value if not isinstance(quad.subject, ox.Triple) else str(quad.subject)
            on.setdefault(quad.object.value, []).append(subject.rsplit("#", 1)[-1])
    return "; ".join(
        f"the update deleted every statement of {support}, and {', '.join(sorted(things))} still stand on it "
        "(home:isLocatedOn): in the same update, delete those and insert what replaces it (DELETE { ?thing "
        "home:isLocatedOn OLD } INSERT { ?thing home:isLocatedOn NEW } WHERE { ?thing home:isLocatedOn OLD }, as "
        "docs/examples/lab9_new_kitchen_table.ru does)"
        for support, things in sorted(on.items())
    )


def _refused(map_error: bool) -> str:
    """What a refused update left: nothing (a remote store's is refused on a copy, before it is sent)."""
    return "nothing was changed" + (" (an update of graph:map is checked as a task reads the map)" * map_error)
