"""A store seeded by an older cbrs, brought up to the bundled ontologies and map when it is opened.

:meth:`KnowledgeBase.open` asks :func:`check_store` what it needs to know of the store (one request to a
remote store) and calls :func:`upgrade_store` on every seeded store; it writes only when something is out
of date, and then in one transaction. An ontology (or the semantic map) is out of date when the store
holds it at another version (``owl:versionInfo``) than the bundled file, unless the store's is newer. The
rules, each about what cbrs owns (docs/ontologies.md, "Upgrading a store"):

- conditions: in every graph, a condition written in the reified form of core 0.1.0 (``rdf:subject``,
  ``rdf:predicate``, ``rdf:object``, ``rdf:type rdf:Statement``) is rewritten with
  ``cbrs:conditionSubject``, ``cbrs:conditionPredicate`` and ``cbrs:conditionObject``
  (:mod:`kb.conditions`), keeping its node, type and text;
- the core vocabulary, when out of date: in the ontology graph, what the store says about the terms
  ``core.ttl`` describes (and any other ``cbrs:`` term) is replaced by what the bundled ``core.ttl``
  says: the code relies on it as it is;
- the other ontologies of the ontology graph, when out of date: a three-way merge of their statements,
  the store's against the bundled file's, with the file as the store's version had it (``history.toml``)
  as the base. What the file says and that version did not is added, what that version said and no
  bundled file says now is removed; the rest of the store (a lab's own statements about a bundled
  class, a bundled statement the lab deleted) stays as it is. Statements are compared up to the names
  of their skolemised nodes, so a restriction is one statement with its nodes;
- ontology headers: the header (version, description) of each out-of-date bundled ontology is replaced
  by the bundled one, so that the next open finds nothing to do;
- new ontologies: a bundled file of the ontology graph whose ontology the store does not name at all
  (the standard vocabularies and the alignments, for a store seeded before they were bundled) is
  added whole, as a seed would have stored it;
- the semantic map (graph:map), when it names the bundled map's ontology at an older version: the same
  three-way merge, except that a bundled value does not join where the lab gave the thing a value of
  its own for that property (a thing a user moved stays where it was put, with one position). An empty
  map is given the bundled one whole; a map that does not name the bundled map's ontology is a lab's
  own home, and is left alone.

Nothing else is touched: the advertisements and requirements a user registered, changed or
deregistered stay as they are. A condition on a blank node (which no cbrs write makes) is left alone.
"""

from __future__ import annotations

import functools
import logging
import tomllib
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path

import pyoxigraph as ox

from cbrs.kb.conditions import LEGACY_PARTS
from cbrs.kb.loader import parse_file
from cbrs.kb.namespaces import CBRS, OWL, RDF, GraphName
from cbrs.kb.queries import QueryLibrary
from cbrs.kb.resources import bundled_files, ontology_dir
from cbrs.kb.skolem import closure, is_skolem, quads_by_subject
from cbrs.kb.store import EmbeddedStore, Store, Term

__all__ = ["StoreCheck", "UpgradeReport", "check_store", "statement_keys", "upgrade_store"]

log = logging.getLogger(__name__)

UPGRADED_GRAPHS = (GraphName.ONTOLOGY, GraphName.SERVICES, GraphName.REQUIREMENTS, GraphName.MAP)
MERGED_GRAPHS = (GraphName.ONTOLOGY, GraphName.MAP)  # the graphs whose bundled files are merged
# the graphs every open asks whether they hold anything: seeded or not, a map to put back, graph:entailed
# to work out (KnowledgeBase.open)
HELD_GRAPHS = (GraphName.ONTOLOGY, GraphName.MAP, GraphName.ENTAILED)
CORE_FILE = "core.ttl"
HISTORY = "history.toml"
_VERSION_INFO = OWL + "versionInfo"
_ONTOLOGY = ox.NamedNode(OWL + "Ontology")

Node = ox.NamedNode | ox.BlankNode | ox.Triple
Key = tuple[object, ...]  # a statement up to the names of its skolemised nodes
_Asked = tuple[ox.NamedNode, GraphName]  # a bundled ontology and the graph it is bundled in


