"""The Oxigraph store behind cbrs: embedded (on disk or in memory) or a SPARQL server.

``Store`` is the one interface the knowledge base talks to; ``Store.open`` picks the backend from the
location: ``http://`` and ``https://`` URLs reach a SPARQL 1.1 endpoint (:mod:`kb.remote_store`),
anything else is a directory or ``:memory:`` for the embedded :class:`EmbeddedStore`.

Every write is one transaction, so a write that fails leaves the store as it was.
"""

from __future__ import annotations

import functools
import hashlib
import logging
import os
import re
from abc import ABC, abstractmethod
from collections import defaultdict
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from pathlib import Path

import pyoxigraph as ox

from cbrs.kb.errors import BlankNodeInsertError, QuerySyntaxError, StoreError, StoreEvaluationError
from cbrs.kb.namespaces import BASE, GENID, GRAPH, PREFIXES, GraphName
from cbrs.kb.query_guard import QueryGuard
from cbrs.kb.recent_keys import RecentKeys
from cbrs.kb.remote_access import loads, refuse_remote_access
from cbrs.kb.results import releases_results
from cbrs.kb.sparql_lexemes import HIDING

log = logging.getLogger(__name__)

MEMORY = ":memory:"
REMOTE_SCHEMES = ("http://", "https://")

MAX_NESTING = 256
"""The deepest bracket nesting a query or update may have: a quick, clear refusal of the commonest deep
text. It is not what keeps the process alive (other constructs recurse as deeply without brackets);
:mod:`kb.query_guard` is."""

# What can hide a bracket (strings, IRIs, comments) or is one; anything else is skipped.
_LEXEME = re.compile(HIDING + r"|[(){}\[\]]", re.DOTALL)
# The same, with keywords and blank node labels: what an INSERT template is read with.
_TEMPLATE_LEXEME = re.compile(HIDING + r"|_:[\w.-]*|[A-Za-z]+|[{}\[]", re.DOTALL)

CHECKED_TEXTS = 1024
"""How many query texts that passed :meth:`EmbeddedStore.check_query` a store remembers (least recently
used first out), so that a client asking the same text again skips its scans: a text of a few kilobytes
costs them a tenth to a third of a millisecond. A text is known by a 16-byte digest of its every
character and the store's allowed remote prefixes, so a text differing by one byte is checked afresh;
one that failed is never remembered."""

BULK_LOADING = ox.NamedNode(GRAPH + "bulk-loading")
"""The graph that, while a bulk load runs, names the graph it writes (``cbrs:bulkLoadOf``): a store
opened with a note there was killed mid-load, and the graph named is dropped (it was empty before)."""
_BULK_LOAD_OF = ox.NamedNode(BASE + "core#bulkLoadOf")

Term = ox.NamedNode | ox.BlankNode | ox.Literal
QueryResult = ox.QuerySolutions | ox.QueryBoolean | ox.QueryTriples


_GRAPH = ox.Variable("g")
_GRAPH_SIZE = "SELECT ?g (COUNT(*) AS ?n) WHERE { GRAPH ?g { ?s ?p ?o } } GROUP BY ?g"

_REMOVED = ox.NamedNode("urn:cbrs:exchange:removed")
_ADDED = ox.NamedNode("urn:cbrs:exchange:added")
_APPLY = """{operation} {{ GRAPH ?g {{ ?s ?p ?o }} ?ds ?dp ?do }} WHERE {{
  VALUES ?row {{ {rows} }}
  BIND (<{f}>(?row, 0) AS ?s) BIND (<{f}>(?row, 1) AS ?p) BIND (<{f}>(?row, 2) AS ?o) BIND (<{f}>(?row, 3) AS ?g)
  BIND (<{f}>(?row, 4) AS ?ds) BIND (<{f}>(?row, 5) AS ?dp) BIND (<{f}>(?row, 6) AS ?do)
}}"""
"""One operation writing the quads of a list: row ``?row`` is the list's quad, terms 0 to 3 bound for a quad
of a named graph, 4 to 6 for one of the default graph (a template triple with an unbound variable is left
out). Only row numbers are written into the text; the terms come from the custom function ``f``."""
_Term = ox.NamedNode | ox.BlankNode | ox.Literal | ox.Triple
_TermOfRow = Callable[[ox.Literal, ox.Literal], _Term | None]
"""A custom function of :data:`_APPLY`: term ``position`` of the quad of row ``row`` (None: unbound)."""


