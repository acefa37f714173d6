"""A cbrs store on a SPARQL 1.1 server, spoken to with the SPARQL 1.1 Protocol over HTTP.

Oxigraph server (``oxigraph serve --location DIR --bind HOST:PORT --union-default-graph``) is the
reference; any endpoint with SPARQL 1.1 Update whose default graph is the union of its named graphs
will do. See docs/remote-store.md.

Three rules keep it equivalent to the embedded store:

- **Union default graph.** cbrs queries see all named graphs as their default graph. The server must
  do the same; it is checked at open (and, while the server holds no data, before each query).
- **Bound values are never pasted as text.** A query's bindings go in as a ``VALUES`` block, the first
  element of the query's top-level group pattern, so they pre-bind the pattern as Oxigraph's
  substitutions do (a trailing ``VALUES`` clause would join after ``GROUP BY`` and ``LIMIT``). Terms
  are written by pyoxigraph's serialiser, which has validated every IRI and escapes every literal.
- **Queries by form POST.** ``query=`` in an ``application/x-www-form-urlencoded`` body is the one
  way every SPARQL 1.1 server answers (Virtuoso 7 never answers a ``application/sparql-query`` body);
  updates go as an ``application/sparql-update`` body, which Oxigraph, Fuseki and Virtuoso all take.
- **One write, one operation.** A server need not run a request of several operations as one
  transaction (Virtuoso 7 does not), but every server keeps one operation whole. ``add`` of up to
  ``batch`` quads sends one ``INSERT DATA``; a larger one is staged in batches and published by one
  operation (:mod:`kb.staged_writes`); ``replace`` sends one ``DELETE { } INSERT { } WHERE { }``. A
  failed write leaves the store as it was.
"""

from __future__ import annotations

import functools
import re
import ssl
from collections.abc import Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import NamedTuple
from urllib.parse import urlencode

import httpx
import pyoxigraph as ox

from cbrs.kb.errors import BindingError, QuerySyntaxError, RemoteStoreError, StoreError, StoreEvaluationError
from cbrs.kb.namespaces import PREFIXES, GraphName
from cbrs.kb.remote_access import refuse_remote_access
from cbrs.kb.results import releases_results
from cbrs.kb.served_updates import HEADER as CBRS_HEADER
from cbrs.kb.served_updates import claims_checked, refusal
from cbrs.kb.staged_writes import write_staged
from cbrs.kb.store import QueryResult, Store, Term, data_block, refuse_deep_nesting

DEFAULT_TIMEOUT = 60.0  # seconds to wait for an answer (the seed takes well under one)
CONNECT_TIMEOUT = 5.0
DEFAULT_BATCH = 250
"""The most quads one write request carries (setting ``remote_batch``) on a server that is not Oxigraph;
a larger write is staged (:mod:`kb.staged_writes`). Virtuoso 7 refuses an ``INSERT DATA`` of about 1,400
simple triples and compiles large ones slowly: 20,000 quads took 6 s in batches of 250, 18 s in 1000s."""
OXIGRAPH_BATCH = 100_000
"""The same on Oxigraph server, where one request is one transaction and the quickest write; it takes
bodies up to 128 MiB, some 900,000 quads, so larger writes are still staged."""
CHECK_BATCH = 5_000
"""The most quads one existence check (:meth:`RemoteStore.contains_each`, what a load asks before it
writes) names: about 1 MB of query text. On Oxigraph server the size mattered little (over 56,258 quads,
chunks of 500, 2,000 and 10,000 took 3.1, 3.0 and 2.4 s); a smaller :attr:`RemoteStore.batch` caps it."""

# One line, so the server's "error at LINE:COLUMN" is off by exactly one line (corrected in errors).
PROLOGUE = " ".join(f"PREFIX {prefix}: <{namespace}>" for prefix, namespace in PREFIXES.items()) + "\n"
# From Oxigraph, TSV first: lossless (N-Triples terms) and the quickest to write and read. Other
# servers' TSV need not be SPARQL 1.1's (Virtuoso 7 writes IRIs as quoted strings), so JSON first.
_ACCEPT_OXIGRAPH = (
    "text/tab-separated-values, application/sparql-results+json;q=0.9, application/sparql-results+xml;q=0.8, "
    "application/n-triples, text/turtle;q=0.9"
)
# Some servers (Virtuoso 7) pick the first type listed whatever the query form, so ask by form.
_ACCEPT_RESULTS = "application/sparql-results+json, application/sparql-results+xml;q=0.9"
_ACCEPT_GRAPH = "application/n-triples, text/turtle;q=0.9"
_FORM = "application/x-www-form-urlencoded"
_POSITION = re.compile(r"\berror at (\d+):(\d+)")
# Virtuoso's SR186 "No permission to execute procedure": its SPARQL user may not update until granted.
_VIRTUOSO_GRANT = (
    "Virtuoso's SPARQL user may not update: grant it SPARQL_UPDATE "
    """(isql-vt 1111 dba PASSWORD 'exec=grant SPARQL_UPDATE to "SPARQL";', docs/remote-store.md)"""
)

# Whether the server's default graph is the union: a quad from a named graph, and whether the
# default graph shows it. No row: the server holds no named-graph data yet, so it cannot tell.
_UNION_PROBE = (
    "SELECT ?seen WHERE { { SELECT ?s ?p ?o WHERE { GRAPH ?g { ?s ?p ?o } } LIMIT 1 } "
    "BIND (EXISTS { ?s ?p ?o } AS ?seen) }"
)


@dataclass(frozen=True)
class Endpoints:
    """Where a remote store sends queries and updates."""

    query: str
    update: str
    update_guessed: bool = field(default=False, compare=False)
    """Whether ``update`` was guessed from a single query URL: a server that answers 404 there takes
    updates at the query URL instead (Virtuoso's one ``/sparql``, which SPARQL 1.1 allows)."""

    @classmethod
    def discover(cls, location: str) -> Endpoints:
        """The endpoints a ``--store`` URL names.

        - ``http://host:7878`` (or any other base, e.g. Fuseki's ``http://host:3030/ds``): the Oxigraph
          layout, ``<base>/query`` and ``<base>/update``;
        - a URL ending in ``/query`` or ``/sparql`` is the query endpoint, with ``update`` beside it;
        - two URLs separated by white space are the query and the update endpoint, as given.
        """
        parts = location.split()
        if len(parts) == 2:
            return cls(_checked_url(location, parts[0]), _checked_url(location, parts[1]))
        if len(parts) != 1:
            raise StoreError(location, "give one endpoint URL, or a query URL and an update URL separated by a space")
        url = httpx.URL(_checked_url(location, parts[0]))
        path = url.path.rstrip("/")
        head, _, last = path.rpartition("/")
        if last in ("query", "sparql"):
            return cls(str(url.copy_with(path=path)), str(url.copy_with(path=f"{head}/update")), True)
        return cls(str(url.copy_with(path=f"{path}/query")), str(url.copy_with(path=f"{path}/update")), True)

    @classmethod
    def candidates(cls, location: str) -> list[Endpoints]:
        """The endpoints to try for ``location``: what :meth:`discover` says, and for a bare base URL
        (no path) also a ``cbrs serve``'s layout, ``<base>/sparql`` and ``<base>/update``, so that
        ``--store http://host:8080`` reaches a running cbrs server as well as an Oxigraph one."""
        found = [cls.discover(location)]
        parts = location.split()
        if len(parts) == 1 and httpx.URL(parts[0]).path.rstrip("/") == "":
            base = parts[0].rstrip("/")
            found.append(cls(_checked_url(location, base + "/sparql"), _checked_url(location, base + "/update")))
        return found


