"""SPARQL queries and updates as a service: content negotiation, a deadline, size limits and access.

The HTTP endpoint and the rosbridge ``/cbrs/query`` service are thin layers over :class:`SparqlService`.

How a query is bounded (Oxigraph has no query timeout of its own):

- at most ``workers`` run at once, and at most ``workers_per_client`` for one client (an IP address);
  one more is refused at once (busy), so runaway queries cannot pile up and one client cannot take them all;
- on an on-disk store it is evaluated in a worker process on a snapshot of the store
  (:mod:`cbrs.query_workers`), killed at the deadline or when it holds more than ``memory`` bytes:
  its core, its memory and its slot are free at once;
- its result is serialised by Oxigraph into a writer that checks the deadline and the byte budget on
  every chunk, so a query that streams many solutions stops at the deadline or the limit;
- an in-memory store is evaluated so too when ``isolate_memory`` is set (``cbrs serve`` sets it), its
  snapshot being a copy; otherwise, and on a remote store, the query runs on a thread: a query still
  computing its first solution at the deadline is answered "timed out" and that thread is left to
  finish, keeping its slot (a remote store's own ``remote_timeout`` ends its wait).

Which graphs a query reads follows SPARQL 1.1 (Query §13.2, Protocol §2.1.4): the protocol's
``default-graph-uri`` / ``named-graph-uri`` (a :class:`Dataset`) win over the query's ``FROM`` /
``FROM NAMED``, which win over cbrs's own default, the union of all graphs (:func:`dataset_for`).
"""

from __future__ import annotations

import contextlib
import functools
import hmac
import io
import threading
import time
from collections.abc import Callable, Iterable, Iterator, Sequence
from concurrent.futures import Future
from concurrent.futures import TimeoutError as FutureTimeout
from dataclasses import dataclass, field
from typing import Any, Concatenate, Literal, ParamSpec, TypeVar

import pyoxigraph as ox
from werkzeug.datastructures import MIMEAccept

from cbrs import __version__, pattern_lookup
from cbrs._query_worker import dataset_options
from cbrs.kb import KnowledgeBase
from cbrs.kb.derived_prefixes import for_store as derived_prefixes
from cbrs.kb.described import about_in, complete
from cbrs.kb.errors import (
    EngineFaultError,
    KnowledgeBaseError,
    QuerySyntaxError,
    QueryTooComplexError,
    StoreEvaluationError,
)
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.query_guard import GuardBusyError, start_evaluation_thread
from cbrs.kb.served_updates import HEADER, header_value
from cbrs.kb.sparql_hints import FORMS, TOKENS, explain_syntax_error, first_keyword
from cbrs.kb.store import EmbeddedStore, QueryResult, is_remote, refuse_inserted_blank_nodes
from cbrs.query_workers import QueryProcesses, QueryStopped, Request
from cbrs.scan_queries import is_single_scan, single_scan, uses_prefixes
from cbrs.settings import setting

# Media types offered for SELECT and ASK results, the first being the default.
RESULT_TYPES: dict[str, ox.QueryResultsFormat] = {
    "application/sparql-results+json": ox.QueryResultsFormat.JSON,
    "application/sparql-results+xml": ox.QueryResultsFormat.XML,
    "text/csv": ox.QueryResultsFormat.CSV,
    "text/tab-separated-values": ox.QueryResultsFormat.TSV,
    "application/json": ox.QueryResultsFormat.JSON,
    "application/xml": ox.QueryResultsFormat.XML,
    "text/xml": ox.QueryResultsFormat.XML,
}
# Media types offered for CONSTRUCT and DESCRIBE results, the first being the default.
GRAPH_TYPES: dict[str, ox.RdfFormat] = {
    "text/turtle": ox.RdfFormat.TURTLE,
    "application/n-triples": ox.RdfFormat.N_TRIPLES,
    "application/ld+json": ox.RdfFormat.JSON_LD,
    "application/rdf+xml": ox.RdfFormat.RDF_XML,
    "application/n-quads": ox.RdfFormat.N_QUADS,  # the triples in the default graph
    "application/trig": ox.RdfFormat.TRIG,
    "text/n3": ox.RdfFormat.N3,
    "text/rdf+n3": ox.RdfFormat.N3,
    "text/plain": ox.RdfFormat.N_TRIPLES,
    "application/json": ox.RdfFormat.JSON_LD,
    "application/xml": ox.RdfFormat.RDF_XML,
}
# Short names for the ``format`` / ``output`` request parameter that SPARQLWrapper and browsers send.
SHORT_NAMES: dict[str, tuple[str, str]] = {
    "json": ("application/sparql-results+json", "application/ld+json"),
    "xml": ("application/sparql-results+xml", "application/rdf+xml"),
    "csv": ("text/csv", "application/n-triples"),
    "tsv": ("text/tab-separated-values", "application/n-triples"),
    "turtle": ("application/sparql-results+json", "text/turtle"),
    "ttl": ("application/sparql-results+json", "text/turtle"),
    "ntriples": ("text/tab-separated-values", "application/n-triples"),
    "nt": ("text/tab-separated-values", "application/n-triples"),
    "jsonld": ("application/sparql-results+json", "application/ld+json"),
    "json-ld": ("application/sparql-results+json", "application/ld+json"),
    "rdfxml": ("application/sparql-results+xml", "application/rdf+xml"),
    "rdf+xml": ("application/sparql-results+xml", "application/rdf+xml"),
    "rdf": ("application/sparql-results+xml", "application/rdf+xml"),  # SPARQLWrapper's RDF return format
    "n-triples": ("text/tab-separated-values", "application/n-triples"),
    "n-quads": ("text/tab-separated-values", "application/n-quads"),
    "nquads": ("text/tab-separated-values", "application/n-quads"),
    "nq": ("text/tab-separated-values", "application/n-quads"),
    "trig": ("application/sparql-results+json", "application/trig"),
    "n3": ("application/sparql-results+json", "text/n3"),
}


