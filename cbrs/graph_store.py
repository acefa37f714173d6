"""The SPARQL 1.1 Graph Store HTTP Protocol over the knowledge base: read, replace, add to and drop graphs.

One named graph (``graph=IRI``), the store's own default graph (``default``), or, for reading and for
adding quads, the whole dataset. Writes take the update token, parse the body whole before anything
is written (a broken body changes nothing), pass the description shapes like every other way in, leave
a readable semantic map readable (as a load or an update into graph:map must), leave no class under a term
of cbrs's own vocabularies that nothing declares (as an ``INSERT DATA`` or ``DELETE DATA`` of the same
statements must: :func:`kb.superclasses.check_change`), put a task nowhere but graph:requirements and an
advertisement nowhere but graph:services (:func:`kb.placement.check_placement`, as ``cbrs load --graph``), and are
one transaction each.
"""

from __future__ import annotations

import logging
from collections.abc import Iterator, Sequence
from dataclasses import dataclass

import pyoxigraph as ox

from cbrs.kb.errors import KnowledgeBaseError
from cbrs.kb.loader import parse_bytes
from cbrs.kb.namespaces import GRAPH, PREFIXES, GraphName
from cbrs.kb.owl_syntaxes import MEDIA_TYPES as OWL_MEDIA_TYPES
from cbrs.kb.placement import check_placement
from cbrs.kb.shapes import DescriptionShapeError, check_descriptions
from cbrs.kb.superclasses import check_change, says_used_terms
from cbrs.output import used_prefixes
from cbrs.sparql_service import (
    BadDatasetError,
    BadRequestError,
    NotAcceptableError,
    SparqlService,
    UnsupportedMediaTypeError,
    negotiate,
)

__all__ = ["GraphStore", "GraphStoreError", "Target", "UnknownGraphError"]

GRAPH_FORMATS = (
    ox.RdfFormat.TURTLE,
    ox.RdfFormat.N_TRIPLES,
    ox.RdfFormat.RDF_XML,
    ox.RdfFormat.JSON_LD,
    ox.RdfFormat.N3,
)
DATASET_FORMATS = (ox.RdfFormat.TRIG, ox.RdfFormat.N_QUADS)


log = logging.getLogger(__name__)


class GraphStoreError(BadRequestError):
    """A Graph Store request that cannot be answered as asked; names what was wrong. Its errors are the
    SPARQL endpoint's for the same mistake (400 ``bad-request``, 403 ``forbidden``, 406 ``not-acceptable``,
    415 ``unsupported-media-type``), so a client reads one set of names (docs/serving.md)."""


class UnknownGraphError(GraphStoreError):
    http_status = 404
    kind = "not-found"  # as the server's other 404s are named

    def __init__(self, graph: str) -> None:
        self.graph = graph
        super().__init__(f"the store has no graph <{graph}>")


@dataclass(frozen=True)
class Target:
    """What a request is about: a named graph, the default graph, or (``graph`` None) the dataset."""

    graph: str | None
    default: bool = False

    @classmethod
    def from_parameters(cls, graphs: Sequence[str], default: bool) -> Target:
        """The target a request's ``graph`` values and ``default`` flag name. A ``graph`` that is not an
        absolute IRI is refused as the endpoint refuses a ``default-graph-uri`` that is not one (400
        ``bad-dataset``), and so is a name written with one of cbrs's prefixes: ``graph:map`` parses as an IRI
        of the scheme ``graph``, and would name a graph nobody has (cbrs's are ``https://w3id.org/cbrs/graph/NAME``)."""
        if len(graphs) > 1 or (graphs and default):
            raise GraphStoreError("name one graph: ?graph=IRI or ?default, once")
        if not graphs:
            return cls(None, default)
        graph = graphs[0]
        try:
            ox.NamedNode(graph)
        except ValueError as error:  # a space, a '<'
            raise BadDatasetError("graph", graph, str(error)) from None
        scheme, _, rest = graph.partition(":")
        if scheme in PREFIXES and not rest.startswith("//"):
            raise BadDatasetError(
                "graph", graph, f"{scheme}: is a prefix of cbrs's, not a scheme; its graphs are {GRAPH}NAME"
            )
        return cls(graph)

    @property
    def node(self) -> ox.NamedNode | ox.DefaultGraph | None:
        if self.default:
            return ox.DefaultGraph()
        return ox.NamedNode(self.graph) if self.graph is not None else None


