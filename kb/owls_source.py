"""What ``cbrs load`` added for an advertisement made from OWL-S, so that deregistering it leaves the
store as it was before the load.

A load converts each OWL-S service into an advertisement and keeps the file's own triples beside it:
the service, its profile, process and grounding, their parameters, expressions and results, the
file's stub class declarations and its ``owl:Ontology`` header. Deregistering the advertisement alone
left those behind (41 triples of ``navigate.owls`` in graph:services). :func:`owls_source` finds them
by walking the file's nodes from the advertisement, keeping what another description still uses.
"""

from __future__ import annotations

from collections.abc import Iterable

import pyoxigraph as ox

from cbrs.kb.namespaces import OWL, RDF
from cbrs.kb.owls import DCTERMS_SOURCE, SERVICE_LINKS, is_owls_service, owls_key
from cbrs.kb.skolem import closure, is_skolem, skolem_digest
from cbrs.kb.store import Store
from cbrs.kb.vocab import CBRS

__all__ = ["GraphReads", "owls_services", "owls_source"]


class GraphReads:
    """The quads of one graph about a node, each read from the store once (a remote store answers each
    read with a request): the reads of one deregistration."""

    def __init__(self, store: Store, graph: ox.NamedNode) -> None:
        self.store = store
        self.graph = graph
        self._out: dict[ox.NamedNode, list[ox.Quad]] = {}
        self._into: dict[ox.NamedNode, list[ox.Quad]] = {}
        self._gone: set[ox.Quad] = set()

    def out(self, node: ox.NamedNode) -> list[ox.Quad]:
        """The quads whose subject is ``node``."""
        if node not in self._out:
            self._out[node] = self._kept(self.store.quads(node, None, None, self.graph))
        return self._out[node]

    def into(self, node: ox.NamedNode) -> list[ox.Quad]:
        """The quads whose object is ``node``."""
        if node not in self._into:
            self._into[node] = self._kept(self.store.quads(None, None, node, self.graph))
        return self._into[node]

    def with_predicate(self, predicate: ox.NamedNode) -> list[ox.Quad]:
        """The quads of the graph with ``predicate`` (not kept: read once per deregistration)."""
        return self._kept(self.store.quads(None, predicate, None, self.graph))

    def drop(self, quads: Iterable[ox.Quad]) -> None:
        """Read the graph from now on as if ``quads`` were gone: how deregistering several descriptions one
        after the other reads it, when they are replaced in one transaction (:meth:`ComponentRegistry.sync`)."""
        self._gone.update(quads)
        for cache in (self._out, self._into):
            for node, found in cache.items():
                cache[node] = self._kept(found)

    def _kept(self, quads: Iterable[ox.Quad]) -> list[ox.Quad]:
        return [q for q in quads if q not in self._gone] if self._gone else list(quads)


def owls_services(root: ox.NamedNode, lookup: GraphReads) -> list[ox.NamedNode]:
    """The OWL-S services ``root`` was made from: itself (an advertisement keeps the service's IRI)
    or its ``dcterms:source`` (a requirement's), when OWL-S triples are about it. A source that is a
    description of its own (a lab's Turtle description citing a loaded OWL-S advertisement) is not."""
    found = [root]
    for quad in lookup.out(root):
        source = quad.object
        if (
            quad.predicate.value == DCTERMS_SOURCE
            and isinstance(source, ox.NamedNode)
            and not any(q.predicate.value == CBRS.hasOWLSModel for q in lookup.out(source))
        ):
            found.append(source)
    return [node for node in found if _has_owls(node, lookup)]


def owls_source(root: ox.NamedNode, services: list[ox.NamedNode], lookup: GraphReads) -> list[ox.Quad]:
    """The description and the OWL-S triples of its services: what the load added for it.

    From the description and its services, the nodes of the service's file are followed
    (:func:`_part_of_source`: the profile, process and grounding, their parameters, expressions,
    results and contacts, and the file's stub ``owl:Class`` lines); so are the profiles, processes
    and groundings that point at the service. The walk stops at another
    description or service. A node something else in the graph still points at (a parameter two
    services of one file share, a stub class another service uses as a parameter type) is shared:
    it stays, and so does what only it reaches. Last, the file's ``owl:Ontology`` header goes with
    the file's last description."""
    kept: set[ox.NamedNode] = set()
    while True:
        found = _walk(root, services, lookup, kept)
        own = {q.subject for q in found}
        shared = {
            node
            for node in own
            if node != root and any(q.subject not in own for q in lookup.into(node))  # type: ignore[arg-type]
        }
        if not shared:
            break
        kept |= shared  # type: ignore[arg-type]
    for service in services:
        found.extend(_header(root, service, lookup, own))  # type: ignore[arg-type]
    return list(dict.fromkeys(found))