@dataclass(frozen=True)
class UpgradeReport:
    """What :func:`upgrade_store` changed."""

    conditions: int = 0  # condition nodes rewritten from the reified form
    removed: int = 0  # quads removed, all rules together
    added: int = 0
    merged: tuple[str, ...] = ()  # the bundled files merged into the store (their names)
    versions: tuple[
        str, ...
    ] = ()  # each out-of-date file's versions in the store and bundled, "home.ttl 0.4.0 -> 0.5.0"

    @property
    def changed(self) -> bool:
        return bool(self.removed or self.added)


@dataclass(frozen=True)
class _Headers:
    """What the store says of the bundled ontologies, each in the graph it is bundled in."""

    declared: frozenset[_Asked]  # the ontologies their graph declares (rdf:type owl:Ontology)
    versions: dict[_Asked, frozenset[str]]  # the versions their graph gives them (owl:versionInfo)


@dataclass(frozen=True)
class StoreCheck:
    """What every open needs to know of a store, asked at once (:func:`check_store`)."""

    holding: frozenset[GraphName]  # those of HELD_GRAPHS that hold a statement
    legacy: tuple[dict[str, Term], ...]  # the conditions in the reified form (the named query legacy_conditions)
    headers: _Headers

    @property
    def seeded(self) -> bool:
        """Whether the ontology graph holds anything (as :meth:`Store.is_seeded` says)."""
        return GraphName.ONTOLOGY in self.holding


def upgrade_store(store: Store, queries: QueryLibrary, check: StoreCheck | None = None) -> UpgradeReport:
    """Bring ``store`` up to the bundled ontologies and map (the rules above), in one transaction; ``check``
    is what :func:`check_store` found, if it was just asked."""
    if check is None:
        check = check_store(store, queries)
    remove, add, conditions = _condition_changes(check.legacy)
    add += _missing_ontologies(check.headers)
    if GraphName.MAP not in check.holding:
        add += _bundled_map()
    outdated = _outdated(check.headers)
    merged: list[str] = []
    if outdated:
        if any(path.name == CORE_FILE for path, _, _ in _merged_files(outdated)):
            core_remove, core_add = _core_changes(store)
            remove += core_remove
            add += core_add
        for graph in MERGED_GRAPHS:
            files = [(path, stored) for path, g, stored in _merged_files(outdated) if g is graph]
            files = [(path, stored) for path, stored in files if path.name != CORE_FILE]
            if files:
                merge_remove, merge_add = _merge_changes(store, graph, files, remove, add)
                remove += merge_remove
                add += merge_add
                merged += [path.name for path, _ in files]
        header_remove, header_add = _header_changes(store, outdated)
        remove += header_remove
        add += header_add
    removing = set(remove) - set(add)
    adding = set(add) - set(remove)
    candidates = list(adding)
    adding = {quad for quad, held in zip(candidates, store.contains_each(candidates), strict=True) if not held}
    if not removing and not adding:
        return UpgradeReport()
    store.replace(sorted(removing, key=str), sorted(adding, key=str))
    versions = _version_changes(outdated)
    log.info(
        "upgraded the store%s: %d conditions rewritten, %s merged, %d quads out, %d in",
        f" ({', '.join(versions)})" if versions else "",
        conditions,
        ", ".join(merged) or "no ontology",
        len(removing),
        len(adding),
    )
    return UpgradeReport(conditions, len(removing), len(adding), tuple(merged), versions)


def _version_changes(outdated: dict[ox.NamedNode, frozenset[str]]) -> tuple[str, ...]:
    """ "home.ttl 0.4.0 -> 0.5.0" for each out-of-date bundled file: what an administrator who upgraded cbrs
    looks for in the log (the line named the files merged, not from which version to which)."""
    bundled = {head: versions for head, _, versions in _bundled_versions()}
    return tuple(
        f"{path.name} {'/'.join(sorted(outdated[head]))} -> {'/'.join(sorted(bundled.get(head, ())))}"
        for path, _, head in _bundled_merged_files()
        if head in outdated
    )