def _checked_url(location: str, text: str) -> str:
    try:
        url = httpx.URL(text)
    except httpx.InvalidURL as error:
        raise StoreError(location, f"not a valid endpoint URL: {error}") from error
    if url.scheme not in ("http", "https") or not url.host:
        raise StoreError(location, f"{text!r} is not an http:// or https:// URL with a host")
    return str(url)


class RemoteStore(Store):
    """A store on a SPARQL 1.1 endpoint with update. Thread-safe: one pooled HTTP client."""

    def __init__(
        self,
        location: str,
        endpoints: Endpoints,
        timeout: float = DEFAULT_TIMEOUT,
        token: str | None = None,
        batch: int | None = None,
    ) -> None:
        self.location = location
        self.endpoints = endpoints
        self.timeout = timeout
        self._batch: int | None = None
        if batch is not None:
            self.batch = batch
        headers = {"User-Agent": "cbrs-kb"}
        token = token.strip() if token else token  # a file read whole keeps its line end, which no header may carry
        if token:  # a cbrs server takes updates with its bearer token; Oxigraph's server ignores it
            headers["Authorization"] = f"Bearer {token}"
        self._token_sent = bool(token)
        self._client: httpx.Client | None = httpx.Client(
            timeout=httpx.Timeout(timeout, connect=min(timeout, CONNECT_TIMEOUT)),
            headers=headers,
            verify=_tls_context(),
        )
        self._union_verified = False
        # learnt from the Server header of each answer: whether TSV can be asked for (Oxigraph), and
        # whether bound values go in as BIND clauses (Virtuoso, see _binds)
        self._oxigraph = False
        self._virtuoso = False
        self._cbrs = False  # a cbrs serve (its Cbrs-Server header), and whether it says its updates are checked
        self._checks_updates = False

    @classmethod
    def open(
        cls,
        location: str | Path,
        timeout: float = DEFAULT_TIMEOUT,
        token: str | None = None,
        batch: int | None = None,
    ) -> RemoteStore:
        """Connect to the endpoint(s) ``location`` names and check its default graph is the union;
        ``token`` is sent as a bearer token (a ``cbrs serve``'s update token); ``batch`` is the most
        quads one write request carries (None: chosen by the server, see :attr:`batch`)."""
        text = str(location).strip()
        first_error: StoreError | None = None
        for endpoints in Endpoints.candidates(text):
            store = cls(text, endpoints, timeout, token, batch)
            try:
                store._check_union()
            except StoreError as error:
                store.close()
                if isinstance(error.__cause__, httpx.TransportError):
                    raise  # nothing answered at that host and port: the next layout is no nearer
                first_error = first_error or error
                continue
            except BaseException:
                store.close()
                raise
            return store
        assert first_error is not None
        raise first_error

    @property
    def batch(self) -> int:
        """The most quads one write request carries: as given, else :data:`OXIGRAPH_BATCH` on Oxigraph
        server and :data:`DEFAULT_BATCH` on any other (known from the answer to the open's first query)."""
        if self._batch is not None:
            return self._batch
        return OXIGRAPH_BATCH if self._oxigraph else DEFAULT_BATCH

    @batch.setter
    def batch(self, quads: int) -> None:
        if quads < 1:
            raise StoreError(self.location, f"a batch must be at least 1 quad, not {quads}")
        self._batch = quads

    def close(self) -> None:
        if self._client is not None:
            self._client.close()
            self._client = None

    def flush(self) -> None:
        """Nothing to do: the server has committed every write it acknowledged."""
        self._http()

    # -- reading ---------------------------------------------------------------------------

    def query(self, text: str, bindings: Mapping[str, Term] | None = None) -> QueryResult:
        """Run a SPARQL query on the server, ``bindings`` sent as a leading ``VALUES`` block."""
        refuse_deep_nesting(text)
        refuse_remote_access(text, self.remote_access)
        if not self._union_verified:
            self._check_union()
        bind = self._binds(text)
        ordered = self._virtuoso and _closures_end_fixed(text) and (bind or not bindings)
        if not bindings:
            return self._query(text, original=text, ordered=ordered)
        return self._query(inject_values(text, bindings, bind=bind), original=text, ordered=ordered)

    def query_dataset(
        self, text: str, default_graphs: Sequence[str] | None = None, named_graphs: Sequence[str] | None = None
    ) -> QueryResult:
        """Run a query over another dataset than the union default graph: the query's own ``FROM`` /
        ``FROM NAMED`` when both lists are ``None``, else these graphs, sent as the protocol's
        ``default-graph-uri`` and ``named-graph-uri`` (which the server applies over any ``FROM``)."""
        refuse_deep_nesting(text)
        refuse_remote_access(text, self.remote_access)
        params = [("default-graph-uri", iri) for iri in default_graphs or ()]
        params += [("named-graph-uri", iri) for iri in named_graphs or ()]
        return self._query(text, original=text, params=params)

    def select_each(self, queries: Sequence[tuple[str, Mapping[str, Term]]]) -> list[list[dict[str, Term]]]:
        """The rows of each SELECT query, asked for in one request (a round trip each cost a run a
        request per query: reading one description took six): each query, its values bound as
        :meth:`query` binds them, becomes a sub-SELECT in one branch of a ``UNION``, its rows tagged with
        its number and ordered as its own ``ORDER BY`` says (:func:`union_of_selects`). A query that
        cannot go in a branch (not a SELECT, a prologue of its own, an ``ORDER BY`` of expressions) is
        asked alone, so the answers are those of :meth:`query` either way. So is every query on Virtuoso 7,
        which refused the taxonomy's four queries so joined ("SQ142: Different number of expected and
        generated columns in a select") though it took the other pairs tried."""
        if len(queries) < 2 or self._virtuoso:
            return super().select_each(queries)
        texts = []
        for text, bindings in queries:
            refuse_deep_nesting(text)
            refuse_remote_access(text, self.remote_access)
            texts.append(inject_values(text, bindings, bind=self._binds(text)) if bindings else text)
        combined = union_of_selects(texts)
        if combined is None:
            return super().select_each(queries)
        if not self._union_verified:
            self._check_union()
        return _split_parts(self._query(combined), len(queries))

    @releases_results
    def quads(
        self,
        subject: ox.NamedNode | ox.BlankNode | None = None,
        predicate: ox.NamedNode | None = None,
        object: Term | None = None,
        graph: ox.NamedNode | ox.DefaultGraph | None = None,
    ) -> Iterator[ox.Quad]:
        given = {"s": subject, "p": predicate, "o": object, "g": graph}
        fixed = {
            name: term for name, term in given.items() if isinstance(term, ox.NamedNode | ox.BlankNode | ox.Literal)
        }
        query = inject_values(f"SELECT ?s ?p ?o ?g WHERE {{ {_graph_pattern('?s ?p ?o', graph)} }}", fixed)
        result, cut = self._answer(query)
        assert isinstance(result, ox.QuerySolutions)
        found = [ox.Quad(*row) for row in result]  # an unbound ?g is the default graph
        return iter(found) if cut is None else self._paged(query, cut, found)

    def _paged(self, query: str, page: int, first: list[ox.Quad]) -> Iterator[ox.Quad]:
        """The quads of ``query`` (``?s ?p ?o ?g``) whose answer the server cut short (Virtuoso sends
        ResultSetMaxRows rows, 10,000 by default, and says so only in a header: an export of OWLS-TC held
        10,000 of each graph's triples): ``first``, the cut answer, then the rest a page of ``page`` rows at
        a time, read only when asked for (a caller that wants one quad reads no page). The order is fixed
        in a subquery and the page taken outside it: Virtuoso refuses an ORDER BY with an OFFSET past its
        MaxSortedTopRows, but not this."""
        yield from first
        seen, offset = set(first), 0
        while True:
            text = f"SELECT ?s ?p ?o ?g WHERE {{ {{ {query} ORDER BY ?s ?p ?o ?g }} }} LIMIT {page} OFFSET {offset}"
            result, _ = self._answer(text)  # no more than the most it sends: not cut, whatever it says
            assert isinstance(result, ox.QuerySolutions)
            rows = [ox.Quad(*row) for row in result]
            yield from (quad for quad in rows if quad not in seen)  # the pages do not overlap; the cut answer may
            offset += len(rows)
            if len(rows) < page:
                return

    def dataset_nquads(self) -> bytes | None:
        """Every quad of the store as N-Quads, in one ``GET`` of Oxigraph server's graph store endpoint
        (``<base>/store`` beside ``<base>/query``), for pyoxigraph to parse whole; None on another server
        or layout, or if it does not answer so (read :meth:`quads` then). On the bundled store's 8,000
        quads it took 58 ms against :meth:`quads`' 91 ms, which builds each row's quad in Python."""
        if not self._oxigraph or not self.endpoints.query.endswith("/query"):
            return None
        url = self.endpoints.query.removesuffix("query") + "store"
        try:
            response = self._http().get(url, headers={"Accept": "application/n-quads"})
        except httpx.HTTPError:
            return None
        media = response.headers.get("content-type", "").split(";")[0].strip().lower()
        return response.content if response.status_code == 200 and media == "application/n-quads" else None

    @releases_results
    def count(self, graph: GraphName | ox.NamedNode | None = None) -> int:
        node = graph.node if isinstance(graph, GraphName) else graph
        result = self._query(f"SELECT (COUNT(*) AS ?n) WHERE {{ {_graph_pattern('?s ?p ?o', node)} }}")
        assert isinstance(result, ox.QuerySolutions)
        return int(next(iter(result))["n"].value)

    @releases_results
    def graphs(self) -> list[str]:
        # Virtuoso 7 matches no graph with an empty pattern, and lists no empty graph either way; it answers
        # GROUP BY ?g from its graph index, but DISTINCT ?g by reading every quad (0.2 s against 10 s on the
        # OWLS-TC store, docs/remote-store.md). Oxigraph lists its empty graphs too, from the empty pattern.
        text = (
            "SELECT ?g WHERE { GRAPH ?g { ?s ?p ?o } } GROUP BY ?g"
            if self._virtuoso
            else "SELECT DISTINCT ?g WHERE { GRAPH ?g { } }"
        )
        result = self._query(text)
        assert isinstance(result, ox.QuerySolutions)
        return sorted(row["g"].value for row in result if isinstance(row["g"], ox.NamedNode))

    def is_seeded(self) -> bool:
        return bool(self._query(f"ASK {{ GRAPH {GraphName.ONTOLOGY.node} {{ ?s ?p ?o }} }}"))

    @releases_results
    def contains_each(self, quads: Sequence[ox.Quad]) -> list[bool]:
        """Whether the store holds each of ``quads``, one query per graph and chunk of :attr:`check_batch`
        quads (a request per quad cost a reload of OWLS-TC 4 minutes): the chunk goes in as a ``VALUES``
        block of numbered rows, written by pyoxigraph's serialiser (:func:`sparql_term`), and the server
        answers the numbers of the rows its graph holds. The server matches each row as it keeps its
        terms (``"0.50"^^xsd:decimal`` is held as ``"0.5"``), as :meth:`contains` does. Virtuoso 7 joins
        no language-tagged literal from a ``VALUES`` block (1,204 of the seed's 6,153 quads were missed),
        so there those rows are asked as a ``UNION`` of ground patterns, ten times slower per row.

        A quad with a blank node is never held (a blank node names nothing on the server; :meth:`add`
        makes a fresh one); one in the default graph or with a quoted triple, which a row cannot match
        alone, is asked with :meth:`contains`."""
        found = [False] * len(quads)
        by_graph: dict[tuple[ox.NamedNode, bool], list[int]] = {}
        for index, quad in enumerate(quads):
            terms = (quad.subject, quad.object, quad.graph_name)
            if any(isinstance(term, ox.BlankNode) for term in terms):
                continue
            if isinstance(quad.graph_name, ox.NamedNode) and not any(isinstance(t, ox.Triple) for t in terms):
                ground = self._virtuoso and isinstance(quad.object, ox.Literal) and quad.object.language is not None
                by_graph.setdefault((quad.graph_name, ground), []).append(index)
            else:
                found[index] = self.contains(quad)
        size = self.check_batch
        for (graph, ground), indices in by_graph.items():
            for start in range(0, len(indices), size):
                rows = [(index, *_written_triple(quads[index])) for index in indices[start : start + size]]
                if ground:
                    branches = " UNION ".join(
                        f"{{ GRAPH {graph} {{ {s} {p} {o} }} BIND ({i} AS ?i) }}" for i, s, p, o in rows
                    )
                    text = f"SELECT ?i WHERE {{ {branches} }}"
                else:
                    values = "\n".join(f"({i} {s} {p} {o})" for i, s, p, o in rows)
                    text = f"SELECT ?i WHERE {{ VALUES (?i ?s ?p ?o) {{\n{values}\n}} GRAPH {graph} {{ ?s ?p ?o }} }}"
                result = self._query(text, direct=True)
                assert isinstance(result, ox.QuerySolutions)
                for row in result:
                    found[int(row["i"].value)] = True
        return found

    @property
    def rewrites_held(self) -> bool:
        """Whether a load writes every quad, held or not (:func:`kb.loader.load_files`): on Virtuoso a read
        right after a ``DROP GRAPH`` could still find what the drop removed (the seed after a cleared
        store then came up short, intermittently, in the test suite); writing a held quad again is a
        no-op, so its loads write all, as they did before the existence check. Its counts still come
        from the check."""
        return self._virtuoso

    @property
    def server(self) -> str:
        """Which server answers, from the ``Server`` header of its last answer: ``oxigraph``, ``virtuoso``,
        or ``other``."""
        return "oxigraph" if self._oxigraph else "virtuoso" if self._virtuoso else "other"

    @property
    def checks_updates(self) -> bool:
        """Whether the server is a ``cbrs serve`` that runs every update through the embedded store's checks,
        all or nothing, and brings graph:entailed up to date, as its ``Cbrs-Server`` header says
        (:mod:`kb.served_updates`), known from the open's first answer on: a checked update is then sent as
        it is rather than carried out first on a copy of the store (:mod:`kb.remote_updates`)."""
        return self._checks_updates

    @property
    def keeps_requests_whole(self) -> bool:
        """Whether the server runs an update request of several operations as one transaction: not Virtuoso
        7, which keeps what the first wrote when a later one fails (:mod:`kb.update_report` refuses such a
        text there)."""
        return not self._virtuoso

    @property
    def check_batch(self) -> int:
        """The most quads one :meth:`contains_each` query asks about: :attr:`batch`, at most
        :data:`CHECK_BATCH` (on Oxigraph, a larger chunk took no less time)."""
        return min(self.batch, CHECK_BATCH)

    # -- writing ---------------------------------------------------------------------------

    def add(self, quads: Iterable[ox.Quad]) -> None:
        """Add ``quads`` all or nothing: up to :attr:`batch` of them as one ``INSERT DATA`` operation,
        more through staging graphs published by one operation (:mod:`kb.staged_writes`).

        Blank nodes become fresh nodes on the server (the loader skolemises them before this).
        """
        quads = self._as_kept(quads)
        if len(quads) > self.batch:
            write_staged(self.location, quads, self.batch, lambda text: self._update(text, original=None))
            return
        block = data_block(quads, blank_nodes=True)
        if block:
            self._update("INSERT DATA {\n" + block + "}", original=None)

    def replace(self, remove: Iterable[ox.Quad], add: Iterable[ox.Quad]) -> None:
        """Remove and add quads in one request: ``DELETE DATA`` then ``INSERT DATA``, which a cbrs server reads
        as a data update (it follows it in graph:entailed statement by statement, :mod:`kb.update_delta`); on
        a server that does not keep a request of two operations whole (Virtuoso 7), one ``DELETE { } INSERT
        { } WHERE { }`` operation, which it does keep whole."""
        self._write_blocks(data_block(self._as_kept(remove)), data_block(self._as_kept(add)))

    def write_change(
        self,
        remove: Iterable[ox.Quad],
        add: Iterable[ox.Quad],
        dropped: Sequence[ox.NamedNode] = (),
        created: Sequence[ox.NamedNode] = (),
    ) -> None:
        """:meth:`replace` of a change worked out on a copy of the store (:mod:`kb.remote_updates`), whose
        added quads may hold blank nodes the store does not: fresh nodes there, as :meth:`add` makes. The
        graphs ``dropped`` are gone afterwards and those ``created`` there, if empty (Oxigraph keeps empty
        graphs), in the same request; on a server that keeps no empty graph (Virtuoso 7) they are left out."""
        removing, adding = data_block(self._as_kept(remove)), data_block(self._as_kept(add), blank_nodes=True)
        graphs = [f"DROP SILENT GRAPH {g}" for g in dropped] + [f"CREATE SILENT GRAPH {g}" for g in created]
        if not graphs or not self.keeps_requests_whole:
            self._write_blocks(removing, adding)
            return
        data = [f"DELETE DATA {{\n{removing}}}"] * bool(removing) + [f"INSERT DATA {{\n{adding}}}"] * bool(adding)
        self._update(" ;\n".join([*data, *graphs]), original=None)

    def _write_blocks(self, removing: str, adding: str) -> None:
        """Remove the quads of one data block and add those of another, in one request."""
        if removing and adding and self.keeps_requests_whole:
            self._update(f"DELETE DATA {{\n{removing}}} ;\nINSERT DATA {{\n{adding}}}", original=None)
        elif removing and adding:
            self._update(f"DELETE {{\n{removing}}}\nINSERT {{\n{adding}}}\nWHERE {{ }}", original=None)
        elif removing:
            self._update("DELETE DATA {\n" + removing + "}", original=None)
        elif adding:
            self._update("INSERT DATA {\n" + adding + "}", original=None)

    def replace_graph(self, graph: ox.NamedNode, quads: Iterable[ox.Quad]) -> None:
        """As the embedded store: one ``DELETE { } INSERT { } WHERE { }`` operation (one request), the
        graph's old statements not read first."""
        super().replace_graph(graph, self._as_kept(quads))

    def _as_kept(self, quads: Iterable[ox.Quad]) -> list[ox.Quad]:
        """``quads`` as the server keeps them when written: on Virtuoso, an ``xsd:decimal`` with a point
        (:func:`decimal_kept`)."""
        return [decimal_kept(quad) for quad in quads] if self._virtuoso else list(quads)

    def _apply_own_update(self, text: str) -> None:
        """An update cbrs wrote itself from validated terms (a staged batch, a publication): sent as it is,
        and a 400 for it is the server's refusal (:class:`RemoteStoreError`), not the caller's syntax."""
        self._update(text, original=None)

    def update(self, text: str) -> None:
        """Run a SPARQL update on the server in one request, hence one transaction."""
        refuse_deep_nesting(text)
        refuse_remote_access(text, self.remote_access)
        self._update(text, original=text)

    # -- the wire ----------------------------------------------------------------------------

    def _http(self) -> httpx.Client:
        if self._client is None:
            raise StoreError(self.location, "is closed")
        return self._client

    def _binds(self, text: str) -> bool:
        """Whether to bind values with BIND clauses rather than a VALUES block: on Virtuoso 7, which starts
        no transitive path (``p*``, ``p+``) from a VALUES block and mis-joins it elsewhere too, except in
        a query that aggregates with GROUP_CONCAT or SAMPLE, whose groups Virtuoso collapses into one
        after a BIND. Both forms give the one solution a substitution gives (docs/remote-store.md)."""
        if not self._virtuoso:
            return False
        names = {token.text.upper() for token in _tokens(text) if token.kind == "name"}
        return not names & {"GROUP_CONCAT", "SAMPLE"}

    @releases_results
    def _check_union(self) -> None:
        result = self._query(_UNION_PROBE)
        assert isinstance(result, ox.QuerySolutions)
        rows = list(result)
        if not rows:
            return  # no named-graph data yet; checked again before the next query
        seen = rows[0]["seen"]
        if not (isinstance(seen, ox.Literal) and seen.value in ("true", "1")):  # Virtuoso 7 says 1
            host = httpx.URL(self.endpoints.query)
            raise StoreError(
                self.location,
                "the server's default graph is not the union of its named graphs, which cbrs queries "
                "rely on; start Oxigraph with --union-default-graph (oxigraph serve --location DIR "
                f"--bind {host.host}:{host.port or 7878} --union-default-graph), or configure your "
                "server's union default graph (docs/remote-store.md)",
            )
        self._union_verified = True

    def _query(
        self,
        text: str,
        original: str | None = None,
        params: Sequence[tuple[str, str]] = (),
        direct: bool = False,
        ordered: bool = False,
    ) -> QueryResult:
        """POST a query as a form; with ``direct``, to a server known to be Oxigraph, as the request's body
        (``application/sparql-query``), which spares encoding a long text: over the 142,845 quads a reload
        of OWLS-TC 4 asks about, 1.4 s against 2.7 s. An answer the server cut short is refused (only
        :meth:`quads` reads one in pages): a rule's conclusions cut at 10,000 rows emptied most of
        graph:entailed on Virtuoso. With ``ordered``, Virtuoso joins the patterns in the order written
        (:data:`_IN_WRITTEN_ORDER`)."""
        result, cut = self._answer(text, original, params, direct, ordered)
        if cut is not None:
            raise StoreError(
                self.location,
                f"the server sent only the first {cut} rows of an answer (Virtuoso: ResultSetMaxRows in the [SPARQL] "
                "section of virtuoso.ini; raise it above the store's size), so the answer is short; nothing was "
                "taken from it (docs/remote-store.md)",
            )
        return result

    def _answer(
        self,
        text: str,
        original: str | None = None,
        params: Sequence[tuple[str, str]] = (),
        direct: bool = False,
        ordered: bool = False,
    ) -> tuple[QueryResult, int | None]:
        """:meth:`_query`'s result, and the most rows the server sends when it cut the result short
        (Virtuoso's ``X-SPARQL-MaxRows`` header, its ResultSetMaxRows: 10,000 by default), else None."""
        if self._oxigraph:
            accept = _ACCEPT_OXIGRAPH
        else:
            forms = (t.text.upper() for t in _tokens(text) if t.kind == "name" and t.text.upper() in _FORMS)
            accept = _ACCEPT_GRAPH if next(forms, "SELECT") in ("CONSTRUCT", "DESCRIBE") else _ACCEPT_RESULTS
        prologue = _IN_WRITTEN_ORDER + PROLOGUE if ordered else PROLOGUE
        if direct and self._oxigraph and not params:
            body, content_type = prologue + text, "application/sparql-query"
        else:
            body, content_type = urlencode([("query", prologue + text), *params]), _FORM
        response = self._post(self.endpoints.query, body, content_type, original, readable=text, accept=accept)
        media = response.headers.get("content-type", "").split(";")[0].strip().lower()
        said = response.headers.get("x-sparql-maxrows", "")
        cut = int(said) if said.isdigit() and int(said) > 0 else None
        try:
            results_format = ox.QueryResultsFormat.from_media_type(media) if media else None
            if results_format is not None:
                return ox.parse_query_results(response.content, results_format), cut
            rdf_format = ox.RdfFormat.from_media_type(media) if media else None
            if rdf_format is not None:
                return _query_triples(ox.parse(response.content, rdf_format)), cut
        except SyntaxError as error:
            raise StoreError(self.location, f"unreadable answer from {self.endpoints.query}: {error}") from error
        raise StoreError(self.location, f"{self.endpoints.query} answered in an unexpected format {media!r}")

    def _update(self, text: str, original: str | None) -> None:
        body = _prologued(text, original)
        try:
            self._post(self.endpoints.update, body, "application/sparql-update", original)
        except RemoteStoreError as error:
            # nothing listens at a guessed update URL: the query URL takes updates too (Virtuoso's /sparql)
            if error.status != 404 or not self.endpoints.update_guessed:
                raise
            self.endpoints = Endpoints(self.endpoints.query, self.endpoints.query)
            self._post(self.endpoints.update, body, "application/sparql-update", original)

    def _post(
        self,
        url: str,
        body: str,
        content_type: str,
        original: str | None,
        readable: str | None = None,
        accept: str | None = None,
    ) -> httpx.Response:
        """POST ``body``; ``original`` is the caller's own text (None for text cbrs wrote), ``readable`` the
        text an error shows when ``body`` is encoded."""
        headers = {"Content-Type": content_type}
        if accept is not None:
            headers["Accept"] = accept
        try:
            response = self._http().post(url, content=body.encode("utf-8"), headers=headers)
        except httpx.ConnectError as error:
            hint = start_hint(self.location)
            raise StoreError(self.location, f"cannot connect to {url} ({error}); {hint}") from error
        except httpx.ConnectTimeout as error:
            connect = min(self.timeout, CONNECT_TIMEOUT)
            tls = " (an https:// URL needs a server that speaks TLS; oxigraph serve speaks http://)"
            raise StoreError(
                self.location,
                f"no connection to {url} within {connect:g} s{tls if url.startswith('https:') else ''}",
            ) from error
        except httpx.TimeoutException as error:
            raise StoreError(self.location, f"{url} did not answer within {self.timeout:g} s") from error
        except httpx.RemoteProtocolError as error:  # a listener that speaks no HTTP, as a rosbridge websocket
            raise StoreError(
                self.location,
                f"{url} closed the connection without an HTTP answer ({error}): is it a SPARQL endpoint? A cbrs "
                "serve's is on its HTTP port (8080 by default), not its bridge port (9090)",
            ) from error
        except httpx.HTTPError as error:
            raise StoreError(self.location, f"request to {url} failed: {error}") from error
        server = response.headers.get("server", "").lower()
        self._oxigraph = server.startswith("oxigraph/")
        self._virtuoso = server.startswith("virtuoso/")
        cbrs = response.headers.get(CBRS_HEADER)
        self._cbrs, self._checks_updates = cbrs is not None, claims_checked(cbrs)
        if response.is_success:
            return response
        if self._cbrs and original is not None and 400 <= response.status_code < 500:
            fixed = functools.partial(_POSITION.sub, _one_line_up)
            refused = refusal(self.location, url, response.status_code, response.content, original, fixed)
            if refused is not None:  # a check's refusal, in the embedded store's words (kb/served_updates.py)
                raise refused
        message = _POSITION.sub(_one_line_up, response.text.strip())
        status = response.status_code
        too_large = status == 413 or "limited to" in message
        if status == 400 and original is not None and not too_large:
            raise QuerySyntaxError(original, message)
        if status in (401, 403):
            media = response.headers.get("content-type", "").split(";")[0].strip().lower()
            message = self._refusal(status, url, "" if media == "text/html" else message)
        if status == 500:  # Oxigraph's (and Fuseki's) answer to an evaluation error; it rolled back
            operation = "update" if content_type == "application/sparql-update" else "query"  # one URL on Virtuoso
            if operation == "update" and self._virtuoso and "SR186" in message:
                message = f"{_VIRTUOSO_GRANT}; it said: {message}"
            raise StoreEvaluationError(self.location, operation, message, url, status, original or readable or body)
        raise RemoteStoreError(self.location, url, status, message, original or readable or body)

    def _refusal(self, status: int, url: str, said: str) -> str:
        """What to do about a 401 or 403, before what the server said (an HTML page is left out): a
        newcomer got a proxy's login page quoted back and no word of how cbrs sends credentials."""
        if status == 403 and "read-only" in said:  # a cbrs serve started --read-only, or without a token
            hint = "the server takes no updates (it is read-only), token or not"
        elif status == 401 and httpx.URL(url).username:
            hint = "the server refused the user name and password in the store URL"
        elif status == 401:
            hint = (
                "the server asks for credentials: put them in the store URL, http://USER:PASSWORD@HOST:PORT "
                "(HTTP basic authentication; set CBRS_STORE rather than --store, which others can see), "
                "or a bearer token in CBRS_UPDATE_TOKEN"
            )
        elif self._token_sent:
            hint = "the server refused the token sent (the cbrs command's CBRS_UPDATE_TOKEN, a program's remote_token)"
        else:  # a notebook with CBRS_UPDATE_TOKEN set was told to set it: only the cbrs command reads it
            hint = (
                "sent without a token: set CBRS_UPDATE_TOKEN (the cbrs command's), or a program passes "
                "KnowledgeBase.open(URL, remote_token=TOKEN)"
            )
        return f"{hint}; it said: {said}" if said else hint