class Store(ABC):
    """A cbrs store: an RDF dataset with the cbrs named graphs.

    Queries see the union of all graphs as their default graph, so a query need not know which
    graph holds a fact; ``GRAPH`` still addresses one graph.
    """

    location: str
    remote_access: tuple[str, ...] = ()
    """IRI prefixes a SERVICE or LOAD may reach (:mod:`kb.remote_access`); none by default."""
    failure: StoreError | None = None
    """The disk error the last write (or snapshot) of this store met, until one succeeds again: what a
    health check reports, since a full disk fails every write and every heavy query of a server that
    otherwise answers (:class:`StoreDiskError`)."""

    @classmethod
    def open(cls, location: str | Path) -> Store:
        """Open the store at ``location``: a SPARQL endpoint URL, a directory (created if needed), or ``:memory:``."""
        text = _location_text(location)
        if is_remote(text):
            from cbrs.kb.remote_store import RemoteStore  # only a remote store needs the HTTP client

            return RemoteStore.open(text)
        return EmbeddedStore.open(text)

    @property
    def in_memory(self) -> bool:
        return False

    # -- reading ---------------------------------------------------------------------------

    @abstractmethod
    def query(self, text: str, bindings: Mapping[str, Term] | None = None) -> QueryResult:
        """Run a SPARQL query with ``bindings`` bound to its variables (never pasted into the text as such)."""

    @abstractmethod
    def quads(
        self,
        subject: ox.NamedNode | ox.BlankNode | None = None,
        predicate: ox.NamedNode | None = None,
        object: Term | None = None,
        graph: ox.NamedNode | ox.DefaultGraph | None = None,
    ) -> Iterator[ox.Quad]:
        """The quads matching a pattern; ``None`` matches anything (in any graph, for ``graph``)."""

    def contains(self, quad: ox.Quad) -> bool:
        """Whether the store holds ``quad`` (in its graph: the default graph only for a default-graph quad).

        Looked up by pattern here, a request for a remote store, so that the store matches a literal as it
        keeps it (``"0.0"^^xsd:decimal`` is kept as ``"0"``, which would not compare equal); a quoted
        triple or a blank graph name, which a pattern cannot fix, is compared against what the rest of
        the pattern matches."""
        subject, obj, graph = quad.subject, quad.object, quad.graph_name
        fixed_subject = None if isinstance(subject, ox.Triple) else subject
        fixed_object = None if isinstance(obj, ox.Triple) else obj
        fixed_graph = None if isinstance(graph, ox.BlankNode) else graph
        found = self.quads(fixed_subject, quad.predicate, fixed_object, fixed_graph)
        if (fixed_subject, fixed_object, fixed_graph) == (subject, obj, graph):
            return next(found, None) is not None
        return any(match == quad for match in found)

    def contains_each(self, quads: Sequence[ox.Quad]) -> list[bool]:
        """Whether the store holds each of ``quads``, as :meth:`contains` says: for a caller that asks of
        many at once (the loader asks of every triple it read), which a remote store answers with one
        query per chunk of them instead of a request per quad."""
        return [self.contains(quad) for quad in quads]

    def select_each(self, queries: Sequence[tuple[str, Mapping[str, Term]]]) -> list[list[dict[str, Term]]]:
        """The rows of each SELECT query with its bindings (as :meth:`query` binds them), each row a dict
        from variable name to term, unbound variables left out: for a caller that needs several answers
        at once, which a remote store asks for in one request instead of one per query."""
        return [solution_rows(self.query(text, bindings)) for text, bindings in queries]

    @abstractmethod
    def count(self, graph: GraphName | ox.NamedNode | None = None) -> int:
        """The number of quads in ``graph``, or in the whole dataset."""

    @abstractmethod
    def graphs(self) -> list[str]:
        """The named graphs' IRIs, sorted."""

    @abstractmethod
    def is_seeded(self) -> bool:
        """Whether the ontology graph holds anything (the bundled data was loaded and not deleted)."""

    def dump(self, rdf_format: ox.RdfFormat = ox.RdfFormat.N_QUADS) -> bytes:
        """The whole dataset, serialised; N-Quads sorted, so two dumps compare byte for byte."""
        if rdf_format == ox.RdfFormat.N_QUADS:
            lines = sorted(str(quad) + " .\n" for quad in self.quads())
            return "".join(lines).encode("utf-8")
        return ox.serialize(list(self.quads()), format=rdf_format, prefixes=PREFIXES) or b""

    # -- writing ---------------------------------------------------------------------------

    @abstractmethod
    def add(self, quads: Iterable[ox.Quad]) -> None:
        """Add ``quads`` in one transaction."""

    def replace(self, remove: Iterable[ox.Quad], add: Iterable[ox.Quad]) -> None:
        """Remove and add quads in one transaction.

        One SPARQL update is one transaction (in Oxigraph, embedded or served). The quads go into the
        update as ground data blocks written by Oxigraph's own term serialiser (the term constructors
        have validated every IRI and escape every literal), so no caller-supplied text reaches the
        update; blank nodes are refused, since a data block cannot name them (the loader skolemises
        them).
        """
        removing = data_block(remove)
        adding = data_block(add)
        parts = []
        if removing:
            parts.append("DELETE DATA {\n" + removing + "}")
        if adding:
            parts.append("INSERT DATA {\n" + adding + "}")
        if parts:
            self._apply_own_update(" ;\n".join(parts))

    def replace_graph(self, graph: ox.NamedNode, quads: Iterable[ox.Quad]) -> None:
        """Make ``graph`` hold exactly ``quads`` (which must be in it), in one update operation: what the
        graph held is not read first, so it costs one request on a remote store, and a statement another
        client added to it meanwhile goes too (the graph is replaced, not patched).

        The new statements are a template whose predicates are variables that only the ``UNION``'s second
        branch binds, once: so they are written once, not once per old statement, and the text names no
        graph but ``graph`` (after an update with a variable graph, a cbrs server checks its map)."""
        quads = list(quads)
        if any(quad.graph_name != graph for quad in quads):
            raise ValueError(f"replace_graph({graph}) was given a quad of another graph")
        data_block(quads)  # refuses blank nodes, which a template would make fresh
        if not quads:  # an empty template and branch, which Virtuoso 7 refuses
            self.clear_graph(graph)
            return
        names = {predicate: f"?cbrs__p{n}" for n, predicate in enumerate(sorted({q.predicate for q in quads}, key=str))}
        template = "".join(f"{q.subject} {names[q.predicate]} {q.object} .\n" for q in quads)
        binds = " ".join(f"BIND ({predicate} AS {name})" for predicate, name in names.items())
        self._apply_own_update(
            f"DELETE {{ GRAPH {graph} {{ ?s ?p ?o }} }}\nINSERT {{ GRAPH {graph} {{\n{template}}} }}\n"
            f"WHERE {{ {{ GRAPH {graph} {{ ?s ?p ?o }} }} UNION {{ {binds} }} }}"
        )

    def clear_graph(self, graph: ox.NamedNode) -> None:
        """Empty one named graph, blank nodes included (which a data block cannot name), in one transaction."""
        self._apply_own_update(f"DROP SILENT GRAPH {graph}")  # the IRI as Oxigraph's serialiser writes it

    def _apply_own_update(self, text: str) -> None:
        """Run an update cbrs wrote itself from validated terms (flat data blocks)."""
        self.update(text)

    @abstractmethod
    def update(self, text: str) -> None:
        """Run a SPARQL update in one transaction."""

    @abstractmethod
    def flush(self) -> None:
        """Make every write durable."""

    @abstractmethod
    def close(self) -> None:
        """Release the store; using it afterwards raises :class:`StoreError`."""


