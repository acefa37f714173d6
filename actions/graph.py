"""The service resource graph (paper section 4): who can feed whom.

Vertices are the advertised components plus three virtual nodes: SRI provides the requirement's inputs
(and takes its preconditions as given), SRO needs its outputs and SRE needs its effects. An edge runs
from a producer to a consumer for every need of the consumer that an offer of the producer meets:

* I-O: an output of the producer for an input of the consumer;
* P-E: an effect of the producer for a precondition of the consumer (an RDF statement);
* D: a delete effect of the producer for a delete effect the requirement wants (SRE's "deletion" needs:
  the statement must stop being true, docs/composition.md "Delete effects a task wants");

when the degree of match is in the paper's threshold {Exact, SubClassOf, HasSubClass}. Each edge
carries that degree and the Sem-Str similarity (equation 8 for statements).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from functools import cached_property
from typing import Literal

import networkx as nx

from cbrs.kb import Advertisement, Parameter, Requirement, Statement
from cbrs.kb.namespaces import shorten
from cbrs.kb.vocab import CBRS
from cbrs.reasoner.config import MatchConfig
from cbrs.reasoner.degrees import Degree, degree_of_match
from cbrs.reasoner.similarity import SemStr
from cbrs.reasoner.statements import statement_similarity
from cbrs.reasoner.taxonomy import TaxonomyIndex

SRI = "SRI"  # virtual entrance: provides the requirement's inputs and preconditions
SRO = "SRO"  # virtual exit: needs the requirement's outputs
SRE = "SRE"  # virtual exit: needs the requirement's effects
VIRTUAL = (SRI, SRO, SRE)

# Component kinds whose invocation depends only on its inputs, so one invocation can feed several
# consumers. Perception (time-varying) and physical actions are invoked once per use.
SHAREABLE_KINDS = frozenset({CBRS.StaticDataComponent, CBRS.MethodInvocationComponent})


def statement_text(statement: Statement) -> str:
    return f"({shorten(statement.subject)}, {shorten(statement.predicate)}, {shorten(statement.object)})"


@dataclass(frozen=True)
class Need:
    """An input or precondition a vertex must have supplied before it can run."""

    role: Literal["input", "precondition", "deletion"]  # deletion: SRE's, a statement to stop being true
    name: str
    concept: str | None = None
    statement: Statement | None = None

    @cached_property  # looked up for every edge an extraction considers
    def key(self) -> str:
        return f"{self.role}:{self.name}"

    def text(self) -> str:
        if self.statement is not None and self.role == "deletion":
            return f"delete effect {statement_text(self.statement)}"
        if self.statement is not None:
            return f"precondition {statement_text(self.statement)}"
        return f"input {self.name} ({shorten(self.concept or '')})"


@dataclass(frozen=True)
class Offer:
    """An output or effect a vertex supplies once it has run."""

    role: Literal["output", "effect", "delete"]
    name: str
    concept: str | None = None
    statement: Statement | None = None


@dataclass(frozen=True)
class Edge:
    source: str
    target: str
    need: Need
    offer: Offer
    degree: Degree
    similarity: float

    @property
    def kind(self) -> str:
        return "io" if self.need.role == "input" else "pe"


@dataclass(frozen=True)
class Vertex:
    iri: str
    needs: tuple[Need, ...]
    offers: tuple[Offer, ...]
    cost: float  # seconds: the advertised response time (composition's default measure of cost)
    advertisement: Advertisement | None = None
    stated_cost: float | None = None  # the advertised cbrs:cost, a unitless figure; None: it states none

    @property
    def shareable(self) -> bool:
        return self.advertisement is not None and self.advertisement.kind in SHAREABLE_KINDS


class Matcher:
    """Degree of match and similarity of an offered entity for a needed one, cached."""

    def __init__(self, index: TaxonomyIndex, config: MatchConfig | None = None) -> None:
        self.index = index
        self.config = config or MatchConfig()
        self.measure = SemStr(index, self.config)
        self._concepts: dict[tuple[str, str], tuple[Degree, float] | None] = {}
        self._statements: dict[tuple[Statement, Statement], tuple[Degree, float] | None] = {}

    def concept(self, wanted: str, offered: str) -> tuple[Degree, float] | None:
        key = (wanted, offered)
        if key not in self._concepts:
            degree = degree_of_match(self.index, wanted, offered)
            self._concepts[key] = (degree, self.measure(wanted, offered).value) if degree.accepted else None
        return self._concepts[key]

    def statement(self, wanted: Statement, offered: Statement) -> tuple[Degree, float] | None:
        key = (wanted, offered)
        if key not in self._statements:  # every composition matches the world state against each precondition
            self._statements[key] = self._statement(wanted, offered)
        return self._statements[key]

    def _statement(self, wanted: Statement, offered: Statement) -> tuple[Degree, float] | None:
        degrees = [
            degree_of_match(self.index, w, o)
            for w, o in (
                (wanted.subject, offered.subject),
                (wanted.predicate, offered.predicate),
                (wanted.object, offered.object),
            )
        ]
        if not all(d.accepted for d in degrees):
            return None
        if all(d is Degree.EXACT for d in degrees):
            degree = Degree.EXACT
        elif Degree.HAS_SUBCLASS in degrees:
            degree = Degree.HAS_SUBCLASS
        else:
            degree = Degree.SUBCLASS_OF
        return degree, statement_similarity(wanted, offered, self.measure, self.config).value

    def match(self, need: Need, offer: Offer) -> tuple[Degree, float] | None:
        if need.concept is not None and offer.concept is not None:
            return self.concept(need.concept, offer.concept)
        if need.statement is not None and offer.statement is not None:
            return self.statement(need.statement, offer.statement)
        return None


class ServicePool:
    """The advertised components and the edges among them: built once, shared by every requirement.

    Offered concepts are indexed by their is-a ancestors, so each need is compared only with the
    offers whose degree can be accepted (its subclasses, itself, its superclasses), never with all.
    """

    def __init__(
        self,
        advertisements: Iterable[Advertisement],
        matcher: Matcher,
        default_cost: float = 1.0,
        unstated_cost: float | None = None,
    ) -> None:
        """``default_cost``: the response time of a component that advertises none; ``unstated_cost``: the
        ``cbrs:cost`` of one that states none (None: it has none, and is not compared by it)."""
        self.matcher = matcher
        self.vertices: dict[str, Vertex] = {
            ad.iri: Vertex(
                ad.iri,
                _needs(ad.inputs, ad.preconditions),
                tuple(_offers(ad.outputs, ad.effects)),
                _cost(ad, default_cost),
                ad,
                stated_cost(ad, unstated_cost),
            )
            for ad in advertisements
        }
        self._by_concept: dict[str, list[tuple[str, Offer]]] = {}
        self._statements: list[tuple[str, Offer]] = []
        self.deletions = [  # what each component deletes, for the delete effects a requirement wants
            (v.iri, Offer("delete", statement_text(s), statement=s))
            for v in self.vertices.values()
            if v.advertisement is not None
            for s in v.advertisement.deletes
        ]
        self._below: dict[str, set[str]] = {}  # ancestor -> offered concepts at or below it
        for vertex in self.vertices.values():
            self.index_offers(vertex)
        self.into: dict[str, dict[str, list[Edge]]] = {
            v.iri: {need.key: self.providers_of(v.iri, need) for need in v.needs} for v in self.vertices.values()
        }

    def index_offers(self, vertex: Vertex) -> None:
        index = self.matcher.index
        for offer in vertex.offers:
            if offer.concept is None:
                self._statements.append((vertex.iri, offer))
                continue
            if offer.concept not in self._by_concept:
                self._by_concept[offer.concept] = []
                above = set(index.is_a_ancestors(offer.concept)) if offer.concept in index else set()
                for ancestor in above | {offer.concept}:
                    self._below.setdefault(ancestor, set()).add(offer.concept)
            self._by_concept[offer.concept].append((vertex.iri, offer))

    def candidates(self, concept: str) -> set[str]:
        """Offered concepts that may match ``concept``: at or below it, or above it."""
        index = self.matcher.index
        found = set(self._below.get(concept, ()))
        if concept in index:
            found |= set(self._below.get(index.canonical(concept), ()))
            found |= {a for a in index.is_a_ancestors(concept) if a in self._by_concept}
        return found

    def providers_of(self, consumer: str, need: Need) -> list[Edge]:
        """Edges from the pool's offers into ``consumer`` for ``need``, most similar first."""
        found: list[Edge] = []
        if need.role == "deletion":
            for src, offer in self.deletions:
                result = self.matcher.match(need, offer)
                if result is not None:
                    found.append(Edge(src, consumer, need, offer, *result))
        elif need.concept is not None:
            for concept in self.candidates(need.concept):
                result = self.matcher.concept(need.concept, concept)
                if result is not None:
                    found += [Edge(src, consumer, need, o, *result) for src, o in self._by_concept[concept]]
        else:
            for src, offer in self._statements:
                result = self.matcher.match(need, offer)
                if result is not None:
                    found.append(Edge(src, consumer, need, offer, *result))
        found = [e for e in found if e.source != e.target]
        found.sort(key=_rank)
        return found


