"""A store seeded by an older cbrs, brought up to the bundled ontologies when it is opened.

:meth:`KnowledgeBase.open` calls :func:`upgrade_store` on every seeded store; it writes only when
something is out of date, and then in one transaction. Three rules, each about what cbrs owns:

- conditions: in every graph, a condition written in the reified form of core 0.1.0 (``rdf:subject``,
  ``rdf:predicate``, ``rdf:object``, ``rdf:type rdf:Statement``) is rewritten with
  ``cbrs:conditionSubject``, ``cbrs:conditionPredicate`` and ``cbrs:conditionObject``
  (:mod:`kb.conditions`), keeping its node, type and text;
- the core vocabulary: in the ontology graph, what the store says about the terms ``core.ttl``
  describes (and any other ``cbrs:`` term) is replaced by what the bundled ``core.ttl`` says, so
  ``cbrs:Condition`` is no longer an ``rdf:Statement`` and ``cbrs:hasOWLSModel`` gets its new domain;
- ontology headers: the header (version, description) of each bundled ontology the store holds is
  replaced by the bundled one, so that the next open finds nothing to do;
- new ontologies: a bundled file of the ontology graph whose ontology the store does not name at all
  (the standard vocabularies and the alignments, for a store seeded before they were bundled) is
  added whole, as a seed would have stored it.

Nothing else is touched: the advertisements and requirements a user registered, changed or
deregistered stay as they are, and the semantic map keeps its own upgrade
(:meth:`KnowledgeBase.add_semantic_map`). A condition on a blank node (which no cbrs write makes) is
left alone.
"""

from __future__ import annotations

import functools
import logging
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import pyoxigraph as ox

from cbrs.kb.conditions import LEGACY_PARTS
from cbrs.kb.loader import parse_file
from cbrs.kb.namespaces import CBRS, OWL, RDF, GraphName
from cbrs.kb.queries import QueryLibrary
from cbrs.kb.resources import bundled_files
from cbrs.kb.skolem import closure, is_skolem, quads_by_subject
from cbrs.kb.store import Store

__all__ = ["UpgradeReport", "new_terms", "upgrade_store"]

log = logging.getLogger(__name__)

UPGRADED_GRAPHS = (GraphName.ONTOLOGY, GraphName.SERVICES, GraphName.REQUIREMENTS)
CORE_FILE = "core.ttl"
_VERSION_INFO = OWL + "versionInfo"


@dataclass(frozen=True)
class UpgradeReport:
    """What :func:`upgrade_store` changed."""

    conditions: int = 0  # condition nodes rewritten from the reified form
    removed: int = 0  # quads removed, all rules together
    added: int = 0

    @property
    def changed(self) -> bool:
        return bool(self.removed or self.added)


def upgrade_store(store: Store, queries: QueryLibrary) -> UpgradeReport:
    """Bring ``store`` up to the bundled ontologies (the three rules above), in one transaction."""
    remove, add, conditions = _condition_changes(store, queries)
    add += _missing_ontologies(store)
    if _headers_outdated(store):
        core_remove, core_add = _core_changes(store)
        header_remove, header_add = _header_changes(store)
        remove += core_remove + header_remove
        add += core_add + header_add
    removing = set(remove) - set(add)
    adding = set(add) - set(remove)
    adding = {quad for quad in adding if not _stored(store, quad)}
    if not removing and not adding:
        return UpgradeReport()
    store.replace(sorted(removing, key=str), sorted(adding, key=str))
    log.info("upgraded the store: %d conditions rewritten, %d quads out, %d in", conditions, len(removing), len(adding))
    return UpgradeReport(conditions, len(removing), len(adding))


def _condition_changes(store: Store, queries: QueryLibrary) -> tuple[list[ox.Quad], list[ox.Quad], int]:
    remove: list[ox.Quad] = []
    add: list[ox.Quad] = []
    nodes = set()
    for row in queries.select(store, "legacy_conditions"):
        node, part, value, graph = row["condition"], row["part"], row["value"], row["graph"]
        if not isinstance(node, ox.NamedNode) or not isinstance(graph, ox.NamedNode):
            continue
        nodes.add(node)
        remove.append(ox.Quad(node, ox.NamedNode(part.value), value, graph))
        if part.value in LEGACY_PARTS:
            add.append(ox.Quad(node, ox.NamedNode(LEGACY_PARTS[part.value]), value, graph))
    return remove, add, len(nodes)


@functools.cache
def _bundled(path: Path, graph: GraphName) -> tuple[ox.Quad, ...]:
    """A bundled file's quads, skolemised as a fresh seed would store them (parsed once per process)."""
    return tuple(parse_file(path, graph).quads)


@functools.cache
def _bundled_headers() -> tuple[tuple[ox.NamedNode, GraphName, tuple[ox.Quad, ...]], ...]:
    """(ontology IRI, graph, header quads) of the bundled ontologies in the upgraded graphs, read without
    skolemising (a header has no blank nodes)."""
    found = []
    for item in bundled_files():
        if item.graph not in UPGRADED_GRAPHS:
            continue
        triples = list(ox.parse(path=str(item.path), format=ox.RdfFormat.TURTLE))
        for head in {t.subject for t in triples if _is_header(t)}:
            if isinstance(head, ox.NamedNode):
                own = (ox.Quad(t.subject, t.predicate, t.object, item.graph.node) for t in triples if t.subject == head)
                found.append((head, item.graph, tuple(own)))
    return tuple(found)