CBRS_SERVE_PORT = 8080
"""``cbrs serve``'s default HTTP port (setting ``port``): a bare URL there is taken for a cbrs server."""
_SERVER_PORTS = {7878: "oxigraph", 8890: "virtuoso", 3030: "fuseki", CBRS_SERVE_PORT: "cbrs"}
"""The usual port of each kind of server: what a bare URL's port suggests is meant to answer there."""


def start_hint(location: str) -> str:
    """What to start when nothing answers at ``location``, judged from what the URL looks like: a path
    names the layout (``/query``: Oxigraph; ``/sparql``: a cbrs server, or Virtuoso on port 8890), a bare
    URL its port (8080: cbrs serve's default; 7878: Oxigraph's; 3030: Fuseki's). A user pointing at a
    stopped ``cbrs serve`` was told to start ``oxigraph serve``, another server holding other data."""
    url = httpx.URL(location.split()[0])
    port = url.port or (443 if url.scheme == "https" else 80)
    path = url.path.rstrip("/")
    oxigraph = f"oxigraph serve --location DIR --bind {url.host}:{port} --union-default-graph"
    cbrs = f"cbrs --store DIR serve --port {port}"
    kind = _SERVER_PORTS.get(port, "either") if path in ("", "/sparql") else None
    if path.endswith("/query") or (path == "" and kind == "oxigraph"):
        return f"is the SPARQL server running? Start one with: {oxigraph}"
    if kind == "virtuoso":
        return f"is Virtuoso running (one SPARQL endpoint at {url.host}:{port}/sparql; docs/remote-store.md)?"
    if path == "/sparql" or kind == "cbrs":
        also = f" (or, for an Oxigraph server at that address, {oxigraph})" if path == "" else ""
        return f"is the cbrs server running? Start one with: {cbrs}{also}"
    if kind == "fuseki" or path:
        return "is the SPARQL server running? (docs/remote-store.md lists the endpoints cbrs reaches)"
    return f"is the SPARQL server running? Start one with: {oxigraph}; or, for a cbrs server, {cbrs}"