UPDATES_CHECKED = True
"""Whether :meth:`SparqlService.update` runs every update through :meth:`KnowledgeBase.update`'s checks (the
semantic map, descriptions, superclasses), all or nothing, and brings graph:entailed up to date: always, no
setting turns them off. A remote store client on this server trusts the word in :func:`identity_header`
to send a checked update as it is, unchecked by itself (:mod:`kb.served_updates`): a setting that
skipped a check must make this False for that server."""


def identity_header() -> tuple[str, str]:
    """The header every answer of the SPARQL endpoints carries: ``Cbrs-Server: cbrs/VERSION checked-updates``
    (docs/serving.md), from which a remote store client learns, on its first request, that this server
    checks its updates itself."""
    return HEADER, header_value(__version__, UPDATES_CHECKED)


class EndpointError(KnowledgeBaseError):
    """A request the endpoint refuses; ``kind`` is a stable machine-readable name."""

    kind = "error"


class NotAcceptableError(EndpointError):
    http_status = 406
    kind = "not-acceptable"

    def __init__(self, asked: str, offered: Sequence[str]) -> None:
        self.asked = asked
        super().__init__(f"cannot answer in {asked!r}; this result is available as {', '.join(offered)}")


class QueryTooLargeError(EndpointError):
    http_status = 413
    kind = "request-too-large"

    def __init__(self, size: int, limit: int) -> None:
        self.size = size
        super().__init__(f"the request is {size} bytes; the limit is {limit} (setting max_query_bytes)")


class ResultTooLargeError(EndpointError):
    http_status = 422
    kind = "result-too-large"

    def __init__(self, limit: int) -> None:
        super().__init__(
            f"the result exceeds {limit} bytes (setting max_result_bytes); add a LIMIT or select fewer variables"
        )


class QueryTimeoutError(EndpointError):
    http_status = 503
    kind = "timeout"

    def __init__(self, seconds: float, stopped: bool = False) -> None:
        self.seconds = seconds
        end = "; it was stopped" if stopped else ""
        super().__init__(f"the query did not finish within {seconds:g} s (setting query_timeout){end}")


class QueryMemoryError(EndpointError):
    http_status = 422
    kind = "query-too-large"

    def __init__(self, limit: int) -> None:
        self.limit = limit
        super().__init__(
            f"the query needed more than {limit >> 20} MiB of memory (setting query_memory) and was stopped; "
            "add a LIMIT, or narrow its patterns"
        )


#: seconds a busy answer (503) asks its client to wait before trying again, in its Retry-After header: a
#: worker or a client's share is free again as soon as a query ends, which a lookup does in milliseconds
BUSY_RETRY_AFTER = 1


class EndpointBusyError(EndpointError):
    http_status = 503
    kind = "busy"
    retry_after = BUSY_RETRY_AFTER

    def __init__(self, workers: int, client: str | None = None, per_client: int | None = None) -> None:
        self.client = client
        if client is not None:
            message = (
                f"{client} already runs {per_client} queries, the most one client may run at once; retry when "
                "one has ended (setting query_workers_per_client)"
            )
        else:
            message = f"all {workers} query workers are busy; retry shortly (setting query_workers)"
        super().__init__(message)


class UpdateForbiddenError(EndpointError):
    http_status = 403
    kind = "forbidden"


class BadRequestError(EndpointError):
    """A request the protocol cannot read as asked (a parameter missing, doubled or misspelt); the
    message names what was wrong."""

    http_status = 400
    kind = "bad-request"