@functools.cache
def _bundled_versions() -> tuple[tuple[ox.NamedNode, GraphName, frozenset[str]], ...]:
    """(ontology IRI, graph, versions) of the bundled ontologies in the upgraded graphs. This runs on every
    open, so a file is read only as far as its header block (where our files keep ``owl:versionInfo``);
    one whose header block names no version is read whole."""
    found = []
    for item in bundled_files():
        if item.graph not in UPGRADED_GRAPHS:
            continue
        head: ox.NamedNode | ox.BlankNode | ox.Triple | None = None
        versions: set[str] = set()
        for triple in ox.parse(path=str(item.path), format=ox.RdfFormat.TURTLE):
            if head is None and _is_header(triple):
                head = triple.subject
            if head is not None and triple.subject != head:
                break
            if head is not None and triple.predicate.value == _VERSION_INFO:
                versions.add(str(triple.object))
        if isinstance(head, ox.NamedNode) and versions:
            found.append((head, item.graph, frozenset(versions)))
            continue
        for head, graph, quads in _bundled_headers():
            if graph is item.graph:
                found.append(
                    (head, graph, frozenset(str(q.object) for q in quads if q.predicate.value == _VERSION_INFO))
                )
    return tuple(dict.fromkeys(found))


@functools.cache
def _bundled_ontology_files() -> tuple[tuple[Path, GraphName, ox.NamedNode], ...]:
    """(file, graph, ontology IRI) of the bundled files of the ontology graph, each read up to its header."""
    found = []
    for item in bundled_files():
        if item.graph is not GraphName.ONTOLOGY:
            continue
        for triple in ox.parse(path=str(item.path), format=ox.RdfFormat.TURTLE):
            if _is_header(triple):
                if isinstance(triple.subject, ox.NamedNode):
                    found.append((item.path, item.graph, triple.subject))
                break
    return tuple(found)


def _missing_ontologies(store: Store) -> list[ox.Quad]:
    """The quads of every bundled ontology-graph file whose ontology the store does not name."""
    ontology = ox.NamedNode(OWL + "Ontology")
    kind = ox.NamedNode(RDF + "type")
    missing: list[ox.Quad] = []
    for path, graph, head in _bundled_ontology_files():
        if next(store.quads(head, kind, ontology, graph.node), None) is None:
            log.info("adding %s, new in this version of cbrs", path.name)
            missing += _bundled(path, graph)
    return missing


def _is_header(triple: ox.Triple) -> bool:
    return triple.predicate.value == RDF + "type" and triple.object == ox.NamedNode(OWL + "Ontology")


def _headers_outdated(store: Store) -> bool:
    """Whether a bundled ontology the store holds has another version there than in its file."""
    version = ox.NamedNode(_VERSION_INFO)
    for head, graph, bundled in _bundled_versions():
        stored = {str(q.object) for q in store.quads(head, version, None, graph.node)}
        if stored and stored != bundled:
            return True
    return False


def _header_changes(store: Store) -> tuple[list[ox.Quad], list[ox.Quad]]:
    remove: list[ox.Quad] = []
    add: list[ox.Quad] = []
    for head, graph, quads in _bundled_headers():
        stored = list(store.quads(head, None, None, graph.node))
        if stored:  # an ontology the store never held is not added by an upgrade
            remove += stored
            add += quads
    return remove, add


def _core_changes(store: Store) -> tuple[list[ox.Quad], list[ox.Quad]]:
    """The stored statements about core terms, and the bundled core's, with the nodes hanging off them."""
    item = next((i for i in bundled_files() if i.path.name == CORE_FILE), None)
    if item is None:
        return [], []
    core = _bundled(item.path, item.graph)
    graph = item.graph.node
    terms = {q.subject for q in core if isinstance(q.subject, ox.NamedNode) and not is_skolem(q.subject)}
    stored = list(store.quads(graph=graph))
    terms |= {q.subject for q in stored if isinstance(q.subject, ox.NamedNode) and q.subject.value.startswith(CBRS)}
    others = {
        q for i in bundled_files() if i.graph is item.graph and i.path != item.path for q in _bundled(i.path, i.graph)
    }
    remove = [q for q in closure(terms, quads_by_subject(stored)) if q not in others]
    return remove, list(core)


def new_terms(store: Store, quads: Sequence[ox.Quad]) -> list[ox.Quad]:
    """What of a bundled file's ``quads`` may join a store seeded from an older version of it: every
    statement between IRIs, and the skolemised structures (restrictions, models) of the terms the store
    does not describe yet. A term the store describes keeps its structures: taken again from a changed
    file, they would come in a second time under other skolem IRIs (the file's digest names them)."""
    described = {q.subject for q in store.quads(graph=quads[0].graph_name)} if quads else set()  # type: ignore[arg-type]
    flat = [q for q in quads if not is_skolem(q.subject) and not is_skolem(q.object)]
    roots = {q.subject for q in quads if isinstance(q.subject, ox.NamedNode) and not is_skolem(q.subject)} - described
    hanging = closure(roots, quads_by_subject(quads))
    return flat + [q for q in hanging if is_skolem(q.subject) or is_skolem(q.object)]


def _stored(store: Store, quad: ox.Quad) -> bool:
    return any(True for _ in store.quads(quad.subject, quad.predicate, quad.object, quad.graph_name))  # type: ignore[arg-type]
