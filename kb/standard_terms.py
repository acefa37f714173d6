"""Standard vocabularies over cbrs's data: what the alignments entail, kept in the graph graph:entailed.

The store answers SPARQL without an OWL reasoner, so ``?s a sosa:Sensor`` would find nothing although
home:Sensor is a subclass of sosa:Sensor (ontologies/alignments.ttl). Rather than rewrite queries, cbrs
materialises: whenever descriptions change (seed, load, update, registration) :func:`refresh` works out
what the alignments entail in the standard vocabularies and makes graph:entailed hold exactly that. A
query in standard terms then needs nothing of cbrs, so a client talking SPARQL to the server directly,
an export and a KnowRob import see it too. The choice and its cost: docs/vocabularies.md.

What is entailed, each conclusion in a standard namespace (``align:standardNamespace``) only:

- **types**: an individual of C is one of every standard class above C (``rdfs:subClassOf`` and
  ``owl:equivalentClass``, through any classes);
- **statements**: (s P o) gives (s Q o) for every standard property Q above P (``rdfs:subPropertyOf``,
  ``owl:equivalentProperty``, ``align:entails``), and (s Q "o"^^xsd:anyURI) for ``align:entailsAsAnyURI``;
- the **domains, ranges and inverses** of those standard properties (RDFS rules 2 and 3, ``owl:inverseOf``);
- **rules**: the answers of the CONSTRUCT queries in ``align:rule`` annotations of the bundled alignments.

Statements about blank nodes are not materialised (cbrs names every node it loads). The statements are
read all terms at once (:mod:`kb.statement_reads`), so a refresh costs a remote store a few requests.
"""

from __future__ import annotations

import functools
import logging
from collections import defaultdict
from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass

import pyoxigraph as ox

from cbrs.kb.errors import StoreError
from cbrs.kb.namespaces import OWL, PREFIXES, RDF, RDFS, XSD, GraphName
from cbrs.kb.resources import ontology_dir
from cbrs.kb.results import releases_results
from cbrs.kb.statement_reads import statements
from cbrs.kb.store import EmbeddedStore, Store
from cbrs.kb.update_delta import DataUpdate

ALIGN = PREFIXES["align"]
ALIGNMENTS_FILE = "alignments.ttl"

_log = logging.getLogger(__name__)
_TYPE = ox.NamedNode(RDF + "type")
_ANY_URI = ox.NamedNode(XSD + "anyURI")
_GRAPH = GraphName.ENTAILED.node

# The links between terms, from every graph but graph:entailed; one pattern per link, so each is an
# index lookup on any server.
_LINKS = [RDFS + "subClassOf", OWL + "equivalentClass", RDFS + "subPropertyOf", OWL + "equivalentProperty"]
_LINKS += [ALIGN + "entails", ALIGN + "entailsAsAnyURI", OWL + "inverseOf", RDFS + "domain", RDFS + "range"]
_LINK_QUERY = (
    "SELECT ?a ?link ?b WHERE {\n"
    + "\n  UNION ".join(f"{{ GRAPH ?g {{ ?a <{link}> ?b }} BIND (<{link}> AS ?link) }}" for link in _LINKS)
    + "\n  FILTER (?g != graph:entailed && isIRI(?a) && isIRI(?b))\n}"
)
_LINK_SET = frozenset(_LINKS) | {ALIGN + "standardNamespace"}
_NAMESPACE_QUERY = "SELECT DISTINCT ?namespace WHERE { ?vocabulary align:standardNamespace ?namespace }"
#: The query texts above: cbrs's own, so they skip the query guard's checker (:func:`kb.store.bundled_query_texts`).
OWN_QUERIES = (_LINK_QUERY, _NAMESPACE_QUERY)


@dataclass(frozen=True)
class Refresh:
    """What :func:`refresh` changed in graph:entailed."""

    added: int
    removed: int
    total: int


@dataclass(frozen=True)
class PendingUpdate:
    """An update about to run, as :meth:`StandardTerms.prepare` read it: its data, and what the rules
    concluded before it ran."""

    data: DataUpdate
    before: frozenset[ox.Quad]