@functools.cache
def _tls_context() -> ssl.SSLContext:
    """httpx's default TLS context, built once per process (building it costs some 20 ms)."""
    return httpx.create_ssl_context()


def _prologued(text: str, original: str | None) -> str:
    """The update as sent: after the prefixes, unless cbrs wrote it (``original`` None) with no prefixed
    name, every term a full IRI (its data blocks), which then goes after an empty line (errors' line
    numbers are corrected for one). A cbrs server checks the descriptions after an update that declares
    a prefix, which could spell their graphs' names (``kb.shapes.may_write_descriptions``): with the
    prefixes, every belief write a run makes had the server read graph:services and graph:requirements."""
    if original is None and not any(token.kind == "name" and ":" in token.text for token in _tokens(text)):
        return "\n" + text
    return PROLOGUE + text


def _one_line_up(match: re.Match[str]) -> str:
    line = int(match.group(1))
    return f"error at {line - 1 if line > 1 else line}:{match.group(2)}"


_DECIMAL = ox.NamedNode("http://www.w3.org/2001/XMLSchema#decimal")


def decimal_kept(quad: ox.Quad) -> ox.Quad:
    """``quad`` with an ``xsd:decimal`` object written with a point: Virtuoso 7 keeps ``"0"^^xsd:decimal``
    as an integer (its answers give it back as ``"0"^^xsd:integer``, so a load or a restore changed the
    datatype), and ``"0.0"^^xsd:decimal`` as the decimal it is (given back as ``"0"^^xsd:decimal``)."""
    term = quad.object
    if not isinstance(term, ox.Literal) or term.datatype != _DECIMAL or "." in term.value:
        return quad
    if not term.value.lstrip("+-").isdigit():
        return quad
    return ox.Quad(quad.subject, quad.predicate, ox.Literal(term.value + ".0", datatype=_DECIMAL), quad.graph_name)