class ServiceResourceGraph:
    """The SRG for one requirement: the pool's vertices and edges plus SRI, SRO and SRE."""

    def __init__(
        self,
        requirement: Requirement,
        pool: ServicePool,
        holding: Sequence[Statement] = (),
        admits: Callable[[Statement, Statement], bool] | None = None,
    ) -> None:
        """``holding``: statements that hold in the world now (the belief state, lifted to classes);
        SRI offers them to the components' preconditions, never to the goals, so what is already
        achieved is kept and a goal is still planned for. ``admits(precondition, held)``: whether a
        statement held may meet a precondition that its classes meet, for this requirement (it is about
        the thing the precondition concerns: ``actions.named_things``); None: every one may."""
        self.requirement = requirement
        self.pool = pool
        self.matcher = pool.matcher
        given = tuple(_offers(requirement.inputs, ())) + tuple(
            Offer("effect", statement_text(s), statement=s) for s in requirement.preconditions
        )
        state = tuple(
            Offer("effect", f"holds {statement_text(s)}", statement=s)
            for s in holding
            if s not in requirement.preconditions
        )
        self.vertices: dict[str, Vertex] = {
            SRI: Vertex(SRI, (), given + state, 0.0),
            **pool.vertices,
            SRO: Vertex(SRO, _needs(requirement.outputs, ()), (), 0.0),
            SRE: Vertex(SRE, _needs((), requirement.effects) + _deletions(requirement.deletes), (), 0.0),
        }
        self._into: dict[str, dict[str, list[Edge]]] = {}
        for goal in (SRO, SRE):
            self._into[goal] = {n.key: pool.providers_of(goal, n) for n in self.vertices[goal].needs}
        # SRI's edges into every vertex that needs what the requirement gives; an input is met by
        # outputs only and a precondition by statements only, so each is compared with its kind alone
        held = set(state) if admits is not None else set()  # what the world offers, as ``admits`` says
        kinds = {
            (to_goal, role): tuple(o for o in offers if (o.concept is not None) == (role == "input"))
            for to_goal, offers in ((True, given), (False, given + state))
            for role in ("input", "precondition")
        }
        for vertex in self.vertices.values():
            to_goal = vertex.iri in (SRO, SRE)
            for need in vertex.needs:
                if need.role == "deletion":  # a step must delete it: what the task gives deletes nothing
                    continue
                offered = kinds[to_goal, need.role]
                given_edges = [
                    Edge(SRI, vertex.iri, need, o, *m)
                    for o in offered
                    if (m := self.matcher.match(need, o)) and (o not in held or _admitted(admits, need, o))
                ]
                if given_edges:
                    base = self._into.get(vertex.iri, {}).get(need.key, pool.into.get(vertex.iri, {}).get(need.key, []))
                    self._into.setdefault(vertex.iri, {})[need.key] = sorted(base + given_edges, key=_rank)

    def needs(self, iri: str) -> tuple[Need, ...]:
        return self.vertices[iri].needs

    def providers(self, iri: str, need: Need) -> list[Edge]:
        """Edges into ``iri`` that meet ``need``, most similar first."""
        mine = self._into.get(iri)
        if mine is not None and need.key in mine:
            return mine[need.key]
        return self.pool.into.get(iri, {}).get(need.key, [])

    def edges(self) -> list[Edge]:
        return [e for iri, vertex in self.vertices.items() for need in vertex.needs for e in self.providers(iri, need)]

    @property
    def graph(self) -> nx.MultiDiGraph[str]:
        """The SRG as a networkx multigraph (built on demand: one edge per need met)."""
        graph: nx.MultiDiGraph[str] = nx.MultiDiGraph()
        graph.add_nodes_from(self.vertices)
        for e in self.edges():
            graph.add_edge(e.source, e.target, key=f"{e.need.key}<-{e.offer.name}", edge=e)
        return graph

    def cost(self, iri: str) -> float:
        return self.vertices[iri].cost

    def stated_cost(self, iri: str) -> float | None:
        """The ``cbrs:cost`` ``iri`` states (None: none, or a virtual node)."""
        return self.vertices[iri].stated_cost