def check_store(store: Store, queries: QueryLibrary) -> StoreCheck:
    """What the rules and the open need to know of a store every time it is opened: which of
    :data:`HELD_GRAPHS` hold anything, the conditions in the reified form, and the bundled ontologies'
    headers. A remote store is asked all at once, in one request (a request each cost every open 4, and a
    lookup per header 18 before that); the embedded store looks each up by pattern, in a tenth of what a
    query of it takes, and asks an unseeded store nothing more."""
    if isinstance(store, EmbeddedStore):
        holding = frozenset(g for g in HELD_GRAPHS if next(store.quads(graph=g.node), None) is not None)
        if GraphName.ONTOLOGY not in holding:
            return StoreCheck(holding, (), _Headers(frozenset(), {}))
        version, kind = ox.NamedNode(_VERSION_INFO), ox.NamedNode(RDF + "type")
        versions = {
            (head, graph): frozenset(_text(q.object) for q in store.quads(head, version, None, graph.node))
            for head, graph, _ in _bundled_versions()
        }
        declared = frozenset(
            (head, graph)
            for _, graph, head in _bundled_ontology_files()
            if next(store.quads(head, kind, _ONTOLOGY, graph.node), None) is not None
        )
        return StoreCheck(holding, tuple(queries.select(store, "legacy_conditions")), _Headers(declared, versions))
    asked = _asked()
    answers = queries.select_each(
        store,
        [
            *(("graph_holds", {"graph": graph.node}) for graph in HELD_GRAPHS),
            ("legacy_conditions", {}),
            *(("ontology_header", {"ontology": head, "graph": graph.node}) for head, graph in asked),
        ],
    )
    held, (legacy, *headers) = answers[: len(HELD_GRAPHS)], answers[len(HELD_GRAPHS) :]
    rows_of = dict(zip(asked, headers, strict=True))
    return StoreCheck(
        frozenset(graph for graph, rows in zip(HELD_GRAPHS, held, strict=True) if rows),
        tuple(legacy),
        _Headers(
            frozenset(pair for pair, rows in rows_of.items() if any("declared" in row for row in rows)),
            {
                pair: frozenset(_text(row["version"]) for row in rows if "version" in row)
                for pair, rows in rows_of.items()
            },
        ),
    )


def _condition_changes(legacy: Sequence[dict[str, Term]]) -> tuple[list[ox.Quad], list[ox.Quad], int]:
    remove: list[ox.Quad] = []
    add: list[ox.Quad] = []
    nodes = set()
    for row in legacy:
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
    return _as_stored(parse_file(path, graph).quads)


def _as_stored(quads: Iterable[ox.Quad]) -> tuple[ox.Quad, ...]:
    """``quads`` as Oxigraph keeps them (``"2.70"^^xsd:decimal`` as ``"2.7"``), so that the merge compares
    a file's statements with a store's, whose literals are so kept, as equal when they are."""
    scratch = ox.Store()
    scratch.extend(quads)
    return tuple(scratch)


def _bundled_map() -> list[ox.Quad]:
    """The quads of the bundled map, for a store whose graph:map is empty (as a seed stores them)."""
    log.info("graph:map is empty: the bundled map is added")
    return [q for item in bundled_files() if item.graph is GraphName.MAP for q in _bundled(item.path, item.graph)]


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
                versions.add(_text(triple.object))
        if isinstance(head, ox.NamedNode) and versions:
            found.append((head, item.graph, frozenset(versions)))
            continue
        for head, graph, quads in _bundled_headers():
            if graph is item.graph:
                found.append(
                    (head, graph, frozenset(_text(q.object) for q in quads if q.predicate.value == _VERSION_INFO))
                )
    return tuple(dict.fromkeys(found))


def _bundled_ontology_files() -> tuple[tuple[Path, GraphName, ox.NamedNode], ...]:
    """(file, graph, ontology IRI) of the bundled files of the ontology graph."""
    return tuple(entry for entry in _bundled_merged_files() if entry[1] is GraphName.ONTOLOGY)


@functools.cache
def _bundled_merged_files() -> tuple[tuple[Path, GraphName, ox.NamedNode], ...]:
    """(file, graph, ontology IRI) of the bundled files of the merged graphs, each read up to its header."""
    found = []
    for item in bundled_files():
        if item.graph not in MERGED_GRAPHS:
            continue
        for triple in ox.parse(path=str(item.path), format=ox.RdfFormat.TURTLE):
            if _is_header(triple):
                if isinstance(triple.subject, ox.NamedNode):
                    found.append((item.path, item.graph, triple.subject))
                break
    return tuple(found)


def _missing_ontologies(headers: _Headers) -> list[ox.Quad]:
    """The quads of every bundled ontology-graph file whose ontology the store does not name."""
    missing: list[ox.Quad] = []
    for path, graph, head in _bundled_ontology_files():
        if (head, graph) not in headers.declared:
            log.info("adding %s, new in this version of cbrs", path.name)
            missing += _bundled(path, graph)
    return missing


