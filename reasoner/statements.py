"""PE matching: the similarity of two RDF statements over subject, predicate and object (equation 8).

Equation 8 is not in the text. A statement says three things, so its similarity is the weighted mean
of the similarities of its three positions, each compared with the entity measure (predicates over
the property hierarchy):

    Sim(R_sup, R_dem) = ws * Sim(s_sup, s_dem) + wp * Sim(p_sup, p_dem) + wo * Sim(o_sup, o_dem)

with ws + wp + wo = 1 (equal by default; see MatchConfig), or the weighted geometric mean. A statement
about the same fact (the other two positions is-a related) whose subject or object is declared disjoint
with the requested one, or named by an antonym of it (antonyms.py), contradicts it and scores 0
(MatchConfig.disjoint_statements, antonym_statements, same_fact_contradictions; Sem-Str only).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from cbrs.kb import Statement
from cbrs.reasoner.antonyms import opposite
from cbrs.reasoner.config import MatchConfig
from cbrs.reasoner.similarity import EntityMeasure, SemStr, Similarity
from cbrs.reasoner.taxonomy import TaxonomyIndex


@dataclass(frozen=True)
class StatementMatch:
    requested: Statement
    advertised: Statement | None
    value: float
    parts: tuple[Similarity, Similarity, Similarity] | None = None
    contradicts: str | None = None  # "subject" or "object": that position contradicts the requested one
    relation: str = "disjoint with"  # how it does: "disjoint with" (declared) or "the opposite of" (antonyms)


def statement_similarity(
    requested: Statement, advertised: Statement, measure: EntityMeasure, config: MatchConfig
) -> StatementMatch:
    s = measure(requested.subject, advertised.subject)
    if isinstance(measure, SemStr):
        p = measure.predicate(requested.predicate, advertised.predicate)
    else:
        p = measure(requested.predicate, advertised.predicate)
    o = measure(requested.object, advertised.object)
    clash = _contradiction(requested, advertised, measure, config)
    if clash is None:
        return StatementMatch(requested, advertised, combine(config, s.value, p.value, o.value), (s, p, o))
    return StatementMatch(requested, advertised, 0.0, (s, p, o), *clash)


def contradiction(
    requested: Statement, advertised: Statement, measure: EntityMeasure, config: MatchConfig
) -> str | None:
    """The position ("subject", "object") where ``advertised`` names a class disjoint with the requested
    one (MatchConfig.disjoint_statements) or its opposite state (MatchConfig.antonym_statements), or
    None (always None for a measure other than Sem-Str)."""
    clash = _contradiction(requested, advertised, measure, config)
    return None if clash is None else clash[0]


def _contradiction(
    requested: Statement, advertised: Statement, measure: EntityMeasure, config: MatchConfig
) -> tuple[str, str] | None:
    """(position, relation) of the first contradiction, or None."""
    if not isinstance(measure, SemStr):
        return None
    index = measure.index
    for position, others in (("subject", ("predicate", "object")), ("object", ("subject", "predicate"))):
        if config.same_fact_contradictions and not all(
            _is_a_related(index, getattr(requested, other), getattr(advertised, other)) for other in others
        ):
            continue  # another fact: its value cannot contradict this one
        relation = _clash(getattr(requested, position), getattr(advertised, position), measure, config)
        if relation is not None:
            return position, relation
    return None


def _clash(wanted: str, got: str, measure: SemStr, config: MatchConfig) -> str | None:
    """How ``got`` contradicts ``wanted`` ("disjoint with", "the opposite of"), or None."""
    if config.disjoint_statements and measure.index.disjoint(wanted, got):
        return "disjoint with"
    if config.antonym_statements and opposite(wanted, got):
        return "the opposite of"
    return None


def undoes(held: Statement, effect: Statement, measure: EntityMeasure, config: MatchConfig) -> bool:
    """Does ``effect`` make the guaranteed statement ``held`` false: the same fact (is-a related subjects
    and predicates) with a contradicting object (MatchConfig.undone_state_factor; Sem-Str only)? A
    statement about another thing (the red lamp's state for the green lamp's) undoes nothing."""
    if not isinstance(measure, SemStr):
        return False
    index = measure.index
    same_fact = _is_a_related(index, held.subject, effect.subject) and _is_a_related(
        index, held.predicate, effect.predicate
    )
    return same_fact and _clash(held.object, effect.object, measure, config) is not None


def contradiction_factor(
    requested: tuple[Statement, ...], advertised: tuple[Statement, ...], measure: EntityMeasure, config: MatchConfig
) -> float:
    """MatchConfig.contradiction_factor when an advertised effect contradicts a requested one, else 1."""
    if config.contradiction_factor >= 1:
        return 1.0
    clash = any(contradiction(wanted, got, measure, config) for wanted in requested for got in advertised)
    return config.contradiction_factor if clash else 1.0


def reported(index: TaxonomyIndex, config: MatchConfig, output: str, effect: Statement) -> tuple[str, ...]:
    """The terms of a requested ``effect`` that an advertised ``output`` reports, for a service that changes
    nothing (MatchConfig.observed_state_weight, observed_state_kind)."""
    if config.observed_state_kind:
        above = output in index and effect.object in index
        links = index.is_a_ancestors(effect.object).get(index.canonical(output)) if above else None
        return (effect.object,) if links else ()  # 0 links: the object itself
    return tuple(term for term in (effect.object, effect.subject) if _is_a_related(index, output, term))


def _is_a_related(index: TaxonomyIndex, first: str, second: str) -> bool:
    """The same concept, or one a subclass of the other (is-a links)."""
    if first == second:
        return True
    if first not in index or second not in index:
        return False
    return index.canonical(first) in index.is_a_ancestors(second) or index.canonical(second) in index.is_a_ancestors(
        first
    )


def combine(config: MatchConfig, s: float, p: float, o: float) -> float:
    """The statement's similarity from its three positions' (MatchConfig.statement_mean)."""
    if (
        config.statement_mean == "geometric"
        and config.subject_weight == config.predicate_weight == config.object_weight
    ):
        return math.cbrt(s * p * o)  # as batch.py computes it
    if config.statement_mean == "geometric":
        return float(s**config.subject_weight * p**config.predicate_weight * o**config.object_weight)
    return config.subject_weight * s + config.predicate_weight * p + config.object_weight * o


def best_statement_matches(
    wanted: tuple[Statement, ...], offered: tuple[Statement, ...], measure: EntityMeasure, config: MatchConfig
) -> list[StatementMatch]:
    """For each wanted statement, its most similar offered statement (or none, with value 0)."""
    matches = []
    for statement in wanted:
        options = [statement_similarity(statement, other, measure, config) for other in offered]
        matches.append(max(options, key=lambda m: m.value) if options else StatementMatch(statement, None, 0.0))
    return matches