@functools.cache
def bundled_query_texts() -> frozenset[str]:
    """The query texts cbrs ships: the named queries (``queries/*.rq``) as :class:`kb.queries.QueryLibrary`
    runs them, and those that work out graph:entailed (:mod:`kb.standard_terms`, its rules from the
    bundled alignments), which run after every load and update."""
    from cbrs.kb import standard_terms
    from cbrs.kb.resources import query_dir

    named = {path.read_text(encoding="utf-8") for path in query_dir().glob("*.rq")}
    return frozenset(named | set(standard_terms.OWN_QUERIES) | set(standard_terms.rules()))


@releases_results
def solution_rows(result: QueryResult) -> list[dict[str, Term]]:
    """A SELECT query's rows as dicts from variable name to term, unbound variables left out."""
    if not isinstance(result, ox.QuerySolutions):
        raise TypeError("not a SELECT query")
    names = [variable.value for variable in result.variables]
    return [{name: row[name] for name in names if row[name] is not None} for row in result]


def nesting_depth(text: str) -> int:
    """The deepest nesting of ``(``, ``{`` and ``[`` in SPARQL ``text``, outside strings, IRIs and comments."""
    depth = deepest = 0
    for match in _LEXEME.finditer(text):
        token = match.group()
        if token in "({[":
            depth += 1
            deepest = max(deepest, depth)
        elif token in ")}]":
            depth = max(depth - 1, 0)
    return deepest


def refuse_deep_nesting(text: str) -> None:
    """Raise :class:`QuerySyntaxError` for text nested deeper than :data:`MAX_NESTING`, before a parser sees it."""
    depth = nesting_depth(text)
    if depth > MAX_NESTING:
        raise QuerySyntaxError(
            text, f"brackets nested {depth} deep; at most {MAX_NESTING} levels are accepted (kb.store.MAX_NESTING)"
        )