class GraphStore:
    """The protocol's four operations over one SPARQL service (its lock, token and caches)."""

    def __init__(self, sparql: SparqlService) -> None:
        self.sparql = sparql

    def read(self, target: Target, accept: str | None, client: str | None = None) -> tuple[bytes, str]:
        """The graph (or the dataset) serialised in the format ``accept`` names, with its media type.

        With the endpoint's limits (:meth:`SparqlService.bounded_read`): one of ``client``'s query
        slots, ``max_result_bytes`` and ``query_timeout``. The quads are read twice, once for the
        prefixes the text declares and once to write it, rather than held in memory."""
        store = self.sparql.kb.store
        node = target.node
        fmt = _negotiate(accept, DATASET_FORMATS if node is None else GRAPH_FORMATS)
        if isinstance(node, ox.NamedNode) and node.value not in store.graphs():
            raise UnknownGraphError(node.value)

        def statements() -> Iterator[ox.Triple | ox.Quad]:
            if node is None:
                return store.quads()
            return (ox.Triple(q.subject, q.predicate, q.object) for q in store.quads(graph=node))

        with self.sparql.bounded_read(client) as budget:
            try:
                prefixes = used_prefixes(budget.watch(statements()))
                return budget.serialize(statements(), fmt, prefixes), fmt.media_type
            except KnowledgeBaseError as error:  # stopped at the limit or the deadline
                # The traceback's frames hold Oxigraph's iterator, which must be dropped on this thread:
                # the error goes on without them.
                error.__context__ = None
                raise error.with_traceback(None) from None

    def replace(self, target: Target, body: bytes, media_type: str, token: str | None) -> bool:
        """PUT: the graph becomes the body's triples; True when the graph did not exist before."""
        node = self._graph_node(target, "PUT")
        fmt = _body_format(media_type, node, "PUT")  # as the endpoint: 415 before 403, 403 before the body is read
        self.sparql.check_token(token)
        new = self._parse(body, fmt, node)
        with self.sparql.lock:
            self.sparql.kb.check_map_write(new, replaces_map=node == GraphName.MAP.node)
            store = self.sparql.kb.store
            created = isinstance(node, ox.NamedNode) and node.value not in store.graphs()
            old = list(store.quads(graph=node))
            check_change(store, old, new, _request("PUT", node))
            store.replace(old, new)
            self._written()
        return created

    def add(self, target: Target, body: bytes, media_type: str, token: str | None) -> None:
        """POST: the body's triples join the graph (or, for the dataset, its quads join the store)."""
        node = target.node
        fmt = _body_format(media_type, node, "POST")
        self.sparql.check_token(token)
        new = self._parse(body, fmt, node)
        with self.sparql.lock:
            self.sparql.kb.check_map_write(new)
            check_change(self.sparql.kb.store, (), new, _request("POST", node))
            self.sparql.kb.store.add(new)
            self._written()

    def drop(self, target: Target, token: str | None) -> None:
        """DELETE: the graph is emptied and gone; 404 when there is no such graph."""
        self.sparql.check_token(token)
        node = self._graph_node(target, "DELETE")
        with self.sparql.lock:
            store = self.sparql.kb.store
            if isinstance(node, ox.NamedNode) and node.value not in store.graphs():
                raise UnknownGraphError(node.value)
            if isinstance(node, ox.NamedNode):
                if says_used_terms(store, node):  # else it cannot remove a declaration: not read
                    check_change(store, list(store.quads(graph=node)), [], _request("DELETE", node))
                store.clear_graph(node)
            else:
                old = list(store.quads(graph=node))
                check_change(store, old, [], _request("DELETE", node))
                store.replace(old, [])
            self._written()

    def _written(self) -> None:
        """After a write that stands: what it entails in standard vocabularies (graph:entailed, as every
        other write path brings it up to date), then the endpoint's caches. A failure of the first is
        logged; the graph lags until the next write."""
        try:
            self.sparql.kb.refresh_standard_terms()
        except KnowledgeBaseError as error:
            log.warning("graph:entailed not brought up to date after a /store write: %s", error)
        self.sparql.changed()

    def _graph_node(self, target: Target, method: str) -> ox.NamedNode | ox.DefaultGraph:
        node = target.node
        if node is None:
            raise GraphStoreError(f"{method} needs ?graph=IRI or ?default: it acts on one graph, not the whole store")
        return node

    def _parse(self, body: bytes, fmt: ox.RdfFormat, node: ox.NamedNode | ox.DefaultGraph | None) -> list[ox.Quad]:
        graph = node.value if isinstance(node, ox.NamedNode) else None
        parsed = parse_bytes(body, "<request body>", fmt, graph=graph, base_iri=graph)  # whole, or an error
        quads = parsed.quads
        if isinstance(node, ox.DefaultGraph):
            quads = [ox.Quad(q.subject, q.predicate, q.object, ox.DefaultGraph()) for q in quads]
        check_placement(self.sparql.kb.store, quads, "<request body>")  # a task into graph:map: 400, as cbrs load
        try:
            check_descriptions(self.sparql.kb.store, quads)  # a description written so passes the shapes too
        except DescriptionShapeError as error:
            error.add_note("nothing was written")  # as /update's refusal of the same description says
            raise
        return quads