class UnsupportedMediaTypeError(EndpointError):
    """A body of a media type the path does not take, or of none: ``where`` names the request, ``accepted``
    the types it takes, ``hint`` (optional) how the mistake is usually made."""

    http_status = 415
    kind = "unsupported-media-type"

    def __init__(self, media_type: str, where: str, accepted: Sequence[str], hint: str = "") -> None:
        self.media_type = media_type
        self.accepted = tuple(accepted)
        types = ", ".join(self.accepted[:-1]) + f" or {self.accepted[-1]}" if len(self.accepted) > 1 else accepted[0]
        super().__init__(f"{where} must be {types}, not {media_type or '(none)'!r}{hint}")


class BadDatasetError(EndpointError):
    http_status = 400
    kind = "bad-dataset"

    def __init__(self, parameter: str, value: str, reason: str) -> None:
        self.parameter = parameter
        self.value = value
        super().__init__(f"{parameter}={value!r} is not an absolute IRI ({reason}); give a graph's full IRI")


@dataclass(frozen=True)
class Dataset:
    """The RDF dataset a request names with the protocol's ``default-graph-uri`` and ``named-graph-uri``.

    The default graph is the merge of ``default_graphs`` (none: an empty graph), and only
    ``named_graphs`` can be reached with ``GRAPH``; it overrides the query's ``FROM`` / ``FROM NAMED``.
    """

    default_graphs: tuple[str, ...] = ()
    named_graphs: tuple[str, ...] = ()

    @classmethod
    def from_parameters(cls, default_graphs: Sequence[str], named_graphs: Sequence[str]) -> Dataset | None:
        """The dataset the parameters name, or ``None`` when there are none; refuses what is not an IRI.
        An empty value names nothing: it is what a query form's blank graph field sends."""
        default_graphs = [value for value in default_graphs if value.strip()]
        named_graphs = [value for value in named_graphs if value.strip()]
        if not default_graphs and not named_graphs:
            return None
        for parameter, values in (("default-graph-uri", default_graphs), ("named-graph-uri", named_graphs)):
            for value in values:
                try:
                    ox.NamedNode(value)
                except ValueError as error:
                    raise BadDatasetError(parameter, value, str(error)) from None
        return cls(tuple(default_graphs), tuple(named_graphs))


def has_dataset_clause(text: str) -> bool:
    """Whether the query names its own dataset with ``FROM`` or ``FROM NAMED`` (only those clauses use the keyword)."""
    if "FROM" not in text.upper():
        return False  # the common case, without tokenising
    return any((match.group("word") or "").upper() == "FROM" for match in TOKENS.finditer(text))


def dataset_clause(text: str) -> Dataset | None:
    """The dataset the query's ``FROM`` / ``FROM NAMED`` clauses name, or ``None`` when it names none.

    The graph names are read as written (IRIs or prefixed names) and resolved by Oxigraph against the
    query's own prologue (``BASE``, ``PREFIX``) and cbrs's prefixes. ``None`` too for a clause that cannot
    be read: the query is then evaluated as written and its parser reports what is wrong.
    """
    tokens = [m for m in TOKENS.finditer(text) if m.lastgroup in ("iri", "pname", "word")]
    prologue_end = next((m.start() for m in tokens if m.lastgroup == "word" and m.group().upper() in FORMS), 0)
    names: list[tuple[bool, str]] = []
    for index, match in enumerate(tokens):
        if match.lastgroup != "word" or match.group().upper() != "FROM":
            continue
        named = index + 1 < len(tokens) and tokens[index + 1].group().upper() == "NAMED"
        at = index + 2 if named else index + 1
        if at >= len(tokens) or tokens[at].lastgroup not in ("iri", "pname"):
            return None
        names.append((named, tokens[at].group()))
    if not names:
        return None
    variables = " ".join(f"?g{i}" for i in range(len(names)))
    terms = " ".join(name for _, name in names)
    resolver = f"{text[:prologue_end]}\nSELECT * WHERE {{ VALUES ({variables}) {{ ({terms}) }} }}"
    try:
        solutions = ox.Store().query(resolver, prefixes=PREFIXES)
    except SyntaxError:
        return None
    assert isinstance(solutions, ox.QuerySolutions)
    row = next(iter(solutions))
    iris = [row[f"g{i}"].value for i in range(len(names))]
    return Dataset(
        tuple(iri for (named, _), iri in zip(names, iris, strict=True) if not named),
        tuple(iri for (named, _), iri in zip(names, iris, strict=True) if named),
    )


def dataset_for(text: str, dataset: Dataset | None) -> dict[str, Any]:
    """How the query ``text`` is evaluated, for :func:`cbrs._query_worker.dataset_options`: the protocol's
    dataset if given, else the query's own ``FROM`` / ``FROM NAMED``, else the union default graph.

    The query's clause is passed on as an explicit dataset rather than left to the store, because a
    store whose default graph is the union (Oxigraph's union option, embedded or served) would let the
    union override it."""
    if dataset is None and has_dataset_clause(text):
        dataset = dataset_clause(text)
        if dataset is None:
            return {}
    if dataset is not None:
        return {"default": list(dataset.default_graphs), "named": list(dataset.named_graphs)}
    return {"union": True}