def refuse_inserted_blank_nodes(text: str) -> None:
    """Raise :class:`BlankNodeInsertError` for an update that would insert a blank node (``_:x`` or ``[...]``
    in an ``INSERT`` or ``INSERT DATA`` block). cbrs names every node it stores (the loader skolemises
    them) so that a description can be read, addressed and deleted; a blank node inserted by an update
    can be none of these. ``WHERE`` and ``DELETE`` patterns may use them."""
    tokens = [m.group() for m in _TEMPLATE_LEXEME.finditer(text) if not m.group().startswith("#")]
    depth = 0
    inserting = False
    for token in tokens:
        if depth == 0 and token.upper() == "INSERT":
            inserting = True
            continue
        if token == "{":
            depth += 1
        elif token == "}":
            depth = max(depth - 1, 0)
            if depth == 0:
                inserting = False
        elif inserting and depth > 0 and (token.startswith("_:") or token == "["):
            raise BlankNodeInsertError(text, token if token.startswith("_:") else "[ ... ]")


def is_remote(location: str) -> bool:
    """Whether ``location`` names a SPARQL endpoint rather than a directory."""
    return location.strip().lower().startswith(REMOTE_SCHEMES)


# What reads as a server rather than a directory: another scheme's URL, or a host and port.
_OTHER_SCHEME = re.compile(r"^[A-Za-z][A-Za-z0-9+.-]*://")
_HOST_PORT = re.compile(r"^(?:\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9._-]+):\d{1,5}(?:/\S*)?$")


def _location_text(location: object) -> str:
    """``location`` as text, refusing what names no store: ``KnowledgeBase.open(None)`` made and seeded a
    store in a directory called ``None``, and ``""`` opened one in the working directory."""
    if not isinstance(location, str | os.PathLike):
        raise TypeError(
            f"a store's location is a directory, ':memory:' or an endpoint URL (str or Path), not {location!r}"
        )
    text = os.fspath(location)
    if not isinstance(text, str) or not text.strip():
        raise StoreError(repr(text), "names no store: give a directory, ':memory:' or an endpoint URL")
    return text


def _refuse_url_like(text: str, path: Path) -> None:
    """A location that reads as a server but is no directory yet is refused, not created: with
    ``--store localhost:7878`` (``http://`` left out) a new store was made and seeded in the working
    directory, and every command answered from it as if from the server. An existing directory of
    that name opens; ``./localhost:7878`` makes one on purpose."""
    if path.exists():
        return
    if _OTHER_SCHEME.match(text):
        raise StoreError(text, "is a URL cbrs cannot use: a remote store is an http:// or https:// URL")
    if _HOST_PORT.match(text):
        raise StoreError(
            text,
            f"reads as a server's host and port, and no such directory exists: give the URL, http://{text}, "
            f"or ./{text} for a new store directory of that name",
        )


class StoreInUseError(StoreError):
    """Another process holds an on-disk store's lock (RocksDB's: one process at a time). ``served``: the URL
    a cbrs server serving the directory wrote into it (None: no server's), which a caller opens instead;
    ``cause``: the lock's own message. Advice for a program, in its terms; the CLI words its own
    (``cbrs.app``)."""

    def __init__(self, location: str, served: str | None, cause: str) -> None:
        self.served = served
        self.cause = cause
        hint = (
            f"a cbrs server serves it: open it by the server's URL, KnowledgeBase.open({served!r}, "
            "remote_token=...) with the server's update token for writes"
            if served
            else "stop that process, or open another store"
        )
        holder = "another process"
        if "current process" in cause:  # RocksDB's words for a lock this process holds: a KnowledgeBase open here
            holder = "this process"  # a server in this process (a test's, a notebook's) keeps its URL's advice
            if not served:
                hint = "close the KnowledgeBase that has it open (kb.close(), or a with block)"
        super().__init__(location, f"is in use by {holder} (RocksDB lock held); {hint} ({cause})")


# What the engine's IO errors say when the store's disk, not the request, is at fault, and what to do.
_DISK_CAUSES = (
    ("No space left on device", "its disk is full: free space on it"),
    ("Disk quota exceeded", "the disk quota is used up: free space or raise the quota"),
    (
        "Read-only file system",
        "its file system is read-only: cbrs opens a store for writing even to read it (RocksDB writes its "
        "LOG and LOCK files), so copy the directory somewhere writable (cp -a) and open the copy",
    ),
)
# Only when opening: a write's "Permission denied" may be an allowed LOAD's file, the request's fault.
_OPEN_CAUSES = (
    ("Permission denied", "permission denied: the directory and its files must be writable by the user cbrs runs as"),
)