def _admitted(admits: Callable[[Statement, Statement], bool] | None, need: Need, offer: Offer) -> bool:
    """Whether the world's ``offer`` may meet ``need``, as ``admits`` says."""
    if admits is None or need.statement is None or offer.statement is None:
        return True
    return admits(need.statement, offer.statement)


def _rank(edge: Edge) -> tuple[float, str, str]:
    return (-edge.similarity, edge.source, edge.offer.name)


def _needs(inputs: Sequence[Parameter], preconditions: Sequence[Statement]) -> tuple[Need, ...]:
    needs = [Need("input", name, concept=p.type) for p, name in zip(inputs, _names(inputs), strict=True)]
    needs += [Need("precondition", statement_text(s), statement=s) for s in preconditions]
    return tuple(needs)


def _deletions(deletes: Sequence[Statement]) -> tuple[Need, ...]:
    """The delete effects a requirement wants, as SRE's needs: met by a component's delete effect."""
    return tuple(Need("deletion", f"not {statement_text(s)}", statement=s) for s in deletes)


def _offers(outputs: Sequence[Parameter], effects: Sequence[Statement]) -> list[Offer]:
    offers = [Offer("output", name, concept=p.type) for p, name in zip(outputs, _names(outputs), strict=True)]
    offers += [Offer("effect", statement_text(s), statement=s) for s in effects]
    return offers


def parameter_names(parameters: Sequence[Parameter]) -> list[str]:
    """The names steps and plans use for ``parameters`` (see ``_names``)."""
    return _names(parameters)


def _names(parameters: Sequence[Parameter]) -> list[str]:
    """Parameter names, unique within one list (the type's local name when a parameter has none)."""
    names: list[str] = []
    for p in parameters:
        base = p.name or shorten(p.type).split(":")[-1]
        name, n = base, 2
        while name in names:
            name, n = f"{base}#{n}", n + 1
        names.append(name)
    return names


def _cost(ad: Advertisement, default: float) -> float:
    """The advertised response time in seconds: the paper's 'minimum cost' uses it."""
    for q in ad.qos:
        if q.metric == CBRS.responseTime:
            return q.value
    return default


def stated_cost(ad: Advertisement, default: float | None = None) -> float | None:
    """The advertised ``cbrs:cost`` (core.ttl: lower is better, no unit), which ``--objective cost`` ranks
    by; ``default`` for a component that states none. Kept apart from the response time: a figure
    without a unit cannot be added to seconds (docs/composition.md, "Which cost")."""
    for q in ad.qos:
        if q.metric == CBRS.cost:
            return q.value
    return default