def _query_triples(quads: Iterable[ox.Quad]) -> ox.QueryTriples:
    """CONSTRUCT and DESCRIBE results as the ``QueryTriples`` callers consume.

    pyoxigraph builds ``QueryTriples`` only from a query, so the triples are put in a scratch
    in-memory store and read back with ``CONSTRUCT WHERE``.
    """
    scratch = ox.Store()
    scratch.extend(quads)
    result = scratch.query("CONSTRUCT WHERE { ?s ?p ?o }")
    assert isinstance(result, ox.QueryTriples)
    return result


def _written_triple(quad: ox.Quad) -> tuple[str, str, str]:
    """A quad's subject, predicate and object as SPARQL text, by pyoxigraph's serialiser."""
    return sparql_term("s", quad.subject), sparql_term("p", quad.predicate), sparql_term("o", quad.object)


def _graph_pattern(triple: str, graph: ox.NamedNode | ox.DefaultGraph | None) -> str:
    """``triple`` in ``graph``; with ``None``, in any named graph (``?g``) or in the default graph alone.

    The server's default graph is the union, so its own triples are those in no named graph.
    """
    if isinstance(graph, ox.NamedNode):
        return f"GRAPH {graph} {{ {triple} }}"
    default_only = f"{triple} FILTER NOT EXISTS {{ GRAPH ?any {{ {triple} }} }}"
    if isinstance(graph, ox.DefaultGraph):
        return default_only
    return f"{{ GRAPH ?g {{ {triple} }} }} UNION {{ {default_only} }}"