class StoreDiskError(StoreError):
    """The store's disk refused a write: full, read-only or not ours. ``cause`` is the engine's message,
    ``advice`` what to do about it. HTTP 507 Insufficient Storage: the request was fine, the server could
    not keep it."""

    http_status = 507

    def __init__(self, location: str, doing: str, advice: str, cause: str, after: str) -> None:
        self.doing = doing
        self.advice = advice
        self.cause = cause
        super().__init__(location, f"{doing} failed: {advice}{after} ({cause})")


def disk_error(
    location: str, doing: str, error: OSError, after: str = "", causes: tuple[tuple[str, str], ...] = _DISK_CAUSES
) -> StoreDiskError | None:
    """``error`` as a :class:`StoreDiskError` when the disk is at fault (the engine's message names one of
    ``causes``), else None; ``after`` is what the caller adds to the advice (what was kept, what to do)."""
    text = str(error)
    for said, advice in causes:
        if said in text:
            return StoreDiskError(location, doing, advice, text, after)
    return None


_RESTART = (
    "; RocksDB takes no further writes in this process after a failed one, so once the disk is fixed "
    "restart the process that holds the store (cbrs serve)"
)
_WRITE_FAILED = "; nothing of this write was kept, what was committed before is" + _RESTART
_SNAPSHOT_FAILED = "; the query was not run, and the store is as it was" + _RESTART
"""What a write (or a query's snapshot) that met a disk error adds: seen on a full disk, every later
write and snapshot failed until the store was opened again, space freed or not (docs/serving.md, "Tried
by a lab's system administrator")."""