@dataclass(frozen=True)
class Answer:
    """A serialised result and its media type."""

    body: bytes
    media_type: str


@dataclass(frozen=True)
class EndpointConfig:
    timeout: float = 30.0
    max_result_bytes: int = 64 * 1024 * 1024
    max_query_bytes: int = 1024 * 1024
    update_token: str | None = None
    workers: int = 4
    read_only: bool = False  # refuse every write, token or not
    # queries one client (an IP address) may run at once, and the resident bytes a query's worker
    # process may hold (0: no limit); from the settings table unless given
    workers_per_client: int = field(default_factory=lambda: setting("query_workers_per_client").resolve())
    memory: int = field(default_factory=lambda: setting("query_memory").resolve())
    worker_idle: float = field(default_factory=lambda: setting("query_worker_idle").resolve())
    isolate: bool = True  # evaluate in killable worker processes when the store is on disk
    isolate_memory: bool = False  # and when it is in memory (a copy per write: cbrs serve turns it on)


class _Stop(Exception):
    """Raised inside Oxigraph's serialiser to abandon a result; carries the error to report."""

    def __init__(self, error: EndpointError) -> None:
        self.error = error


class _BudgetWriter(io.BytesIO):
    """Collects a serialised result, stopping it at the byte limit or the deadline."""

    def __init__(self, limit: int, deadline: float, timeout: float) -> None:
        super().__init__()
        self.limit = limit
        self.deadline = deadline
        self.timeout = timeout

    def write(self, data: Any) -> int:
        written = super().write(data)
        if self.tell() > self.limit:
            raise _Stop(ResultTooLargeError(self.limit))
        if time.monotonic() > self.deadline:
            raise _Stop(QueryTimeoutError(self.timeout))
        return written


_T = TypeVar("_T")


class ReadBudget:
    """The limits of one read that is not a SPARQL query (the Graph Store protocol's ``GET /store``): its
    result stops at ``max_result_bytes`` (422) and its reading and writing at the deadline (503)."""

    def __init__(self, limit: int, timeout: float) -> None:
        self.limit = limit
        self.timeout = timeout
        self.deadline = time.monotonic() + timeout

    def watch(self, items: Iterable[_T], every: int = 4096) -> Iterator[_T]:
        """``items``, checking the deadline every ``every`` of them."""
        for count, item in enumerate(items):
            if count % every == 0 and time.monotonic() > self.deadline:
                raise QueryTimeoutError(self.timeout, stopped=True)
            yield item

    def serialize(self, statements: Iterable[Any], fmt: ox.RdfFormat, prefixes: dict[str, str]) -> bytes:
        """``statements`` in ``fmt``, within the byte budget and the deadline."""
        writer = _BudgetWriter(self.limit, self.deadline, self.timeout)
        try:
            ox.serialize(self.watch(statements), writer, format=fmt, prefixes=prefixes)
        except _Stop as stop:
            raise stop.error from None
        return writer.getvalue()


BOM = "\ufeff"
_P = ParamSpec("_P")
_R = TypeVar("_R")


def _sparql_text(
    expected: Literal["query", "update"],
) -> Callable[[Callable[Concatenate[SparqlService, str, _P], _R]], Callable[Concatenate[SparqlService, str, _P], _R]]:
    """Run a method taking the SPARQL text first: without a leading byte order mark (a file saved by a
    Windows editor and posted as it is; the parser refuses it as a character it did not expect), and
    with its syntax errors explained (:func:`explain_syntax_error`, with the store's derived prefixes offered)."""

    def wrap(
        method: Callable[Concatenate[SparqlService, str, _P], _R],
    ) -> Callable[Concatenate[SparqlService, str, _P], _R]:
        @functools.wraps(method)
        def run(self: SparqlService, text: str, /, *args: _P.args, **kwargs: _P.kwargs) -> _R:
            text = text.removeprefix(BOM)
            try:
                return method(self, text, *args, **kwargs)
            except QuerySyntaxError as error:
                # a prefix nobody declared is offered the store's derived one, as cbrs query offers it
                explained = explain_syntax_error(error, text, expected, offered=lambda: derived_prefixes(self.kb))
                if explained is error:
                    raise
                raise explained from error

        return run

    return wrap