@functools.cache
def _asked() -> tuple[_Asked, ...]:
    """The (ontology, graph) pairs a remote store is asked about: the bundled ontologies of the upgraded
    graphs."""
    pairs = [(head, graph) for head, graph, _ in _bundled_versions()]
    pairs += [(head, graph) for _, graph, head in _bundled_ontology_files()]
    return tuple(dict.fromkeys(pairs))


def _is_header(triple: ox.Triple) -> bool:
    return triple.predicate.value == RDF + "type" and triple.object == ox.NamedNode(OWL + "Ontology")


def _text(term: ox.NamedNode | ox.BlankNode | ox.Literal | ox.Triple) -> str:
    """A version's text (a literal's value, whatever its datatype or language)."""
    return term.value if isinstance(term, ox.Literal) else str(term)


def _version(text: str) -> tuple[int, ...] | None:
    """``"0.2.0"`` as (0, 2, 0); None for a version that is not dotted numbers."""
    parts = text.split(".")
    return tuple(int(part) for part in parts) if all(part.isdigit() for part in parts) else None


def _newer(stored: frozenset[str], bundled: frozenset[str]) -> bool:
    """Whether every stored version is newer than every bundled one (a store a newer cbrs upgraded)."""
    mine = [number for number in map(_version, bundled) if number is not None]
    theirs = [number for number in map(_version, stored) if number is not None]
    if len(mine) < len(bundled) or len(theirs) < len(stored):
        return False
    return min(theirs) > max(mine)


def _outdated(headers: _Headers) -> dict[ox.NamedNode, frozenset[str]]:
    """The bundled ontologies the store holds at another, not newer, version, with their stored versions
    other than the bundled one."""
    found = {}
    for head, graph, bundled in _bundled_versions():
        stored = headers.versions.get((head, graph), frozenset())
        if stored and stored != bundled:
            if _newer(stored, bundled):
                log.info("%s is at %s in the store, newer than this cbrs's %s: left alone", head.value, stored, bundled)
                continue
            found[head] = stored - bundled or stored  # (the bundled version beside an older: the older is the base)
    return found


def _merged_files(outdated: dict[ox.NamedNode, frozenset[str]]) -> list[tuple[Path, GraphName, frozenset[str]]]:
    """(file, graph, stored versions) of the out-of-date ontologies of the merged graphs."""
    return [(path, graph, outdated[head]) for path, graph, head in _bundled_merged_files() if head in outdated]


def _header_changes(store: Store, outdated: dict[ox.NamedNode, frozenset[str]]) -> tuple[list[ox.Quad], list[ox.Quad]]:
    remove: list[ox.Quad] = []
    add: list[ox.Quad] = []
    for head, graph, quads in _bundled_headers():
        if head in outdated:
            remove += store.quads(head, None, None, graph.node)
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


def statement_keys(quads: Iterable[ox.Quad]) -> dict[Key, list[ox.Quad]]:
    """The statements of ``quads`` (one graph), each by a key that does not depend on the names of its
    skolemised nodes, with its quads: a quad between named terms, a quad whose object is a skolemised
    structure (a restriction, a list, an action model) with that structure's quads, or a structure nothing
    points to (an ``owl:AllDisjointClasses``). Equal keys are equal statements, whatever file digest
    named their nodes."""
    quads = list(quads)
    quads_of = quads_by_subject(quads)
    pointed = {q.object for q in quads if is_skolem(q.object)}
    found: dict[Key, list[ox.Quad]] = {}
    roots: set[object] = set()
    for quad in quads:
        if is_skolem(quad.subject):
            if quad.subject not in pointed and quad.subject not in roots:
                roots.add(quad.subject)
                key: Key = ("structure", _shape(quad.subject, quads_of, ()))
                found.setdefault(key, []).extend(closure([quad.subject], quads_of))
            continue
        if is_skolem(quad.object):
            shape = _shape(quad.object, quads_of, ())  # type: ignore[arg-type]
            found.setdefault((quad.subject, quad.predicate, shape), []).extend(
                [quad, *closure([quad.object], quads_of)]  # type: ignore[list-item]
            )
        else:
            found.setdefault((quad.subject, quad.predicate, quad.object), []).append(quad)
    return found