class Alignment:
    """The alignments found in a store: which standard terms each term entails."""

    def __init__(self, links: Iterable[tuple[str, str, str]], namespaces: Iterable[str]) -> None:
        self.namespaces = tuple(sorted(set(namespaces)))
        down: dict[str, set[str]] = defaultdict(set)  # term -> the terms just below it
        self._as_uri: dict[str, set[str]] = defaultdict(set)
        self._inverse: dict[str, set[str]] = defaultdict(set)
        self._domain: dict[str, set[str]] = defaultdict(set)
        self._range: dict[str, set[str]] = defaultdict(set)
        standard: set[str] = set()
        for a, link, b in links:
            name = link.rsplit("#", 1)[-1]
            if name in ("subClassOf", "subPropertyOf", "entails"):
                down[b].add(a)
            elif name in ("equivalentClass", "equivalentProperty"):
                down[b].add(a)
                down[a].add(b)
            elif name == "entailsAsAnyURI":
                self._as_uri[a].add(b)
            elif name == "inverseOf":
                self._inverse[a].add(b)
                self._inverse[b].add(a)
            elif name == "domain":
                self._domain[a].add(b)
            else:
                self._range[a].add(b)
            standard.update(term for term in (a, b) if self.is_standard(term))
        self.standard = frozenset(standard)
        # Walk down from each standard term: everything below it has it above. Only the (small) part of
        # the taxonomy under standard terms is visited.
        above: dict[str, set[str]] = defaultdict(set)
        for top in self.standard:
            seen, pending = {top}, [top]
            while pending:
                for lower in down.get(pending.pop(), ()):
                    if lower not in seen:
                        seen.add(lower)
                        pending.append(lower)
            for lower in seen - {top}:
                above[lower].add(top)
        self._above = {term: frozenset(uppers) for term, uppers in above.items()}
        self._classes = frozenset(self.classes())
        self._properties = frozenset(self.properties())
        # The properties whose statements entail something about their object (a range or an inverse).
        self.object_reaching = frozenset(
            p for p in self._properties if any(self._range.get(q) or self._inverse.get(q) for q in self._standard_of(p))
        )

    def is_standard(self, iri: str) -> bool:
        return bool(self.namespaces) and iri.startswith(self.namespaces)

    def above(self, term: str) -> frozenset[str]:
        """The standard terms above ``term`` (not ``term`` itself), through any terms."""
        return self._above.get(term, frozenset())

    def classes(self) -> set[str]:
        """The classes whose individuals to read: those with a standard class above them, and the
        standard ones (so that what the data asserts in standard terms is not repeated)."""
        return set(self._above) | set(self.standard)

    def properties(self) -> set[str]:
        """The properties whose statements to read: those with a standard property above them or an
        anyURI counterpart, and the standard ones."""
        return set(self._above) | set(self._as_uri) | set(self.standard)

    def _standard_of(self, p: str) -> set[str]:
        """The standard properties (s p o) is a statement of: those above ``p``, and ``p`` if it is one."""
        return set(self.above(p)) | ({p} if self.is_standard(p) else set())

    def statement(
        self, s: ox.NamedNode, p: str, o: ox.NamedNode | ox.BlankNode | ox.Literal | ox.Triple
    ) -> Iterator[ox.Triple]:
        """What (s p o) entails."""
        standard = self._standard_of(p)
        for q in self.above(p):
            yield ox.Triple(s, ox.NamedNode(q), o)
        for q in self._as_uri.get(p, ()):
            if isinstance(o, ox.NamedNode) and self.is_standard(q):
                yield ox.Triple(s, ox.NamedNode(q), ox.Literal(o.value, datatype=_ANY_URI))
        for q in standard:
            yield from self._typed(s, self._domain.get(q, ()))
            if isinstance(o, ox.NamedNode):
                yield from self._typed(o, self._range.get(q, ()))
                for inverse in self._inverse.get(q, ()):
                    if self.is_standard(inverse):
                        yield ox.Triple(o, ox.NamedNode(inverse), s)

    def typed(self, s: ox.NamedNode, cls: str) -> Iterator[ox.Triple]:
        """What (s rdf:type cls) entails."""
        return self._typed(s, self.above(cls))

    def triple(self, triple: ox.Triple) -> Iterator[ox.Triple]:
        """What one statement entails, whatever its predicate."""
        s, p, o = triple.subject, triple.predicate, triple.object
        if not isinstance(s, ox.NamedNode) or isinstance(o, ox.Triple):
            return
        if p == _TYPE and isinstance(o, ox.NamedNode):
            yield from self.typed(s, o.value)
        else:
            yield from self.statement(s, p.value, o)

    def is_read(self, triple: ox.Triple) -> bool:
        """Whether :meth:`StandardTerms.refresh` reads ``triple`` (when in a named graph other than
        graph:entailed): a type of one of :meth:`classes`, a statement of one of :meth:`properties`."""
        s, p, o = triple.subject, triple.predicate, triple.object
        if not isinstance(s, ox.NamedNode):
            return False
        return (p == _TYPE and isinstance(o, ox.NamedNode) and o.value in self._classes) or p.value in self._properties

    def entailments(self, triple: ox.Triple) -> Iterator[ox.Triple]:
        """What one statement entails as :meth:`StandardTerms.refresh` reads it (:meth:`is_read`)."""
        s, p, o = triple.subject, triple.predicate, triple.object
        if not isinstance(s, ox.NamedNode):
            return
        if p == _TYPE and isinstance(o, ox.NamedNode) and o.value in self._classes:
            yield from self.typed(s, o.value)
        if p.value in self._properties:
            yield from self.statement(s, p.value, o)

    def _typed(self, s: ox.NamedNode, classes: Iterable[str]) -> Iterator[ox.Triple]:
        for cls in classes:
            if self.is_standard(cls):
                yield ox.Triple(s, _TYPE, ox.NamedNode(cls))
                for upper in self.above(cls):
                    yield ox.Triple(s, _TYPE, ox.NamedNode(upper))


