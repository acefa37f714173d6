"""Conceptual span similarity (CSS) between a Requirement Tree and an Advertisement Tree.

The paper's equations 6 and 7 are not in the text; docs/matchmaking.md gives the reasoning for this
definition. A tree's root is the parameter's concept, its other nodes the concept's parts. Roots are
compared with roots and parts with parts. Each requirement node n spans the leaves below it (a leaf
spans itself) and has its own similarity own(n), the best Sim of n against the eligible nodes of the
advertisement tree. A node is covered either by its own match or by its parts:

    cover(n) = own(n)                                                     n a leaf
    cover(n) = max(own(n), (own(n) + sum_c w(c) span(c) cover(c)) / (1 + sum_c w(c) span(c)))   otherwise
    CSS(RT, AT) = cover(root of RT)

so when the roots match at least as well as their parts do, CSS = Sim(roots), the paper's special
case; when they do not (Position against Location: siblings, but with the same x, y, theta parts), the
parts' evidence lifts the score, and the root's own similarity still weighs in. Parts of the root that
both concepts inherit from their common superclass (``implied``) are left out of the sum: the taxonomy
has already counted them. A part's weight w(c) says how specific it is in the loaded ontology: a part
that nearly every whole has (a timestamp) is weak evidence that two concepts are alike. Pairs reaching
the pair threshold are reported as matched; requirement leaves below it are what the advertisement
lacks.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from cbrs.kb import PartNode
from cbrs.reasoner.similarity import EntityMeasure, Similarity


@dataclass(frozen=True)
class PairMatch:
    requested: str
    advertised: str
    similarity: Similarity
    span: int  # requirement leaves this pair covers


@dataclass(frozen=True)
class SpanMatch:
    value: float
    pairs: tuple[PairMatch, ...]
    uncovered: tuple[str, ...]  # requirement leaves no matched pair covers


def span(node: PartNode) -> int:
    """Leaves at or below ``node``."""
    return 1 if node.is_leaf else sum(span(child) for child in node.children)


def conceptual_span_similarity(
    requested: PartNode,
    advertised: PartNode,
    measure: EntityMeasure,
    threshold: float,
    use_parts: bool = True,
    implied: frozenset[str] = frozenset(),
    weight: Callable[[str], float] = lambda _: 1.0,
    inherited: bool = False,
    value: Callable[[str, str], float] | None = None,
) -> SpanMatch:
    """CSS of two trees; with ``use_parts`` false only the roots are compared (flat matching).
    ``implied``: parts of the roots' common superclass, which do not count as evidence, unless
    ``inherited``: the advertised root is a subclass of the requested one, so it has every implied part
    (they count as covered, similarity 1); ``weight``: how much a matched part of a given concept
    counts (TaxonomyIndex.part_weight); ``value``: the measure's value alone, when it is cheaper to have
    (a cached vector), so that the full Similarity is built only for each node's best partner."""
    parts = [node for node in advertised.walk() if node is not advertised] if use_parts else []
    pairs: list[PairMatch] = []
    uncovered: list[str] = []

    def own(node: PartNode, candidates: list[PartNode]) -> tuple[Similarity | None, str | None]:
        if not candidates:
            return None, None
        if value is not None and len(candidates) > 1:  # values first; the reasons of the best only
            values = [value(node.concept, other.concept) for other in candidates]
            partner = candidates[values.index(max(values))].concept
            return measure(node.concept, partner), partner
        best, partner = max(
            ((measure(node.concept, other.concept), other.concept) for other in candidates),
            key=lambda pair: pair[0].value,
        )
        return best, partner

    def cover(node: PartNode, candidates: list[PartNode]) -> float:
        best, partner = own(node, candidates)
        value = best.value if best else 0.0
        if node.is_leaf or not use_parts:
            if best is not None and partner is not None and value >= threshold:
                pairs.append(PairMatch(node.concept, partner, best, span(node) if use_parts else 1))
            else:
                uncovered.append(node.concept)
            return value
        mark = len(pairs), len(uncovered)
        at_root = node is requested
        counted = [c for c in node.children if not (at_root and c.concept in implied and not inherited)]
        weights = [weight(c.concept) * span(c) for c in counted]
        by_parts = (
            value
            + sum(
                w * (inherit(c) if at_root and c.concept in implied else cover(c, parts))
                for w, c in zip(weights, counted, strict=True)
            )
        ) / (1 + sum(weights))
        if value >= by_parts:
            del pairs[mark[0] :], uncovered[mark[1] :]  # the node's own match covers its span
            if best is not None and partner is not None and value >= threshold:
                pairs.append(PairMatch(node.concept, partner, best, span(node)))
            else:
                uncovered.append(node.concept)
            return value
        if best is not None and partner is not None and value >= threshold:
            pairs.append(PairMatch(node.concept, partner, best, 0))  # reported, its parts carry the span
        return by_parts

    def inherit(node: PartNode) -> float:
        pairs.append(PairMatch(node.concept, node.concept, Similarity(1.0, "inherited"), span(node)))
        return 1.0

    result = cover(requested, [advertised])
    return SpanMatch(result, tuple(pairs), tuple(uncovered))