class SparqlService:
    """Queries and updates on a knowledge base, bounded and access-checked."""

    def __init__(self, kb: KnowledgeBase, config: EndpointConfig | None = None, lock: threading.RLock | None = None):
        self.kb = kb
        self.config = config or EndpointConfig()
        self.lock = lock or threading.RLock()  # held by writers, so readers of cached descriptions see whole updates
        self._slots = threading.BoundedSemaphore(self.config.workers)
        self._clients: dict[str, int] = {}  # queries running per client
        self._clients_lock = threading.Lock()
        self._listeners: list[Callable[[], None]] = []
        self.generation = 0  # bumped by every update, so caches built from the store know they are stale
        store = kb.store
        self.processes: QueryProcesses | None = None
        if (
            self.config.isolate
            and isinstance(store, EmbeddedStore)
            and (self.config.isolate_memory or not store.in_memory)
        ):
            self.processes = QueryProcesses(
                store, self.config.workers, self.config.memory, idle=self.config.worker_idle
            )

    @property
    def writable(self) -> bool:
        return self.config.update_token is not None and not self.config.read_only

    @_sparql_text("query")
    def query(
        self,
        text: str,
        accept: str | None = None,
        short_format: str | None = None,
        client: str | None = None,
        dataset: Dataset | None = None,
    ) -> Answer:
        """Run ``text`` and serialise its result in the best format for ``accept`` (an Accept header value).

        ``client`` (an IP address) is who asks: one client runs at most ``workers_per_client`` queries at once.
        ``dataset`` is the protocol's ``default-graph-uri`` / ``named-graph-uri``, if the request gave any.
        """
        self._check_size(text)
        graphs = dataset_for(text, dataset)
        scan = isinstance(self.kb.store, EmbeddedStore) and is_single_scan(text)
        try:
            release = self._admit(client, slot=not scan)
        except EndpointBusyError:
            self._refuse_malformed(text)
            raise
        if scan:  # one index scan: stopped by the writer's deadline, so it needs no worker (cbrs.scan_queries)
            try:
                deadline = time.monotonic() + self.config.timeout
                return self._evaluate(text, accept, short_format, deadline, graphs, flat=True)
            finally:
                release()
        if self.processes is not None:
            try:
                return self._described(text, self._in_process(text, accept, short_format, graphs), graphs)
            finally:
                release()
        deadline = time.monotonic() + self.config.timeout
        future: Future[Answer] = Future()

        def work() -> None:
            try:
                future.set_result(self._evaluate(text, accept, short_format, deadline, graphs))
            except BaseException as error:  # handed to the waiting request
                future.set_exception(error)
            finally:
                release()

        # A daemon thread, not a pool's: an abandoned query must not keep the process from exiting.
        worker = threading.Thread(target=work, name="cbrs-sparql-query", daemon=True)
        try:
            start_evaluation_thread(worker)  # the stack kb.query_guard's margin is measured against
        except BaseException:
            release()
            raise
        try:
            answer = future.result(timeout=self.config.timeout)
        except FutureTimeout:
            raise QueryTimeoutError(self.config.timeout) from None
        return self._described(text, answer, graphs)

    def _described(self, text: str, answer: Answer, graphs: dict[str, Any]) -> Answer:
        """A DESCRIBE's ``answer`` completed through the skolemised blank nodes it reaches (a class's OWL
        restrictions: :func:`cbrs.kb.described.complete`), within the query's dataset, serialised again in
        its media type under the endpoint's size limit; any other answer as it is."""
        if (first_keyword(text) or "").upper() != "DESCRIBE" or answer.media_type not in GRAPH_TYPES:
            return answer
        form = GRAPH_TYPES[answer.media_type]
        triples = [quad.triple for quad in ox.parse(answer.body, format=form)]
        default = graphs.get("default")
        about = about_in(
            self.kb.store, None if graphs.get("union") or default is None else [ox.NamedNode(g) for g in default]
        )
        completed = complete(triples, about)
        if len(completed) == len(triples):
            return answer
        timeout = self.config.timeout
        writer = _BudgetWriter(self.config.max_result_bytes, time.monotonic() + timeout, timeout)
        try:
            ox.serialize(completed, writer, form)
        except _Stop as stop:
            raise stop.error from None
        return Answer(writer.getvalue(), answer.media_type)

    @_sparql_text("query")
    def query_here(
        self, text: str, accept: str | None, short_format: str | None, client: str | None, budget: int
    ) -> Answer | None:
        """Answer ``text`` on the caller's thread if it is a single scan whose result fits in ``budget``
        bytes; ``None`` if it is not one, or its result grew past ``budget`` (then :meth:`query` it on a
        thread that may wait). An event loop answers point lookups so, without a thread hand-over, and
        ``budget`` bounds how long it is kept from its other requests. On an in-memory store, a lookup of
        the shape :func:`cbrs.pattern_lookup.parse` takes, asked in SPARQL JSON, is answered from the
        index directly, with the bytes the engine would write."""
        self._check_size(text)
        store = self.kb.store
        scan = single_scan(text) if isinstance(store, EmbeddedStore) else None
        if scan is None or not isinstance(store, EmbeddedStore):
            return None
        graphs = dataset_for(text, None)
        release = self._admit(client, slot=False)
        limit = min(budget, self.config.max_result_bytes)
        try:
            deadline = time.monotonic() + self.config.timeout
            # In memory only: on disk, quads_for_pattern reads the subject and graph name of every quad
            # back from RocksDB, which the engine skips, and that costs what the direct path saves.
            direct = store.in_memory and graphs.get("union")
            lookup = pattern_lookup.parse(scan, PREFIXES) if direct else None
            media_type = _json_results_type(accept, short_format) if lookup is not None else None
            if lookup is None or media_type is None:
                return self._evaluate(text, accept, short_format, deadline, graphs, flat=True, limit=limit)
            try:  # read from the index without the SPARQL engine's parse and plan (cbrs.pattern_lookup)
                body = pattern_lookup.json_results(store._backend, lookup, limit, deadline)
            except pattern_lookup.Stopped as stopped:
                if stopped.reason == "timeout":
                    raise QueryTimeoutError(self.config.timeout) from None
                raise ResultTooLargeError(limit) from None
            return Answer(body, media_type)
        except ResultTooLargeError:
            if limit < self.config.max_result_bytes:
                return None  # not too large for the endpoint, only for this thread
            raise
        finally:
            release()

    @contextlib.contextmanager
    def bounded_read(self, client: str | None) -> Iterator[ReadBudget]:
        """A read of the store that is not a query (``GET /store``), with a query's limits: it takes a
        worker slot and counts against ``client``'s share (503 ``busy`` past either), and what it
        writes stops at ``max_result_bytes`` and ``query_timeout`` (:class:`ReadBudget`). A whole
        store's dump took a request thread, its quads and their text in memory, without any limit."""
        release = self._admit(client)
        try:
            yield ReadBudget(self.config.max_result_bytes, self.config.timeout)
        finally:
            release()

    def close(self) -> None:
        """Stop the query worker processes and delete their snapshots."""
        if self.processes is not None:
            self.processes.close()

    def _refuse_malformed(self, text: str) -> None:
        """Raise ``text``'s syntax error if it has one. A busy endpoint answered a text that does not parse
        "busy", so a class whose other students held every worker was told to retry a typo. The store's
        checks come first (:meth:`EmbeddedStore.check_query`: nesting, a ``SERVICE`` outside
        ``federation_allow``), then the text is parsed in the query guard's checker process, never here:
        Oxigraph evaluates an ASK, an aggregate or a ``SERVICE`` as it parses, so a parse on an empty store
        of the request's own reached out and ran a cross product of ``VALUES`` with no worker and no
        deadline. No checker free at once, or none done in its time: answered busy, as before."""
        store = self.kb.store
        if not isinstance(store, EmbeddedStore):
            return  # a remote store parses and answers its own errors
        store.check_query(text)  # a long text is parsed by the checker here already
        if len(text) > store.guard.direct_chars:
            return
        try:
            store.guard.check("query", text, wait=0.0)
        except (GuardBusyError, QueryTooComplexError):
            return

    def _admit(self, client: str | None, slot: bool = True) -> Callable[[], None]:
        """Count a query of ``client`` against its share and, with ``slot``, take one of the ``workers``
        slots (a single scan runs on the request's thread and takes none); the call returned gives
        them back (once)."""
        limit = min(self.config.workers_per_client, self.config.workers)
        clients = self._clients  # a plain dict: every point lookup passes here, Counter's misses run Python
        with self._clients_lock:
            running = clients.get(client, 0) if client is not None else 0
            if client is not None and running >= limit:
                raise EndpointBusyError(self.config.workers, client, limit)
            if slot and not self._slots.acquire(blocking=False):
                raise EndpointBusyError(self.config.workers)
            if client is not None:
                clients[client] = running + 1
        released = False

        def release() -> None:
            nonlocal released
            with self._clients_lock:
                if released:
                    return
                released = True
                if client is not None:
                    left = clients[client] - 1
                    if left > 0:
                        clients[client] = left
                    else:
                        del clients[client]
                if slot:
                    self._slots.release()

        return release

    def _in_process(self, text: str, accept: str | None, short_format: str | None, graphs: dict[str, Any]) -> Answer:
        assert self.processes is not None
        store = self.processes.store
        refusals: dict[bool, NotAcceptableError] = {}
        chosen: dict[bool, str | None] = {}
        for graph in (False, True):
            try:
                chosen[graph] = negotiate(graph, accept, short_format)
            except NotAcceptableError as error:
                refusals[graph], chosen[graph] = error, None
        store.check_query(text)
        results, graph_type = chosen[False], chosen[True]
        request = Request(
            text=text,
            results_type=results,
            graph_type=graph_type,
            results_format=RESULT_TYPES[results].media_type if results else "application/sparql-results+json",
            graph_format=GRAPH_TYPES[graph_type].media_type if graph_type else "application/n-triples",
            limit=self.config.max_result_bytes,
            timeout=self.config.timeout,
            dataset=graphs,
        )
        try:
            body, media_type = self.processes.run(request)
        except QueryStopped as stopped:
            raise self._stopped(stopped, refusals) from None
        except QueryTooComplexError as error:
            raise QueryTooComplexError(text, error.message) from None
        except EngineFaultError as error:
            raise EngineFaultError(text, error.reason) from None
        return Answer(body, media_type)

    def _stopped(self, stopped: QueryStopped, refusals: dict[bool, NotAcceptableError]) -> EndpointError:
        if stopped.reason == "timeout":
            return QueryTimeoutError(self.config.timeout, stopped=True)
        if stopped.reason == "memory":
            return QueryMemoryError(self.config.memory)
        if stopped.reason == "too-large":
            return ResultTooLargeError(self.config.max_result_bytes)
        return refusals[str(stopped) == "graph"]

    def check_token(self, token: str | None) -> None:
        """Refuse a write (``UpdateForbiddenError``, 403) unless ``token`` is the configured update token."""
        expected = self.config.update_token
        if self.config.read_only:
            raise UpdateForbiddenError("updates are disabled: this server was started read-only")
        if expected is None:
            raise UpdateForbiddenError("updates are disabled: this server is read-only (no update token set)")
        if token is None:
            raise UpdateForbiddenError("updates need the server's token: Authorization: Bearer <token>")
        if not hmac.compare_digest(token.encode("utf-8"), expected.encode("utf-8")):
            raise UpdateForbiddenError("the bearer token sent is not this server's update token")

    @_sparql_text("update")
    def update(self, text: str, token: str | None) -> None:
        """Run a SPARQL update when ``token`` is the configured update token; one transaction."""
        self.check_token(token)
        self._check_size(text)
        refuse_inserted_blank_nodes(text)  # what cbrs stores it must be able to read back by name
        with self.lock:
            try:
                # refused, nothing changed: StoreEvaluationError (400), a description the shapes refuse (400),
                # a semantic map it would leave unreadable (MapError, 422: KnowledgeBase.update checks it)
                self.kb.update(text, check_map=UPDATES_CHECKED)
            finally:
                self.generation += 1
        for listener in list(self._listeners):
            listener()

    def changed(self) -> None:
        """Say the store was written other than by :meth:`update` (a live registration, a lapsed
        lease): caches go stale and the update listeners hear of it. Call with :attr:`lock` held."""
        self.generation += 1
        for listener in list(self._listeners):
            listener()

    def on_update(self, listener: Callable[[], None]) -> Callable[[], None]:
        """Call ``listener()`` after each update; returns the call that stops it."""
        self._listeners.append(listener)
        return lambda: self._listeners.remove(listener)

    def _check_size(self, text: str) -> None:
        size = len(text.encode("utf-8"))
        if size > self.config.max_query_bytes:
            raise QueryTooLargeError(size, self.config.max_query_bytes)

    def _evaluate(
        self,
        text: str,
        accept: str | None,
        short_format: str | None,
        deadline: float,
        graphs: dict[str, Any],
        flat: bool = False,
        limit: int | None = None,
    ) -> Answer:
        result: Any = None  # Oxigraph results must be dropped on the thread that made them
        try:
            result = self._run_flat(text, graphs) if flat else self._run(text, graphs)
            media_type = negotiate(isinstance(result, ox.QueryTriples), accept, short_format)
            writer = _BudgetWriter(limit or self.config.max_result_bytes, deadline, self.config.timeout)
            try:
                if isinstance(result, ox.QueryTriples):
                    result.serialize(writer, GRAPH_TYPES[media_type])
                else:
                    result.serialize(writer, RESULT_TYPES[media_type])
            except _Stop as stop:
                raise stop.error from None
            except KnowledgeBaseError:
                raise
            except RuntimeError as error:  # Oxigraph evaluates lazily: its errors can surface while serialising
                raise StoreEvaluationError(self.kb.store.location, "query", str(error)) from error
            return Answer(writer.getvalue(), media_type)
        finally:
            result = None

    def _run_flat(self, text: str, graphs: dict[str, Any]) -> QueryResult:
        """Evaluate a single scan (:func:`cbrs.scan_queries.is_single_scan`) on the embedded store. Its text
        is flat by construction and names no SERVICE, so the checks for deep or reaching texts are moot."""
        store = self.kb.store
        assert isinstance(store, EmbeddedStore)
        try:
            prefixes = PREFIXES if uses_prefixes(text) else None
            return store._backend.query(text, prefixes=prefixes, **dataset_options(graphs))
        except SyntaxError as error:
            raise QuerySyntaxError(text, str(error)) from error
        except (OSError, RuntimeError) as error:
            raise StoreEvaluationError(store.location, "query", str(error)) from error

    def _run(self, text: str, graphs: dict[str, Any]) -> QueryResult:
        """Evaluate ``text`` on this thread over the dataset ``graphs`` (see :func:`dataset_for`)."""
        store = self.kb.store
        if graphs.get("union"):
            return self.kb.query(text)  # the store's own rule: the union default graph
        if is_remote(store.location):  # the server applies FROM, and the parameters sent on
            from cbrs.kb.remote_store import RemoteStore  # httpx loads only for a remote store

            assert isinstance(store, RemoteStore)
            return store.query_dataset(text, graphs.get("default"), graphs.get("named"))
        if not isinstance(store, EmbeddedStore):
            raise StoreEvaluationError(store.location, "query", "this store cannot take a dataset; query without one")
        store.check_query(text)
        # EmbeddedStore.query always reads the union default graph, so the dataset goes to Oxigraph here,
        # with the same options the worker processes use.
        try:
            return store._backend.query(text, prefixes=PREFIXES, **dataset_options(graphs))
        except SyntaxError as error:
            raise QuerySyntaxError(text, str(error)) from error
        except (OSError, RuntimeError) as error:
            raise StoreEvaluationError(store.location, "query", str(error)) from error