class StandardTerms:
    """graph:entailed of one store, kept to what the rest of the store entails.

    :meth:`refresh` works it out from the whole store (after a seed, a load, an update of any kind);
    :meth:`prepare` and :meth:`updated` bring it up to date after an update of ground data (``INSERT
    DATA``, ``DELETE DATA``) from the nodes it changed alone, and :meth:`begin` and :meth:`changed` after
    one description changed (a registration), both reusing the alignments read at the last refresh.

    Each is two writes: first what the alignments entail statement by statement, then the rules'
    conclusions, so that a rule may ask for standard types (``?sensor a sosa:Sensor``) instead of
    following ``rdfs:subClassOf*`` paths, which Virtuoso 7 evaluates unreliably inside larger patterns.
    """

    def __init__(self, store: Store) -> None:
        self.store = store
        self._alignment: Alignment | None = None
        # Whether graph:entailed is known to be what the store entails: a whole refresh in this process
        # made it so and every change since was followed. Until then an update takes a whole refresh.
        self._exact = False

    def alignment(self) -> Alignment:
        if self._alignment is None:
            self._alignment = read_alignment(self.store)
        return self._alignment

    def refresh(self) -> Refresh:
        """Make graph:entailed hold what the store entails now."""
        self._exact = False
        alignment = self._alignment = read_alignment(self.store)
        before = self._rule_conclusions(alignment)
        wanted, asserted = self._closure(alignment)
        held = set(self.store.quads(graph=_GRAPH))
        first = self._write(held - wanted - before, wanted - held)
        held = (held - (held - wanted - before)) | wanted
        after = self._rule_conclusions(alignment) - asserted
        second = self._write(held - wanted - after, after - held)
        self._exact = True
        return Refresh(first.added + second.added, first.removed + second.removed, len(wanted | after))

    def prepare(self, data: DataUpdate | None) -> PendingUpdate | None:
        """Before an update runs: what :meth:`updated` needs to follow it node by node, or None when a whole
        :meth:`refresh` must follow instead. ``data`` is the update as :meth:`DataUpdate.read` read it, None
        when it is not only ground data operations read for certain (:mod:`kb.update_delta`); a whole
        refresh follows too when it names an alignment, a standard namespace or graph:entailed itself,
        on a remote store (which other clients write meanwhile), and while graph:entailed is not known
        to be exact."""
        if data is None or not self._exact or not isinstance(self.store, EmbeddedStore):
            return None
        if any(q.predicate.value in _LINK_SET or q.graph_name == _GRAPH for q in data.named):
            return None
        return PendingUpdate(data, self.begin())

    def updated(self, pending: PendingUpdate | None) -> Refresh:
        """After an update ran: bring graph:entailed up to date from the nodes it changed (``pending``, from
        :meth:`prepare`), or by a whole :meth:`refresh` when there is none or its reading is not borne out."""
        delta = pending.data.delta(self.store) if pending is not None and self._exact else None
        if pending is None or delta is None:
            if pending is not None:
                _log.info("update not read for certain; graph:entailed is worked out from the whole store")
            return self.refresh()
        added, removed = delta
        return self._follow(pending.before, _nodes(self.alignment(), (*added, *removed)))

    def begin(self) -> frozenset[ox.Quad]:
        """What the rules conclude now: call it before changing a description, then :meth:`changed`."""
        return frozenset(self._rule_conclusions(self.alignment()))

    def changed(self, before: frozenset[ox.Quad], removed: Sequence[ox.Quad], added: Sequence[ox.Quad]) -> Refresh:
        """Bring graph:entailed up to date after one description's ``removed`` quads made way for ``added``.

        What the removed statements entailed about the description's own nodes goes, what the added
        ones entail comes, and the rules' conclusions are compared before and after. A change to the
        alignments themselves (a subclass axiom in a description) takes a whole :meth:`refresh`.
        """
        try:
            if any(quad.predicate.value in _LINK_SET for quad in (*removed, *added)):
                return self.refresh()
            if isinstance(self.store, EmbeddedStore):
                return self._follow(before, _nodes(self.alignment(), (*removed, *added)))
            return self._changed(before, removed, added)
        except StoreError as error:
            # the description's own write stands; graph:entailed lags until the next refresh
            _log.warning("graph:entailed not brought up to date: %s", error)
            self._alignment = None
            return Refresh(0, 0, -1)

    def _changed(self, before: frozenset[ox.Quad], removed: Sequence[ox.Quad], added: Sequence[ox.Quad]) -> Refresh:
        alignment = self.alignment()
        if not alignment.namespaces:
            return Refresh(0, 0, 0)
        own = {_quad(ox.Triple(q.subject, q.predicate, q.object)) for q in added}
        new = {_quad(t) for q in added for t in alignment.triple(ox.Triple(q.subject, q.predicate, q.object))} - own
        nodes = {q.subject for q in removed}
        old = {_quad(t) for q in removed for t in alignment.triple(ox.Triple(q.subject, q.predicate, q.object))}
        # what another graph's statements still entail about those nodes stays (a service's request copy
        # shares its OWL-S parameters: deregistering one copy took <#Goal> a process:Parameter from both)
        kept = self._wanted(alignment, {n for n in nodes if isinstance(n, ox.NamedNode)}) if old else set()
        first = self._write({q for q in old if q.subject in nodes} - new - before - kept, new)
        after = self._rule_conclusions(alignment) - own
        second = self._write(set(before) - after - new, after)
        return Refresh(first.added + second.added, first.removed + second.removed, -1)

    def _follow(self, before: frozenset[ox.Quad], nodes: set[ox.NamedNode]) -> Refresh:
        """Bring graph:entailed up to date after the statements about ``nodes`` changed (and nothing else),
        when ``before`` is what the rules concluded before the change: as :meth:`refresh` would, but
        reading only the statements about those nodes.

        What the statements entail one by one about a node is worked out from all the statements about
        it now, those it is the object of included (ranges, inverses): a conclusion stays while any
        statement supports it. Nothing about another node can have changed, except what the rules
        concluded: the two writes are :meth:`refresh`'s, over the changed nodes and the subjects of the
        rules' conclusions that came or went. Exact when graph:entailed was: what it holds beyond the
        statements' entailments is what the rules concluded (``before``).
        """
        exact, self._exact = self._exact, False  # not exact if a write fails half way
        alignment = self.alignment()
        if not alignment.namespaces:
            self._exact = exact
            return Refresh(0, 0, 0)
        now = self._rule_conclusions(alignment)  # what refresh calls before: the rules on the changed store
        near = nodes | _subjects(before - now)
        wanted = self._wanted(alignment, near)
        held = {quad for node in near for quad in self.store.quads(node, None, None, _GRAPH)}
        first = self._write(held - wanted - now, wanted - held)
        # the rules again on the store as the first write left it (which, if it wrote nothing, is as it was)
        concluded = self._rule_conclusions(alignment) if first.added or first.removed else now
        after = {quad for quad in concluded if not self._asserted(alignment, quad)}
        gone = now - after
        wanted |= self._wanted(alignment, _subjects(gone) - near)
        second = self._write(
            {q for q in gone if q not in wanted and _holds(self.store, q)},
            {q for q in after if not _holds(self.store, q)},
        )
        self._exact = exact
        return Refresh(first.added + second.added, first.removed + second.removed, -1)

    def _wanted(self, alignment: Alignment, nodes: Iterable[ox.NamedNode]) -> set[ox.Quad]:
        """What the statements of the store entail one by one about ``nodes`` (:meth:`_closure`'s part), from
        the statements about them, and those they are the object of whose property reaches its object (a
        range, an inverse): read for all the nodes at once, so what one node's statements entail about
        another is among what that one's own reading would give."""
        about = set(nodes)
        if not about:
            return set()
        reaching = [ox.NamedNode(p) for p in sorted(alignment.object_reaching)]
        listed = sorted(about, key=str)
        read = statements(self.store, [{"s": listed}, {"o": listed, "p": reaching}])
        asserted = {t for t in read if alignment.is_read(t)}
        triples = {t for statement in read for t in alignment.entailments(statement)}
        return {_quad(t) for t in triples - asserted if t.subject in about and _named(t)}

    def _asserted(self, alignment: Alignment, quad: ox.Quad) -> bool:
        """Whether :meth:`_closure` reads ``quad``'s statement from the store (so it is no conclusion)."""
        subject = quad.subject
        if not isinstance(subject, ox.NamedNode) or isinstance(quad.object, ox.Triple):
            return False
        triple = ox.Triple(subject, quad.predicate, quad.object)
        return alignment.is_read(triple) and any(
            _read(q) for q in self.store.quads(subject, quad.predicate, quad.object)
        )

    def _closure(self, alignment: Alignment) -> tuple[set[ox.Quad], set[ox.Quad]]:
        """What the statements of the store entail one by one, and the statements read for it."""
        if not alignment.namespaces:
            return set(), set()
        classes = [ox.NamedNode(c) for c in sorted(alignment.classes())]
        properties = [ox.NamedNode(p) for p in sorted(alignment.properties())]
        asserted = statements(self.store, [{"p": [_TYPE], "o": classes}, {"p": properties}])
        triples = {t for statement in asserted for t in alignment.entailments(statement)}
        return {_quad(t) for t in triples - asserted if _named(t)}, {_quad(t) for t in asserted}

    @releases_results
    def _rule_conclusions(self, alignment: Alignment) -> set[ox.Quad]:
        """What the rules conclude from the store as it is now (graph:entailed included), closed."""
        found: set[ox.Quad] = set()
        if not alignment.namespaces:
            return found
        for rule in rules():
            result = self.store.query(rule)
            assert isinstance(result, ox.QueryTriples)
            for triple in result:
                if _named(triple):
                    found.add(_quad(triple))
                    found.update(_quad(t) for t in alignment.triple(triple) if _named(t))
        return found

    def _write(self, stale: set[ox.Quad], fresh: set[ox.Quad]) -> Refresh:
        removing, adding = sorted(stale, key=str), sorted(fresh, key=str)
        batch: int | None = getattr(self.store, "batch", None)  # a remote store's largest write
        if batch is None or len(removing) + len(adding) <= batch:
            if removing or adding:
                self.store.replace(removing, adding)
        else:
            # Too large for one request: the new statements first (one staged write, whole or nothing),
            # then the stale ones; if that fails part way, stale statements stay until the next refresh.
            self.store.add(adding)
            for start in range(0, len(removing), batch):
                self.store.replace(removing[start : start + batch], [])
        return Refresh(len(adding), len(removing), -1)