class EmbeddedStore(Store):
    """An Oxigraph store in this process, on disk or in memory.

    Every query and update text passes :attr:`guard` first, so that no text can crash the process
    (see :mod:`kb.query_guard`); the texts cbrs writes itself (:meth:`replace`) are flat and skip it.
    """

    guard = QueryGuard()  # one per process: its checker processes serve every store
    checked_texts = CHECKED_TEXTS  # texts remembered as passing check_query (0: none)

    def __init__(self, backend: ox.Store, location: str) -> None:
        self._open: ox.Store | None = backend
        self.location = location
        self.generation = 0
        """Counts the writes made through this object, so a snapshot knows whether it is current."""
        self.on_failure: Callable[[StoreDiskError], None] | None = None
        """Told of the first disk error after a success: ``cbrs serve`` logs it, since the client whose
        request failed is told and nobody else is (a command raises it to its user instead)."""
        self._checked = RecentKeys()

    @property
    def _backend(self) -> ox.Store:
        if self._open is None:
            raise StoreError(self.location, "is closed")
        return self._open

    def close(self) -> None:
        """Flush and release the store (and its on-disk lock) even if this object lives on. A flush the disk
        refuses is logged, not raised: what was committed is in the write-ahead log, and the next open
        replays it (a full disk made every command that had written end in "internal error" before)."""
        if self._open is not None:
            told = self.failure is not None  # a write that failed so raised to its caller already
            try:
                self.flush()
            except StoreDiskError as error:  # the write-ahead log keeps every committed write
                if not told and self.on_failure is None:
                    log.error("%s", error)  # nobody heard of it: a command would end without a word
            finally:
                self._open = None  # the lock goes with the engine, flushed or not

    @classmethod
    def open(cls, location: str | Path) -> EmbeddedStore:
        """Open (creating if needed) the store at ``location``: a directory, or ``:memory:``."""
        text = _location_text(location)
        if text == MEMORY:
            return cls(ox.Store(), MEMORY)
        if is_remote(text):
            raise StoreError(text, "is a SPARQL endpoint, not a directory; open it with Store.open")
        path = Path(text).expanduser()
        _refuse_url_like(text, path)
        if path.exists() and not path.is_dir():
            raise StoreError(text, "exists and is not a directory")
        try:
            path.mkdir(parents=True, exist_ok=True)
            store = cls(ox.Store(str(path)), str(path))
            store._undo_broken_bulk_load()
            return store
        except OSError as error:
            if "lock" in str(error).lower():
                raise StoreInUseError(text, _served_at(path), str(error)) from error
            causes = _DISK_CAUSES + _OPEN_CAUSES
            raise disk_error(text, "opening it", error, causes=causes) or StoreError(text, str(error)) from error

    @property
    def in_memory(self) -> bool:
        return self.location == MEMORY

    def query(self, text: str, bindings: Mapping[str, Term] | None = None) -> QueryResult:
        """Run a SPARQL query with ``bindings`` substituted for its variables (never pasted into text)."""
        substitutions: dict[ox.Variable, ox.NamedNode | ox.BlankNode | ox.Literal | ox.Triple] = {
            ox.Variable(name): value for name, value in (bindings or {}).items()
        }
        self.check_query(text)
        try:
            return self._backend.query(
                text, prefixes=PREFIXES, use_default_graph_as_union=True, substitutions=substitutions
            )
        except SyntaxError as error:
            raise QuerySyntaxError(text, str(error)) from error
        except RuntimeError as error:  # errors found while iterating the result stay pyoxigraph's RuntimeError
            raise StoreEvaluationError(self.location, "query", str(error)) from error

    def check_query(self, text: str) -> None:
        """Refuse, before any parser sees it, a query that nests too deeply, reaches out or crashes the
        guard's checker; what :meth:`query` does first, for callers that evaluate elsewhere. cbrs's own
        named queries (``queries/*.rq``) skip every check: they are ours, none reaches out or nests deeply
        (tests/test_queries.py), and checking a long one cost every command that opens a store a checker
        process (a quarter of a second); scanning them all took a fifth of a task run's store time."""
        if text in bundled_query_texts():
            return
        key = self._checked_key(text)
        if self._checked.seen(key):
            return
        refuse_deep_nesting(text)
        refuse_remote_access(text, self.remote_access)
        self.guard.admit("query", text)
        self._checked.add(key, self.checked_texts)

    def _checked_key(self, text: str) -> tuple[bytes, tuple[str, ...]]:
        """What a passed text is remembered by (:data:`CHECKED_TEXTS`): its digest, and the prefixes it
        was checked against, on which the remote-access check depends."""
        digest = hashlib.blake2b(text.encode("utf-8", "surrogatepass"), digest_size=16).digest()
        return digest, self.remote_access

    def snapshot(self, target: Path) -> None:
        """A read-only copy of the store as it is now in ``target`` (which must not exist): a RocksDB
        checkpoint, hard links to the store's immutable files when on the same file system; for an
        in-memory store, its quads copied into a new on-disk store there."""
        try:
            if self.in_memory:
                copy = ox.Store(str(target))
                copy.bulk_extend(self._backend.quads_for_pattern(None, None, None, None))
                copy.flush()
                del copy  # closes it, so that a worker can open it
                return
            self._backend.backup(str(target))
        except OSError as error:
            doing = f"a snapshot into {target}"
            raise self._failed(disk_error(self.location, doing, error, _SNAPSHOT_FAILED)) or StoreError(
                self.location, f"snapshot into {target} failed: {error}"
            ) from error
        self.failure = None

    def quads(
        self,
        subject: ox.NamedNode | ox.BlankNode | None = None,
        predicate: ox.NamedNode | None = None,
        object: Term | None = None,
        graph: ox.NamedNode | ox.DefaultGraph | None = None,
    ) -> Iterator[ox.Quad]:
        return iter(self._backend.quads_for_pattern(subject, predicate, object, graph))

    def contains(self, quad: ox.Quad) -> bool:
        """Whether the store holds ``quad``: Oxigraph's own membership test, 0.4 us a quad through this
        method (81 ms for 200,000), 15 times less than a pattern lookup: the loader asks it of every triple."""
        return quad in self._backend

    def count(self, graph: GraphName | ox.NamedNode | None = None) -> int:
        """A named graph's quads counted by the query engine: as fast as a Python step per quad on the
        bundled graphs, and twice as fast on a million (0.4 s against 0.8 s)."""
        node = graph.node if isinstance(graph, GraphName) else graph
        if node is None:
            return sum(1 for _ in self._backend.quads_for_pattern(None, None, None, None))
        solutions = self._backend.query(_GRAPH_SIZE, substitutions={_GRAPH: node})
        assert isinstance(solutions, ox.QuerySolutions)
        solution = next(iter(solutions), None)
        return int(solution["n"].value) if solution is not None else 0

    def graphs(self) -> list[str]:
        return sorted(g.value for g in self._backend.named_graphs() if isinstance(g, ox.NamedNode))

    def is_seeded(self) -> bool:
        # a graph emptied by an update still exists in Oxigraph: what counts is that it holds something
        return next(iter(self._backend.quads_for_pattern(None, None, None, GraphName.ONTOLOGY.node)), None) is not None

    def dump(self, rdf_format: ox.RdfFormat = ox.RdfFormat.N_QUADS) -> bytes:
        if rdf_format == ox.RdfFormat.N_QUADS:
            return super().dump(rdf_format)
        data = self._backend.dump(format=rdf_format, prefixes=PREFIXES)
        assert data is not None
        return data

    def add(self, quads: Iterable[ox.Quad]) -> None:
        """Add ``quads`` in one transaction."""
        try:
            self._backend.extend(quads)
        except OSError as error:
            raise self._failed(disk_error(self.location, "the write", error, _WRITE_FAILED)) or StoreError(
                self.location, f"write failed: {error}"
            ) from error
        else:
            self.failure = None
        finally:
            self.generation += 1

    def add_nquads(self, data: bytes) -> None:
        """Add the quads of an N-Quads document in one transaction, parsed by Oxigraph itself (no
        Python object per quad: a kept seed goes in several times faster than through :meth:`add`)."""
        try:
            self._backend.load(data, ox.RdfFormat.N_QUADS)
        except OSError as error:
            raise self._failed(disk_error(self.location, "the write", error, _WRITE_FAILED)) or StoreError(
                self.location, f"write failed: {error}"
            ) from error
        else:
            self.failure = None
        finally:
            self.generation += 1

    def bulk_load(self, path: Path, rdf_format: ox.RdfFormat, graph: ox.NamedNode, base_iri: str) -> None:
        """Write the triples of the file at ``path`` into ``graph`` with Oxigraph's bulk loader.

        It writes the store's files directly, with no transaction log, which makes it several times
        faster than :meth:`add` and leaves no log as large as the data behind; but it is not one
        transaction. So the caller parses the file whole first (:mod:`kb.loader`) and ``graph`` must
        hold nothing yet: if the write fails all the same, ``graph`` is dropped again."""
        self.generation += 1
        # A note, in the transaction log before the first table is written: a process killed from here on
        # leaves it, and the next open drops the graph (_undo_broken_bulk_load), so the load is all or nothing.
        self._backend.add(ox.Quad(graph, _BULK_LOAD_OF, ox.Literal(str(path)), BULK_LOADING))
        try:
            self._backend.bulk_load(path=str(path), format=rdf_format, base_iri=base_iri, to_graph=graph)
            self.flush()
        except (OSError, SyntaxError, ValueError, RuntimeError) as error:
            undone = "it was undone"
            try:
                self._backend.remove_graph(graph)
                self._backend.remove_graph(BULK_LOADING)
            except (OSError, RuntimeError) as second:
                undone = f"undoing it failed too ({second}); the next open of the store drops graph {graph}"
            raise StoreError(self.location, f"bulk load of {path} failed ({error}); {undone}") from error
        finally:
            self.generation += 1
        self._backend.remove_graph(BULK_LOADING)  # the load stands

    def _undo_broken_bulk_load(self) -> None:
        """Drop the graph a bulk load was writing when its process died (see :meth:`bulk_load`)."""
        notes = list(self._backend.quads_for_pattern(None, _BULK_LOAD_OF, None, BULK_LOADING))
        for note in notes:
            assert isinstance(note.subject, ox.NamedNode)
            self._backend.remove_graph(note.subject)
        if notes:
            self._backend.remove_graph(BULK_LOADING)
            self._backend.flush()

    def update(self, text: str) -> None:
        """Run a SPARQL update in one transaction."""
        refuse_deep_nesting(text)
        refuse_remote_access(text, self.remote_access)
        self.guard.admit("update", text)
        try:
            self._apply_own_update(text)
        except StoreError as error:
            # an allowed LOAD that cannot read its file or URL is the request's fault, not the store's
            if isinstance(error, StoreEvaluationError) or not loads(text):
                raise
            raise StoreEvaluationError(self.location, "update", f"LOAD failed: {error.__cause__}") from error

    def dump_to(self, path: Path) -> None:
        """Write the whole dataset to ``path`` as N-Quads, streamed by Oxigraph (blank nodes' labels kept,
        in no order: :meth:`dump` sorts, for comparing, at a cost this copy need not pay)."""
        try:
            self._backend.dump(str(path), format=ox.RdfFormat.N_QUADS)
        except OSError as error:
            raise StoreError(self.location, f"a copy to {path} failed: {error}") from error

    def exchange(self, removed: Sequence[ox.Quad], added: Sequence[ox.Quad]) -> None:
        """Remove ``removed`` and add ``added`` in one transaction, blank nodes as they are (which
        :meth:`replace`'s data blocks cannot name): one update of :data:`_APPLY` operations whose terms a
        custom function gives; nothing in it sorts (:mod:`kb.sorting_updates` writes a child's delta so)."""
        operations = []
        functions: dict[ox.NamedNode, _TermOfRow] = {}
        for operation, quads, name in (("DELETE", removed, _REMOVED), ("INSERT", added, _ADDED)):
            if quads:
                rows = " ".join(str(n) for n in range(len(quads)))
                operations.append(_APPLY.format(operation=operation, rows=rows, f=name.value))
                functions[name] = _terms(quads)
        if operations:
            self._apply_own_update(" ;\n".join(operations), functions)

    def _apply_own_update(
        self,
        text: str,
        functions: Mapping[ox.NamedNode, _TermOfRow] | None = None,
    ) -> None:
        self.generation += 1  # before as well as after: a snapshot taken meanwhile is never current
        try:
            self._backend.update(text, prefixes=PREFIXES, custom_functions=dict(functions or {}))
        except SyntaxError as error:
            raise QuerySyntaxError(text, str(error)) from error
        except OSError as error:
            raise self._failed(disk_error(self.location, "the update", error, _WRITE_FAILED)) or StoreError(
                self.location, f"update failed: {error}"
            ) from error
        except RuntimeError as error:  # e.g. CREATE GRAPH of a graph that exists
            raise StoreEvaluationError(self.location, "update", str(error)) from error
        else:
            self.failure = None
        finally:
            self.generation += 1

    def flush(self) -> None:
        """Write the engine's memory tables to disk. Every write was committed to the write-ahead log
        before; a flush that fails (a full disk) loses none of it: the next open replays the log."""
        if self.in_memory:
            return
        try:
            self._backend.flush()
        except OSError as error:
            after = (
                "; every write that was committed is in its write-ahead log and is kept: "
                "the next open finishes the flush, once the disk is fixed"
            )
            raise self._failed(disk_error(self.location, "flushing it to disk", error, after)) or StoreError(
                self.location, f"flushing it to disk failed: {error}"
            ) from error
        self.failure = None

    def _failed(self, error: StoreDiskError | None) -> StoreDiskError | None:
        """Remember a disk error, and hand the first since a write last succeeded to :attr:`on_failure`;
        ``error`` unchanged."""
        if error is not None:
            if self.failure is None and self.on_failure is not None:
                self.on_failure(error)
            self.failure = error
        return error