def _json_results_type(accept: str | None, short_format: str | None) -> str | None:
    """The media type a SELECT or ASK result is answered in when it is SPARQL JSON, else ``None``
    (another format, or none acceptable: the engine's path answers or refuses)."""
    try:
        media_type = negotiate(False, accept, short_format)
    except NotAcceptableError:
        return None
    return media_type if RESULT_TYPES[media_type] == ox.QueryResultsFormat.JSON else None


@functools.lru_cache(maxsize=256)
def negotiate(
    graph: bool, accept: str | None, short_format: str | None = None, only: tuple[str, ...] | None = None
) -> str:
    """The media type to answer in: a ``format`` short name wins, then the Accept header, then the default.
    ``only`` narrows the offer (the Graph Store protocol writes fewer formats), its first the default.

    Kept for the last 256 requests' headers: clients send the same few, and parsing one costs more
    than a point lookup's evaluation."""
    offered = list(only if only is not None else GRAPH_TYPES if graph else RESULT_TYPES)
    if short_format:
        name = short_format.partition(";")[0].strip().lower()  # JSON, or a media type with its charset
        names = SHORT_NAMES.get(name)
        if names is not None:
            return names[1] if graph else names[0]
        media = _offered_alias(graph, name, offered)
        if media in offered:
            return media
        raise NotAcceptableError(short_format, sorted(SHORT_NAMES))
    ranges = accept_ranges(accept) if accept else []
    if not ranges:  # no header, or nothing in it that reads as a media range: the default
        return offered[0]
    ranges = [(_offered_alias(graph, media, offered), quality) for media, quality in ranges]
    best = MIMEAccept(ranges).best_match(offered)
    if best is None:
        raise NotAcceptableError(accept or "", offered[:4])
    return best