def _request(method: str, node: ox.NamedNode | ox.DefaultGraph | None) -> str:
    """How a refusal names the request: ``the PUT of graph <IRI>``, ``the POST to the store``."""
    return f"the {method} {'to' if method == 'POST' else 'of'} {_named(node)}"


def _named(node: ox.NamedNode | ox.DefaultGraph | None) -> str:
    if node is None:
        return "the store"
    return "the default graph" if isinstance(node, ox.DefaultGraph) else f"graph {node}"


def _negotiate(accept: str | None, offered: tuple[ox.RdfFormat, ...]) -> ox.RdfFormat:
    """The offered format the Accept header prefers, by its q-values and with the endpoint's reading of
    media types (parameters ignored, Oxigraph's aliases such as ``application/x-turtle``)."""
    by_type = {fmt.media_type: fmt for fmt in offered}
    try:
        return by_type[negotiate(True, accept, None, tuple(by_type))]
    except NotAcceptableError:  # the endpoint's refusal, naming every type offered (it names four of its many)
        raise NotAcceptableError(accept or "", tuple(by_type)) from None


_FORM_TYPE = "application/x-www-form-urlencoded"


def _body_format(media_type: str, node: ox.NamedNode | ox.DefaultGraph | None, method: str) -> ox.RdfFormat:
    """The RDF format of a write's body by its ``Content-Type``; 415 naming the types taken, as the SPARQL
    endpoint refuses a body it cannot read, for one of another type or of none. curl's ``--data-binary``
    sends a form's type unless told another: the refusal says so."""
    offered = DATASET_FORMATS if node is None else GRAPH_FORMATS
    fmt = ox.RdfFormat.from_media_type(media_type) if media_type else None
    if fmt is not None and fmt in offered:
        return fmt
    hint = ""
    if media_type == _FORM_TYPE:
        hint = f" (curl --data-binary sends {_FORM_TYPE} unless told: -H 'Content-Type: {offered[0].media_type}')"
    elif node is None and fmt in GRAPH_FORMATS:
        hint = " (a body of triples goes into one graph: ?graph=IRI or ?default)"
    elif media_type in OWL_MEDIA_TYPES:
        hint = (
            f" ({OWL_MEDIA_TYPES[media_type]} is no RDF syntax: save the ontology from Protégé as RDF/XML or Turtle "
            "and send it as application/rdf+xml or text/turtle)"
        )
    where = f"the body of a {method} to {_named(node)}"
    raise UnsupportedMediaTypeError(media_type, where, [f.media_type for f in offered], hint)