def data_block(quads: Iterable[ox.Quad], blank_nodes: bool = False) -> str:
    """The body of an ``INSERT DATA`` / ``DELETE DATA`` block for ``quads``, one ``GRAPH`` group per graph.

    Every term is written by pyoxigraph's serialiser. Blank nodes are refused unless ``blank_nodes``
    (they are fresh nodes in an ``INSERT DATA``, and a ``DELETE DATA`` cannot name them).
    """
    by_graph: dict[ox.NamedNode | ox.DefaultGraph, list[str]] = defaultdict(list)
    for quad in quads:
        if not blank_nodes:
            for term in (quad.subject, quad.object):
                if isinstance(term, ox.BlankNode):
                    raise ValueError(f"blank node {term} in a data block; skolemise it under {GENID} first")
        graph = quad.graph_name
        if isinstance(graph, ox.BlankNode):
            raise ValueError(f"blank node graph name {graph} in a data block")
        by_graph[graph].append(f"{quad.subject} {quad.predicate} {quad.object} .\n")
    parts = []
    for graph, lines in by_graph.items():
        if isinstance(graph, ox.NamedNode):
            parts.append(f"GRAPH {graph} {{\n{''.join(lines)}}}\n")
        else:
            parts.append("".join(lines))
    return "".join(parts)