def sparql_term(variable: str, term: object) -> str:
    """``term`` as SPARQL text, written by pyoxigraph (validated IRIs, escaped literals)."""
    if isinstance(term, ox.NamedNode | ox.Literal):
        return str(term)
    if isinstance(term, ox.BlankNode):
        raise BindingError(
            variable, term, "a blank node cannot be sent to a SPARQL endpoint (it names nothing there); bind an IRI"
        )
    raise BindingError(variable, term, "not an IRI or a literal")


# -- VALUES injection --------------------------------------------------------------------------


class _Token(NamedTuple):
    kind: str
    text: str
    start: int
    end: int


_LOCAL = r"""(?:[^\s{}()\[\]<>"',;#\\]|\\.)*"""
_TOKENS = re.compile(
    rf"""
      (?P<space>\s+)
    | (?P<comment>\#[^\n\r]*)
    | (?P<string>\"\"\"(?:[^"\\]|\\.|"(?!""))*\"\"\"
               |'''(?:[^'\\]|\\.|'(?!''))*'''
               |"(?:[^"\\\n\r]|\\.)*"
               |'(?:[^'\\\n\r]|\\.)*')
    | (?P<iri><[^<>"{{}}|^`\\\x00-\x20]*>)
    | (?P<variable>[?$]\w+)
    | (?P<name>[A-Za-z_\u00b7\u00c0-\uffff][\w.\-\u00b7\u00c0-\uffff]*(?::{_LOCAL})?|:{_LOCAL})
    | (?P<punct>[{{}}()])
    | (?P<other>.)
    """,
    re.VERBOSE | re.DOTALL,
)
_FORMS = {"SELECT", "ASK", "CONSTRUCT", "DESCRIBE"}
_MODIFIERS = {"GROUP", "HAVING", "ORDER", "LIMIT", "OFFSET", "VALUES"}


