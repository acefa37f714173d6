"""Writes too large for one request to a remote store: staged in batches, then published by one operation.

Why not one request: Virtuoso 7 refuses an ``INSERT DATA`` of more than about 1,400 triples ("generated
SQL text has exceeded 10000 lines"); and a server need not run a request of several operations as one
transaction (Virtuoso 7 keeps what the first operation of a request wrote when the second fails). What
every SPARQL 1.1 server we know of does keep whole is **one operation**. So a large write is made in
three steps (docs/remote-store.md, "Large writes"):

1. **Stage.** The quads go, in batches of at most ``batch`` quads (one ``INSERT DATA`` each), into fresh
   staging graphs, one per target graph, named ``graph:staging/<random>/<n>``. Each predicate is
   wrapped, ``<https://w3id.org/cbrs/staged/` + predicate + `>``, so that a staged statement does not
   say what it will say once published: a reader's ``?x a cbrs:Advertisement`` does not see a half
   written description while the batches arrive.
2. **Publish.** One ``INSERT { GRAPH ?g { ?s ?p ?o } } WHERE { ... }`` operation copies every staged
   triple into its target graph, unwrapping the predicate with ``IRI(STRAFTER(STR(?w), prefix))``.
3. **Clean.** The staging graphs are dropped.

If a batch or the publication fails, the staging graphs are dropped (compensation) and the error
raised: the store holds what it held before. A blank node's quads are kept in one batch, since a blank
node in an ``INSERT DATA`` names a fresh node in each request.
"""

from __future__ import annotations

import logging
import uuid
from collections.abc import Callable, Iterable, Sequence

import pyoxigraph as ox

from cbrs.kb.errors import RemoteStoreError, StoreError, StoreEvaluationError
from cbrs.kb.namespaces import BASE, GRAPH
from cbrs.kb.store import data_block

STAGED = BASE + "staged/"
"""The prefix a staged predicate is wrapped in (a staged ``rdf:type`` is ``<STAGED + rdf:type's IRI>``)."""
STAGING = GRAPH + "staging/"
"""Where staging graphs are made; a graph here that outlives a write is inert and may be dropped."""

_log = logging.getLogger(__name__)

Send = Callable[[str], None]


def write_staged(
    location: str,
    quads: Sequence[ox.Quad],
    batch: int,
    send: Send,
    replacing: Sequence[ox.NamedNode] = (),
    progress: Callable[[int, int], None] | None = None,
) -> None:
    """Write ``quads`` through staging graphs with ``send`` (one update request per call). The graphs in
    ``replacing`` are emptied by the publishing operation itself (a restore, :mod:`kb.backup`), so that
    readers see the old contents or the new, never neither; ``progress`` is told each batch sent."""
    run = f"{STAGING}{uuid.uuid4().hex}/"
    stages: dict[ox.NamedNode, ox.NamedNode] = {}
    staged = []
    for quad in quads:
        target = quad.graph_name
        if not isinstance(target, ox.NamedNode):
            raise StoreError(
                location,
                f"a write of more than {batch} quads (setting remote_batch) goes to named graphs only; "
                f"{quad} is in the default graph",
            )
        stage = stages.setdefault(target, ox.NamedNode(f"{run}{len(stages) + 1}"))
        staged.append(ox.Quad(quad.subject, _wrapped(location, quad.predicate), quad.object, stage))
    written: set[ox.NamedNode | ox.BlankNode | ox.DefaultGraph] = set()  # staging graphs a batch may have reached
    parts = batches(staged, batch)
    try:
        for done, part in enumerate(parts):
            if progress is not None:
                progress(done, len(parts))
            touched = {quad.graph_name for quad in part}
            try:
                send("INSERT DATA {\n" + data_block(part, blank_nodes=True) + "}")
            except (RemoteStoreError, StoreEvaluationError):
                raise  # the server answered that it refused the batch: it wrote none of it
            except BaseException:
                written.update(touched)  # no answer (a timeout, a lost connection): it may be written
                raise
            written.update(touched)
        send(publication(stages, replacing))
    except BaseException as error:
        _drop([stage for stage in stages.values() if stage in written], send, error)
        raise
    try:
        send(_drops(stages.values()))
    except StoreError as error:  # the write is done; an inert staging graph is left behind
        _log.warning("store %s: staging graphs under %s were not dropped: %s", location, run, error)


