"""The service resource graph (paper section 4): who can feed whom.

Vertices are the advertised components plus three virtual nodes: SRI provides the requirement's inputs
(and takes its preconditions as given), SRO needs its outputs and SRE needs its effects. An edge runs
from a producer to a consumer for every need of the consumer that an offer of the producer meets:

* I-O: an output of the producer for an input of the consumer;
* P-E: an effect of the producer for a precondition of the consumer (an RDF statement);

when the degree of match is in the paper's threshold {Exact, SubClassOf, HasSubClass}. Each edge
carries that degree and the Sem-Str similarity (equation 8 for statements).
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Literal

import networkx as nx

from kb import Advertisement, Parameter, Requirement, Statement
from kb.namespaces import shorten
from kb.vocab import CBRS
from reasoner.config import MatchConfig
from reasoner.degrees import Degree, degree_of_match
from reasoner.similarity import SemStr
from reasoner.statements import statement_similarity
from reasoner.taxonomy import TaxonomyIndex

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

    role: Literal["input", "precondition"]
    name: str
    concept: str | None = None
    statement: Statement | None = None

    @property
    def key(self) -> str:
        return f"{self.role}:{self.name}"

    def text(self) -> str:
        if self.statement is not None:
            return f"precondition {statement_text(self.statement)}"
        return f"input {self.name} ({shorten(self.concept or '')})"


@dataclass(frozen=True)
class Offer:
    """An output or effect a vertex supplies once it has run."""

    role: Literal["output", "effect"]
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
    cost: float
    advertisement: Advertisement | None = None

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

    def concept(self, wanted: str, offered: str) -> tuple[Degree, float] | None:
        key = (wanted, offered)
        if key not in self._concepts:
            degree = degree_of_match(self.index, wanted, offered)
            self._concepts[key] = (degree, self.measure(wanted, offered).value) if degree.accepted else None
        return self._concepts[key]

    def statement(self, wanted: Statement, offered: Statement) -> tuple[Degree, float] | None:
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


class ServiceResourceGraph:
    """The SRG for one requirement over a pool of advertisements (a networkx MultiDiGraph)."""

    def __init__(
        self,
        requirement: Requirement,
        advertisements: Iterable[Advertisement],
        matcher: Matcher,
        default_cost: float = 1.0,
    ) -> None:
        self.requirement = requirement
        self.matcher = matcher
        self.vertices: dict[str, Vertex] = {}
        given = tuple(_offers(requirement.inputs, ())) + tuple(
            Offer("effect", statement_text(s), statement=s) for s in requirement.preconditions
        )
        self.vertices[SRI] = Vertex(SRI, (), given, 0.0)
        for ad in advertisements:
            self.vertices[ad.iri] = Vertex(
                ad.iri,
                _needs(ad.inputs, ad.preconditions),
                tuple(_offers(ad.outputs, ad.effects)),
                _cost(ad, default_cost),
                ad,
            )
        self.vertices[SRO] = Vertex(SRO, _needs(requirement.outputs, ()), (), 0.0)
        self.vertices[SRE] = Vertex(SRE, _needs((), requirement.effects), (), 0.0)
        self.graph: nx.MultiDiGraph[str] = nx.MultiDiGraph()
        self.graph.add_nodes_from(self.vertices)
        self._into: dict[str, dict[str, list[Edge]]] = {iri: {} for iri in self.vertices}
        self._connect()

    def _connect(self) -> None:
        # Index offers by concept (and statements by predicate) so each need is compared only with
        # offers of the same kind, not with every vertex.
        by_concept: dict[str, list[tuple[str, Offer]]] = {}
        statements: list[tuple[str, Offer]] = []
        for vertex in self.vertices.values():
            for offer in vertex.offers:
                if offer.concept is not None:
                    by_concept.setdefault(offer.concept, []).append((vertex.iri, offer))
                else:
                    statements.append((vertex.iri, offer))
        for vertex in self.vertices.values():
            for need in vertex.needs:
                found: list[Edge] = []
                if need.concept is not None:
                    for concept, offers in by_concept.items():
                        result = self.matcher.concept(need.concept, concept)
                        if result is not None:
                            found.extend(self._edge(src, vertex.iri, need, offer, result) for src, offer in offers)
                else:
                    for src, offer in statements:
                        result = self.matcher.match(need, offer)
                        if result is not None:
                            found.append(self._edge(src, vertex.iri, need, offer, result))
                found = [e for e in found if e.source != e.target]
                found.sort(key=lambda e: (-e.similarity, e.source, e.offer.name))
                self._into[vertex.iri][need.key] = found

    def _edge(self, source: str, target: str, need: Need, offer: Offer, result: tuple[Degree, float]) -> Edge:
        edge = Edge(source, target, need, offer, result[0], result[1])
        if source != target:
            self.graph.add_edge(source, target, key=f"{need.key}<-{offer.name}", edge=edge)
        return edge

    def needs(self, iri: str) -> tuple[Need, ...]:
        return self.vertices[iri].needs

    def providers(self, iri: str, need: Need) -> list[Edge]:
        """Edges into ``iri`` that meet ``need``, most similar first."""
        return self._into[iri].get(need.key, [])

    def edges(self) -> list[Edge]:
        return [e for by_need in self._into.values() for edges in by_need.values() for e in edges]

    def cost(self, iri: str) -> float:
        return self.vertices[iri].cost


def _needs(inputs: Sequence[Parameter], preconditions: Sequence[Statement]) -> tuple[Need, ...]:
    needs = [Need("input", name, concept=p.type) for p, name in zip(inputs, _names(inputs), strict=True)]
    needs += [Need("precondition", statement_text(s), statement=s) for s in preconditions]
    return tuple(needs)


def _offers(outputs: Sequence[Parameter], effects: Sequence[Statement]) -> list[Offer]:
    offers = [Offer("output", name, concept=p.type) for p, name in zip(outputs, _names(outputs), strict=True)]
    offers += [Offer("effect", statement_text(s), statement=s) for s in effects]
    return offers


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