SERVED_AT = "cbrs-served-at.txt"
"""A file a running ``cbrs serve`` keeps in its on-disk store, holding its base URL: what another
command that finds the store locked tells its user to use instead."""


def mark_served(location: str, url: str | None) -> None:
    """Note (or, with None, forget) the URL a server serves the on-disk store at ``location`` from."""
    marker = Path(location) / SERVED_AT
    if url is None:
        marker.unlink(missing_ok=True)
    else:
        marker.write_text(url + "\n", encoding="utf-8")


def _served_at(path: Path) -> str | None:
    try:
        return (path / SERVED_AT).read_text(encoding="utf-8").strip() or None
    except OSError:
        return None


def _terms(quads: Sequence[ox.Quad]) -> _TermOfRow:
    """The custom function of :data:`_APPLY` for ``quads``: term ``position`` of quad ``row``, or None (unbound)."""

    def term(row: ox.Literal, position: ox.Literal) -> _Term | None:
        quad, at = quads[int(row.value)], int(position.value)
        graph = quad.graph_name
        if isinstance(graph, ox.DefaultGraph) != (at >= 4):
            return None  # this template triple is not this quad's
        if at % 4 == 3:
            assert not isinstance(graph, ox.DefaultGraph)
            return graph
        return (quad.subject, quad.predicate, quad.object)[at % 4]

    return term