_IN_WRITTEN_ORDER = 'DEFINE sql:select-option "order"\n'
"""Virtuoso's pragma to join a query's patterns in the order written rather than in one its optimiser
picks from sampled statistics (docs/remote-store.md): some of its picks walked a transitive path from each
row of an earlier pattern and answered short, with no error."""


def _closures_end_fixed(text: str) -> bool:
    """Whether ``text`` has a transitive path (``p*``, ``p+``) and each one ends in a fixed term (an IRI or
    a prefixed name, not a variable): the paths Virtuoso walks right when it walks them first, whole, from
    that term. A prefixed name cannot hold ``*`` or ``+`` unescaped, so in a name token they are path
    operators; after an IRI or a ``)``, one is taken as one too."""
    tokens = _tokens(text)
    ends = []
    for index, token in enumerate(tokens):
        closes = token.kind == "name" and ("*" in token.text or "+" in token.text)
        if token.kind == "other" and token.text in "*+" and index > 0:
            before = tokens[index - 1]
            closes = before.kind == "iri" or (before.kind == "punct" and before.text == ")")
        if closes:
            ends.append(tokens[index + 1] if index + 1 < len(tokens) else None)
    return bool(ends) and all(end is not None and end.kind in ("iri", "name") for end in ends)


def _tokens(text: str) -> list[_Token]:
    """The tokens that matter for finding the group pattern: comments, strings and IRIs are skipped whole."""
    found = []
    for match in _TOKENS.finditer(text):
        kind = match.lastgroup or "other"
        if kind not in ("space", "comment"):
            found.append(_Token(kind, match.group(), match.start(), match.end()))
    return found


def _closing(tokens: list[_Token], index: int) -> int:
    """The index of the ``}`` closing the ``{`` at ``index``."""
    depth = 0
    for position in range(index, len(tokens)):
        text = tokens[position].text
        if tokens[position].kind == "punct" and text in "{}":
            depth += 1 if text == "{" else -1
            if depth == 0:
                return position
    raise ValueError("unbalanced braces")


def _written(bindings: Mapping[str, Term]) -> tuple[list[str], list[str]]:
    names, terms = [], []
    for name, value in bindings.items():
        try:
            names.append(str(ox.Variable(name)))
        except ValueError as error:
            raise BindingError(name, value, f"not a SPARQL variable name: {error}") from error
        terms.append(sparql_term(name, value))
    return names, terms


def values_block(bindings: Mapping[str, Term]) -> str:
    """`` VALUES (?a ?b) { (<x> "y") } `` for ``bindings``."""
    names, terms = _written(bindings)
    return f" VALUES ({' '.join(names)}) {{ ({' '.join(terms)}) }} "


def bind_block(bindings: Mapping[str, Term]) -> str:
    """`` BIND (<x> AS ?a) BIND ("y" AS ?b) `` for ``bindings``: opening a group, the same one solution as
    :func:`values_block`, in the form Virtuoso 7 takes as the start of a transitive property path."""
    names, terms = _written(bindings)
    return " " + " ".join(f"BIND ({term} AS {name})" for name, term in zip(names, terms, strict=True)) + " "