def _shape(node: Node, quads_of: Callable[[Node], list[ox.Quad]], path: tuple[Node, ...]) -> frozenset[object]:
    """What hangs off a skolemised node, its own name left out (a cycle through skolemised nodes, which
    Turtle's brackets cannot write, is cut where it closes)."""
    if node in path:
        return frozenset({"cycle"})
    inner = (*path, node)
    return frozenset(
        (q.predicate, _shape(q.object, quads_of, inner) if is_skolem(q.object) else q.object)  # type: ignore[arg-type]
        for q in quads_of(node)
    )


@functools.cache
def _history() -> dict[tuple[str, str], tuple[Path, Path | None]]:
    """(bundled file name, version) -> (what every file of that version said, what only some said)."""
    folder = ontology_dir()
    manifest = tomllib.loads((folder / HISTORY).read_text(encoding="utf-8"))
    found: dict[tuple[str, str], tuple[Path, Path | None]] = {}
    for entry in manifest.get("version", []):
        sometimes = entry.get("sometimes")
        found[(entry["file"], entry["version"])] = (folder / entry["said"], folder / sometimes if sometimes else None)
    return found


@functools.cache
def _said(path: Path) -> frozenset[Key]:
    """The statement keys of a history file (parsed once per process, as an upgrade reads it)."""
    return frozenset(statement_keys(_as_stored(parse_file(path, GraphName.ONTOLOGY).quads)))


def _base(name: str, stored: frozenset[str]) -> tuple[frozenset[Key], frozenset[Key]]:
    """What the store's version(s) of bundled file ``name`` said, as (what every file of it said, what
    any said). An unrecorded version says nothing, and the merge then only adds."""
    every: frozenset[Key] | None = None
    some: frozenset[Key] = frozenset()
    for version in stored:
        record = _history().get((name, version))
        if record is None:
            log.warning("%s: version %s is not in %s: what the store lacks of it is added", name, version, HISTORY)
            return frozenset(), some
        said, sometimes = _said(record[0]), _said(record[1]) if record[1] else frozenset()
        every = said if every is None else every & said
        some |= said | sometimes
    return every or frozenset(), some


def _merge_changes(
    store: Store,
    graph: GraphName,
    files: Sequence[tuple[Path, frozenset[str]]],
    removing: list[ox.Quad],
    adding: list[ox.Quad],
) -> tuple[list[ox.Quad], list[ox.Quad]]:
    """The three-way merge of the out-of-date ``files`` into ``graph`` as the other rules (``removing``,
    ``adding``) leave it: add what a file says and its stored version did not, remove what that version
    said and no bundled file says now. Headers are the header rule's. In graph:map, a statement does not
    join where the store gives its subject a value of the lab's own for its property (one neither that
    version nor the bundle says): a thing has one position, one size, one colour, and the lab's stands."""
    heads = {head for _, g, head in _bundled_merged_files() if g is graph}
    view = set(store.quads(graph=graph.node)) - {q for q in removing if q.graph_name == graph.node}
    view |= {q for q in adding if q.graph_name == graph.node}
    stored = statement_keys(view)
    current: dict[Key, list[ox.Quad]] = {}
    for item in bundled_files():
        if item.graph is graph:
            current.update(statement_keys(_bundled(item.path, item.graph)))
    remove: list[ox.Quad] = []
    add: list[ox.Quad] = []
    for path, versions in files:
        theirs = statement_keys(_bundled(path, graph))
        every, some = _base(path.name, versions)
        own = _own_values(stored, some | current.keys()) if graph is GraphName.MAP else frozenset()
        for key, quads in theirs.items():
            if key not in every and key not in stored and not _about(key, heads) and key[:2] not in own:
                add += quads
        for key in some - current.keys():
            if key in stored and not _about(key, heads):
                remove += stored[key]
    return remove, add


def _about(key: Key, heads: set[ox.NamedNode]) -> bool:
    return key[0] in heads


def _own_values(stored: dict[Key, list[ox.Quad]], known: Iterable[Key]) -> frozenset[Key]:
    """The (subject, property) pairs to which the store gives a value that none of ``known`` gives: the
    lab's own (a thing it moved, a colour it changed)."""
    return frozenset(key[:2] for key in stored.keys() - set(known) if len(key) == 3)