def read_alignment(store: Store) -> Alignment:
    """The alignments and standard namespaces the store holds (outside graph:entailed)."""
    links = _rows(store, _LINK_QUERY)
    namespaces = [row["namespace"].value for row in _rows(store, _NAMESPACE_QUERY)]
    return Alignment(((r["a"].value, r["link"].value, r["b"].value) for r in links), namespaces)


def entailed(store: Store) -> set[ox.Quad]:
    """Every quad graph:entailed should hold, worked out from the rest of the store: what its statements
    entail one by one, and what the rules conclude from those and the rest (for checking: it does not
    write, so a rule sees the statement-by-statement part as graph:entailed holds it now)."""
    terms = StandardTerms(store)
    alignment = terms.alignment()
    wanted, asserted = terms._closure(alignment)
    return wanted | (terms._rule_conclusions(alignment) - asserted)


def refresh(store: Store) -> Refresh:
    """Make graph:entailed hold what the store entails now (:meth:`StandardTerms.refresh`)."""
    return StandardTerms(store).refresh()


@functools.cache
def rules() -> tuple[str, ...]:
    """The CONSTRUCT rules of the bundled alignments (read from the package, not the store: a rule is
    a query cbrs runs on every change, so only the shipped ones run)."""
    graph = ox.parse(path=str(ontology_dir() / ALIGNMENTS_FILE), format=ox.RdfFormat.TURTLE)
    return tuple(sorted(t.object.value for t in graph if t.predicate.value == ALIGN + "rule"))