def publication(stages: dict[ox.NamedNode, ox.NamedNode], replacing: Sequence[ox.NamedNode] = ()) -> str:
    """The one operation that copies each staging graph into its target graph, predicates unwrapped; and
    empties the graphs in ``replacing`` (a solution of the first branch instantiates only the DELETE
    template, one of the second only the INSERT template, and SPARQL deletes before it inserts)."""
    pairs = " ".join(f"({stage} {target})" for target, stage in stages.items())
    copied = (
        f"VALUES (?stage ?target) {{ {pairs} }}\n"
        "  GRAPH ?stage { ?s ?wrapped ?o }\n"
        f'  BIND (IRI(STRAFTER(STR(?wrapped), "{STAGED}")) AS ?p)'
    )
    if not replacing:
        return f"INSERT {{ GRAPH ?target {{ ?s ?p ?o }} }}\nWHERE {{ {copied} }}"
    emptied = f"VALUES ?old {{ {' '.join(map(str, replacing))} }} GRAPH ?old {{ ?os ?op ?oo }}"
    if not stages:
        return f"DELETE {{ GRAPH ?old {{ ?os ?op ?oo }} }}\nWHERE {{ {emptied} }}"
    return (
        "DELETE { GRAPH ?old { ?os ?op ?oo } }\nINSERT { GRAPH ?target { ?s ?p ?o } }\n"
        f"WHERE {{ {{ {emptied} }}\n  UNION\n  {{ {copied} }} }}"
    )


def batches(quads: Sequence[ox.Quad], size: int) -> list[list[ox.Quad]]:
    """``quads`` in lists of at most ``size``, each blank node's quads together (a blank node that links
    more than ``size`` quads makes one larger list)."""
    groups = _blank_node_groups(quads)
    found: list[list[ox.Quad]] = []
    current: list[ox.Quad] = []
    for group in groups:
        if current and len(current) + len(group) > size:
            found.append(current)
            current = []
        current.extend(group)
    if current:
        found.append(current)
    return found


def _blank_node_groups(quads: Iterable[ox.Quad]) -> list[list[ox.Quad]]:
    """The quads in groups: one per quad without a blank node, one per set of blank nodes linked by quads."""
    parent: dict[ox.BlankNode, ox.BlankNode] = {}

    def root(node: ox.BlankNode) -> ox.BlankNode:
        while parent.setdefault(node, node) != node:
            parent[node] = parent[parent[node]]
            node = parent[node]
        return node

    plain: list[list[ox.Quad]] = []
    linked: list[tuple[ox.BlankNode, ox.Quad]] = []
    for quad in quads:
        nodes = [term for term in (quad.subject, quad.object) if isinstance(term, ox.BlankNode)]
        if not nodes:
            plain.append([quad])
            continue
        first = root(nodes[0])
        for other in nodes[1:]:
            parent[root(other)] = first
        linked.append((nodes[0], quad))
    together: dict[ox.BlankNode, list[ox.Quad]] = {}
    for node, quad in linked:
        together.setdefault(root(node), []).append(quad)
    return plain + list(together.values())


def _wrapped(location: str, predicate: ox.NamedNode) -> ox.NamedNode:
    try:
        return ox.NamedNode(STAGED + predicate.value)
    except ValueError as error:
        raise StoreError(location, f"predicate {predicate} cannot be staged: {error}") from error


def _drops(stages: Iterable[ox.NamedNode]) -> str:
    return " ; ".join(f"DROP SILENT GRAPH {stage}" for stage in stages)


def _drop(stages: Iterable[ox.NamedNode], send: Send, cause: BaseException) -> None:
    """Compensation: drop the staging graphs after a failed write; if even that fails, say which are left."""
    names = list(stages)
    if not names:
        return
    try:
        send(_drops(names))
    except StoreError as error:
        cause.add_note(
            f"the staging graphs {', '.join(str(n) for n in names)} could not be dropped ({error.reason}); they "
            f"are inert (nothing reads them as data): remove them when the server is back, with the update "
            f"{_drops(names)}"
        )