def _header(root: ox.NamedNode, service: ox.NamedNode, lookup: GraphReads, own: set[ox.NamedNode]) -> list[ox.Quad]:
    """The ``owl:Ontology`` header of the file ``service`` is named in (``file.owls`` for
    ``file.owls#Service``), when no other description of that file stays in the graph."""
    document, separator, _ = service.value.partition("#")
    if not separator:
        return []
    header = ox.NamedNode(document)
    if header in own or not any(
        q.predicate.value == RDF + "type" and q.object == ox.NamedNode(OWL + "Ontology") for q in lookup.out(header)
    ):
        return []
    if any(q.subject != header and q.subject not in own for q in lookup.into(header)):
        return []  # another file imports it
    if _more_of_file(root, document, lookup, own):
        return []
    return closure([header], lookup.out)  # type: ignore[arg-type]


def _more_of_file(root: ox.NamedNode, document: str, lookup: GraphReads, own: set[ox.NamedNode]) -> bool:
    """Whether another description in the graph came from the file ``root`` came from: it is named
    under ``document#``, or its model node was named in the same load (:func:`skolem_digest`). One
    pass over the models' links; a scan of the graph's subjects for the prefix took 140 ms on OWLS-TC."""
    model = ox.NamedNode(CBRS.hasOWLSModel)
    digests = {skolem_digest(q.object) for q in lookup.out(root) if q.predicate == model} - {None}
    for quad in lookup.with_predicate(model):
        if quad.subject in own:
            continue
        if quad.subject.value.startswith(document + "#") or skolem_digest(quad.object) in digests:  # type: ignore[union-attr]
            return True
    return False


def _has_owls(node: ox.NamedNode, lookup: GraphReads) -> bool:
    """Whether the graph holds OWL-S triples about ``node`` (a Turtle description has none)."""
    for quad in lookup.out(node):
        kind = quad.object if quad.predicate.value == RDF + "type" else None
        if owls_key(quad.predicate.value) or (isinstance(kind, ox.NamedNode) and owls_key(kind.value)):
            return True
    return any(owls_key(q.predicate.value) in SERVICE_LINKS for q in lookup.into(node))


def _walk(
    root: ox.NamedNode, services: list[ox.NamedNode], lookup: GraphReads, kept: set[ox.NamedNode]
) -> list[ox.Quad]:
    """One walk of :func:`owls_source`, passing over the ``kept`` (shared) nodes."""
    found: list[ox.Quad] = []
    seen: set[ox.NamedNode] = set()
    pending = [root, *services]
    files = {_file_of(service) for service in services}
    while pending:
        node = pending.pop()
        if node in seen or node in kept:
            continue
        seen.add(node)
        for quad in lookup.out(node):
            found.append(quad)
            if (
                isinstance(quad.object, ox.NamedNode)
                and quad.object not in seen
                and _part_of_source(quad.object, lookup, files)
            ):
                pending.append(quad.object)
        if node in services:
            for quad in lookup.into(node):
                if owls_key(quad.predicate.value) in SERVICE_LINKS and isinstance(quad.subject, ox.NamedNode):
                    pending.append(quad.subject)
    return found


def _part_of_source(node: ox.NamedNode, lookup: GraphReads, files: set[str]) -> bool:
    """Whether the walk goes on to ``node``: the graph says something about it; it is a node of the
    service's file (named under the file's IRI, or skolemised) or a stub declaration (type triples
    only, as an OWL-S file's ``<owl:Class rdf:about="...#Price"/>``); and it is neither a description
    nor an OWL-S service (those are deregistered on their own). A resource of its own the file only
    points at (a device another file describes) is not the file's to remove."""
    quads = lookup.out(node)
    stub = True
    for quad in quads:
        if quad.predicate.value == CBRS.hasOWLSModel:
            return False
        kind = quad.object if quad.predicate.value == RDF + "type" else None
        if isinstance(kind, ox.NamedNode) and is_owls_service([kind.value]):
            return False
        stub = stub and kind is not None
    return bool(quads) and (stub or is_skolem(node) or _file_of(node) in files)


def _file_of(node: ox.NamedNode) -> str:
    """The IRI of the document ``node`` is named in: before its ``#``, else up to its last ``/``."""
    if "#" in node.value:
        return node.value.split("#", 1)[0]
    return node.value.rsplit("/", 1)[0]