def _named(triple: ox.Triple) -> bool:
    return not isinstance(triple.subject, ox.BlankNode) and not isinstance(triple.object, ox.BlankNode)


def _read(quad: ox.Quad) -> bool:
    """Whether :meth:`StandardTerms.refresh` reads ``quad``'s graph: a named graph other than graph:entailed."""
    return not isinstance(quad.graph_name, ox.DefaultGraph) and quad.graph_name != _GRAPH


def _holds(store: Store, quad: ox.Quad) -> bool:
    """Whether graph:entailed holds ``quad``."""
    subject, obj = quad.subject, quad.object
    if isinstance(subject, ox.Triple) or isinstance(obj, ox.Triple):
        return False
    return next(store.quads(subject, quad.predicate, obj, _GRAPH), None) is not None


def _subjects(quads: Iterable[ox.Quad]) -> set[ox.NamedNode]:
    return {quad.subject for quad in quads if isinstance(quad.subject, ox.NamedNode)}


def _nodes(alignment: Alignment, quads: Sequence[ox.Quad]) -> set[ox.NamedNode]:
    """The nodes what ``quads`` entail one by one is about: their subjects, and their objects when the
    predicate has a range or an inverse."""
    nodes = _subjects(quads)
    for quad in quads:
        if isinstance(quad.object, ox.NamedNode) and quad.predicate.value in alignment.object_reaching:
            nodes.add(quad.object)
    return nodes


def _quad(triple: ox.Triple) -> ox.Quad:
    return ox.Quad(triple.subject, triple.predicate, triple.object, _GRAPH)


@releases_results
def _rows(store: Store, query: str, bindings: dict[str, ox.NamedNode] | None = None) -> list[ox.QuerySolution]:
    result = store.query(query, bindings)
    assert isinstance(result, ox.QuerySolutions)
    return list(result)