def inject_values(query: str, bindings: Mapping[str, Term], bind: bool = False) -> str:
    """``query`` with ``bindings`` as a ``VALUES`` block (``BIND`` clauses with ``bind``) opening its
    top-level group pattern.

    Comments, strings (all four quote forms), IRIs, and a CONSTRUCT template are skipped. A
    ``CONSTRUCT WHERE { T }`` becomes ``CONSTRUCT { T } WHERE { VALUES ... T }``; a ``DESCRIBE``
    without a WHERE clause gains one.
    """
    if not bindings:
        return query
    values = bind_block(bindings) if bind else values_block(bindings)
    tokens = _tokens(query)
    form = next((i for i, t in enumerate(tokens) if t.kind == "name" and t.text.upper() in _FORMS), None)
    if form is None:
        raise QuerySyntaxError(query, "cannot bind values: no SELECT, ASK, CONSTRUCT or DESCRIBE found")
    try:
        start = form + 1
        if tokens[form].text.upper() == "CONSTRUCT" and start < len(tokens):
            if tokens[start].text == "{":
                start = _closing(tokens, start) + 1  # skip the template
            else:
                return _expand_construct_where(query, tokens, form, values)
        depth = 0
        for token in tokens[start:]:
            if token.kind == "punct" and token.text in "()":
                depth += 1 if token.text == "(" else -1
            elif depth == 0 and token.kind == "punct" and token.text == "{":
                return query[: token.end] + values + query[token.end :]
            elif depth == 0 and token.kind == "name" and token.text.upper() in _MODIFIERS:
                return query[: token.start] + "WHERE {" + values + "}\n" + query[token.start :]
    except (ValueError, IndexError) as error:
        raise QuerySyntaxError(query, f"cannot bind values: {error}") from error
    return query + "\nWHERE {" + values + "}"


# -- several SELECT queries in one ---------------------------------------------------------------

_PART = "cbrs__part"
"""The variable numbering the query a row of :func:`union_of_selects` answers; ``cbrs__`` variables are
cbrs's own (a query using one is asked alone)."""


def union_of_selects(texts: Sequence[str]) -> str | None:
    """One SELECT query whose answer holds the rows of each of ``texts`` (SELECT queries, values bound):
    each is a sub-SELECT in a branch of a ``UNION`` that numbers its rows (``?cbrs__part``) and copies
    its ``ORDER BY`` variables to keys of its own, and the whole is ordered by the number, then by every
    branch's keys (those of the other branches are unbound in a row, so equal): each query's rows come in
    its own order. None when a text cannot be a sub-SELECT as it is: not a SELECT, a ``PREFIX`` or
    ``BASE`` of its own, a ``cbrs__`` variable, or an ``ORDER BY`` of other than variables or ``STR`` of
    one (with ``ASC`` or ``DESC``)."""
    branches, keys = [], []
    for number, text in enumerate(texts):
        order = _order_keys(text)
        if order is None:
            return None
        names = [f"?cbrs__key{number}_{index}" for index in range(len(order))]
        copies = "".join(f" BIND ({key.expression} AS {name})" for key, name in zip(order, names, strict=True))
        branches.append(f"{{ {{ {text}\n}} BIND ({number} AS ?{_PART}){copies} }}")
        keys += [f"{key.direction}({name})" for key, name in zip(order, names, strict=True)]
    return "SELECT * WHERE {\n" + "\nUNION\n".join(branches) + f"\n}} ORDER BY ?{_PART} " + " ".join(keys)


class OrderKey(NamedTuple):
    """One key of an ``ORDER BY``: ``ASC`` or ``DESC``, its variable, and the expression sorted
    (the variable, or ``STR(variable)``: what cbrs's named queries sort literals by, docs/security.md)."""

    direction: str
    variable: str
    expression: str


def _order_keys(text: str) -> list[OrderKey] | None:
    """The keys of a SELECT query's top-level ``ORDER BY`` ([] without one), None when the text is no
    plain SELECT (see :func:`union_of_selects`)."""
    tokens = _tokens(text)
    names = [token.text.upper() for token in tokens if token.kind == "name"]
    if (
        not names
        or names[0] != "SELECT"
        or any(t.kind == "variable" and t.text[1:].startswith("cbrs__") for t in tokens)
    ):
        return None
    depth, start = 0, None
    for index, token in enumerate(tokens):
        if token.kind == "punct" and token.text in "{}":
            depth += 1 if token.text == "{" else -1
        elif depth == 0 and token.kind == "name" and token.text.upper() == "ORDER":
            start = index + 2  # past BY
    if start is None:
        return []
    projected = _projected(tokens)
    keys: list[OrderKey] = []
    rest = tokens[start:]
    while rest and not (rest[0].kind == "name" and rest[0].text.upper() in ("LIMIT", "OFFSET", "VALUES")):
        direction = "ASC"
        if rest[0].text.upper() in ("ASC", "DESC") and len(rest) >= 2 and rest[1].text == "(":
            direction, rest, closing = rest[0].text.upper(), rest[2:], 1
        else:
            closing = 0
        if rest and rest[0].kind == "variable":
            key, rest = OrderKey(direction, rest[0].text, rest[0].text), rest[1:]
        elif len(rest) >= 4 and rest[0].text.upper() == "STR" and rest[1].text == "(" and rest[2].kind == "variable":
            if rest[3].text != ")":
                return None
            key, rest = OrderKey(direction, rest[2].text, f"STR({rest[2].text})"), rest[4:]
        else:
            return None
        if closing:
            if not rest or rest[0].text != ")":
                return None
            rest = rest[1:]
        keys.append(key)
    if projected is not None and any(key.variable not in projected for key in keys):
        return None  # a key the sub-SELECT does not project cannot order the rows outside it
    return keys


def _projected(tokens: list[_Token]) -> set[str] | None:
    """The variables a SELECT projects (None for ``SELECT *``): the plain ones and those named by ``AS``."""
    found: set[str] = set()
    depth = 0
    for index, token in enumerate(tokens[1:], start=1):
        if token.text == "{" or (token.kind == "name" and token.text.upper() == "WHERE"):
            break
        if token.kind == "punct" and token.text in "()":
            depth += 1 if token.text == "(" else -1
        elif token.text == "*" and depth == 0:
            return None
        elif token.kind == "variable" and (depth == 0 or tokens[index - 1].text.upper() == "AS"):
            found.add(token.text)
    return found


@releases_results
def _split_parts(result: QueryResult, parts: int) -> list[list[dict[str, Term]]]:
    """The rows of :func:`union_of_selects`' answer, query by query, without cbrs's own variables."""
    if not isinstance(result, ox.QuerySolutions):
        raise TypeError("not a SELECT query")
    names = [variable.value for variable in result.variables]
    kept = [name for name in names if not name.startswith("cbrs__")]
    found: list[list[dict[str, Term]]] = [[] for _ in range(parts)]
    for row in result:
        number = row[_PART]
        assert isinstance(number, ox.Literal)
        found[int(number.value)].append({name: row[name] for name in kept if row[name] is not None})
    return found


def _expand_construct_where(query: str, tokens: list[_Token], form: int, values: str) -> str:
    opening = next((i for i in range(form + 1, len(tokens)) if tokens[i].kind == "punct" and tokens[i].text == "{"), -1)
    if opening < 0:
        raise ValueError("CONSTRUCT without a template or WHERE clause")
    closing = _closing(tokens, opening)
    template = query[tokens[opening].end : tokens[closing].start]
    at = tokens[form].end
    return query[:at] + " {" + template + "}" + query[at : tokens[opening].end] + values + query[tokens[opening].end :]