def _offered_alias(graph: bool, media: str, offered: list[str]) -> str:
    """``media`` as one of the ``offered`` types when Oxigraph reads it as that format
    (``application/x-turtle``, ``application/x-sparql-results+json``, ``text/tsv``), else as it is."""
    if media in offered or "*" in media:
        return media
    known = ox.RdfFormat.from_media_type(media) if graph else ox.QueryResultsFormat.from_media_type(media)
    canonical = known.media_type.partition(";")[0] if known is not None else media  # text/csv; charset=utf-8
    return canonical if canonical in offered else media


def accept_ranges(accept: str) -> list[tuple[str, float]]:
    """The media ranges of an Accept header with their qualities, each without its other parameters.

    Werkzeug matches ``application/sparql-results+json; charset=utf-8`` only with an offer that carries
    the same parameter, so a client asking for UTF-8 JSON (which every answer here is) got 406; the
    parameters name nothing cbrs could answer differently, so only ``q`` is kept. A range that is not
    ``type/subtype`` is left out, and a ``q`` that is not a number counts as 1, as lenient servers read it."""
    ranges: list[tuple[str, float]] = []
    for part in accept.split(","):
        media, *parameters = part.split(";")
        media = media.strip().lower()
        kind, slash, subtype = media.partition("/")
        if not (kind and slash and subtype) or "/" in subtype:
            continue
        quality = 1.0
        for parameter in parameters:
            name, _, value = parameter.partition("=")
            if name.strip().lower() == "q":
                try:
                    quality = min(max(float(value.strip()), 0.0), 1.0)
                except ValueError:
                    quality = 1.0
                if quality != quality:  # nan
                    quality = 1.0
        ranges.append((media, quality))
    return ranges
