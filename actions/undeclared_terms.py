"""What a term of a task that the ontology has no class for is, and what to declare it under.

Composition names the classes of a requirement the ontology lacks (:class:`cbrs.actions.unmet.Unsatisfied`,
``undeclared``). Two readings of such a term lead to different fixes:

- a thing of the semantic map (``lab4:Trolley1``, an individual of ``lab4:Trolley``): a goal and an input
  name classes, and a run finds the things of the map that are of them, so the fix is to name its class;
- a new class: the fix is to declare it under a class the components know. Which one depends on where
  the task uses it: the class the components' conditions have at the same side of the same property (the
  object of ``home:isLocated`` is a ``home:Place`` in the put-down's effect), else of a super- or
  sub-property of it. The most general of those is suggested, so that each of them fits below it; among
  classes none of which is above the others, the one the most of those conditions are at or below, then
  the first by IRI. The
  ontology declares no ranges for its spatial properties (``home:isLocated``), so the components' own
  conditions are the range as composition will use it. A term that is only the type of an input gets no
  class suggested: an input's class says what the thing is, which only the user knows.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Iterable, Sequence
from dataclasses import replace

from cbrs.actions.unmet import Unsatisfied
from cbrs.kb import Advertisement, KnowledgeBase, Requirement, Statement
from cbrs.reasoner.taxonomy import TaxonomyIndex

__all__ = ["described", "individual_classes", "suggested_superclass"]


def described(
    unsatisfied: Unsatisfied,
    requirement: Requirement,
    index: TaxonomyIndex,
    kb: KnowledgeBase,
    advertisements: Sequence[Advertisement],
) -> Unsatisfied:
    """``unsatisfied`` with each of its undeclared terms said to be a thing of the map (with its classes)
    or given the superclass its use in ``requirement`` suggests."""
    individuals = []
    superclasses = []
    for term in unsatisfied.undeclared:
        classes = individual_classes(kb, term, index)
        if classes:
            individuals.append((term, classes))
            continue
        found = suggested_superclass(term, requirement, index, advertisements)
        if found is not None:
            superclasses.append((term, found))
    return replace(unsatisfied, individuals=tuple(individuals), superclasses=tuple(superclasses))


def individual_classes(kb: KnowledgeBase, term: str, index: TaxonomyIndex) -> tuple[str, ...]:
    """The classes of the ontology ``term`` is stated to be of, when it is a thing of the semantic map."""
    rows = kb.select("map_types", {"thing": term})
    return tuple(sorted({row["type"].value for row in rows if "type" in row and row["type"].value in index}))


def suggested_superclass(
    term: str, requirement: Requirement, index: TaxonomyIndex, advertisements: Iterable[Advertisement]
) -> str | None:
    """The class to declare ``term`` under, from the first statement of ``requirement`` that names it (its
    goals first): the most general class the components' conditions have at the same side of the same
    property, else of a related one (module docstring). None: no statement names it, or no condition fits."""
    conditions = [
        c for ad in advertisements for c in (*ad.effects, *ad.preconditions, *ad.deletes) if c.predicate in index
    ]
    for statement in (*requirement.effects, *requirement.preconditions, *requirement.deletes):
        sides = [
            side for side, named in (("subject", statement.subject), ("object", statement.object)) if named == term
        ]
        for side in sides:
            found = _most_general(_at_side(statement.predicate, side, conditions, index), index)
            if found is not None:
                return found
    return None


def _at_side(predicate: str, side: str, conditions: Sequence[Statement], index: TaxonomyIndex) -> list[str]:
    """The classes at ``side`` of the conditions about ``predicate``; when none is, of its super- and
    sub-properties."""
    same = [getattr(c, side) for c in conditions if c.predicate == predicate]
    if same or predicate not in index:
        return [c for c in same if c in index]
    related = [
        getattr(c, side) for c in conditions if index.is_a(c.predicate, predicate) or index.is_a(predicate, c.predicate)
    ]
    return [c for c in related if c in index]


def _most_general(classes: Sequence[str], index: TaxonomyIndex) -> str | None:
    """The class of ``classes`` none of the others is above; of several, the one the most of ``classes`` are
    at or below, then the first by IRI."""
    counted = Counter(classes)
    top = [c for c in counted if not any(index.is_a(c, other) and not index.is_a(other, c) for other in counted)]
    if not top:
        return None
    covered = {c: sum(n for other, n in counted.items() if index.is_a(other, c)) for c in top}
    return min(top, key=lambda c: (-covered[c], c))
