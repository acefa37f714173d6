"""Which thing a world fact is about, and which things a requirement names: a fact about one thing meets a
statement (a component's precondition, a goal) only for the requirement whose thing that statement concerns.

Composition is between classes. The world state is lifted (the cup in the left hand is (Cup, isGraspedBy,
Gripper)) and a component states its precondition over classes (the carry's (PhysicalObject, isGraspedBy,
Gripper)), so the cup held met the pen's carry's precondition and a re-plan carried the pen without taking it.
When a step runs, its precondition is about the things the step handles, and a step handles the things its
requirement (the task, or the part of it the step was planned for) names by its inputs, for its goals. So a
side of a wanted statement, its subject or its object, is *bound* to the things the requirement's goals are
about that are of a class at or below that side's class (the pen is a PhysicalObject: the carry's subject
is the pen), else to every named thing of such a class (a tool no goal is about); a fact meets the
statement only when, on each bound side, the fact's thing is one of those. A side no named thing falls
under (the robot's hand, a room, a quality such as Water) is not bound, and any thing's fact meets it, as
before. The cup held is the goal of the cup's part and meets its own carry; it does not meet the carry of a
part whose goal is the pen's, even one given the cup too (a goal of the task planned on its own is given
the inputs no goal is about). A statement with no thing behind it (taken as holding, not read from the
world) meets as its classes do.

An input designates what a run's input of that class would (``kb.semantic_map.designate``: the one thing of
the class, else the one the requester owns or stated directly of it); when several remain, every one of them
counts as named: which the run takes is not known when planning. Why and what it changed:
docs/composition.md, "A fact about one thing".
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field

from pyoxigraph import NamedNode

from cbrs.kb import KnowledgeBase, Requirement, Statement
from cbrs.kb.errors import KnowledgeBaseError
from cbrs.kb.semantic_map import designate
from cbrs.reasoner.taxonomy import TaxonomyIndex

__all__ = ["AchievedGoal", "Designations", "NamedThings", "WorldFact"]


@dataclass(frozen=True)
class WorldFact:
    """A relation that holds between two things of the world (``object``: a class, for a quality such as
    home:Water), with ``statement``, the same lifted to their classes."""

    statement: Statement
    subject: str
    object: str


@dataclass(frozen=True)
class AchievedGoal:
    """A goal an earlier part of the plan achieves (a sub-action before), about the things that part's
    requirement names on each side of it (:meth:`NamedThings.bound`; none: a side about no named thing)."""

    statement: Statement
    subjects: frozenset[str]
    objects: frozenset[str]


@dataclass
class NamedThings:
    """The things a requirement's inputs designate, each with its classes (at or below the input's), and
    ``aims``: those of them its goals are about (an input's class at or below a goal's subject or object)."""

    index: TaxonomyIndex
    things: Mapping[str, frozenset[str]]
    aims: frozenset[str] = frozenset()
    _bound: dict[str, frozenset[str]] = field(default_factory=dict)

    def bound(self, side: str) -> frozenset[str]:
        """The named things a statement's side of class ``side`` concerns: those of the goals' things of that
        class or below, else those of every named thing; none, for a side that is about no named thing."""
        if side not in self._bound:
            under = frozenset(
                thing for thing, concepts in self.things.items() if any(self.index.is_a(c, side) for c in concepts)
            )
            self._bound[side] = (under & self.aims) or under
        return self._bound[side]

    def meets(self, wanted: Statement, fact: WorldFact) -> bool:
        """Whether ``fact`` is about the things ``wanted`` concerns here: on each side bound to named things,
        the fact's thing is one of them (the classes are matched elsewhere)."""
        return all(
            not (bound := self.bound(side)) or thing in bound
            for thing, side in ((fact.subject, wanted.subject), (fact.object, wanted.object))
        )

    def meets_achieved(self, wanted: Statement, goal: AchievedGoal) -> bool:
        """Whether ``goal``, achieved by an earlier part, is about the things ``wanted`` concerns here: on each
        side where both name things, they share one (the cup the part before keeps in a hand is not the pen
        this part sets down)."""
        return all(
            not (bound := self.bound(side)) or not things or bool(bound & things)
            for things, side in ((goal.subjects, wanted.subject), (goal.objects, wanted.object))
        )

    def admits(self, wanted: Statement, facts: Iterable[WorldFact]) -> bool:
        """Whether a statement lifted from ``facts`` meets ``wanted`` for this requirement: one of the facts
        is about its things; with no fact behind it (assumed, not read from the world), it does."""
        found = list(facts)
        return not found or any(self.meets(wanted, fact) for fact in found)


class Designations:
    """The things each input class designates, by the ``designate`` query, read once per class for all the
    requirements of one composition."""

    def __init__(self, kb: KnowledgeBase, index: TaxonomyIndex) -> None:
        self.kb, self.index = kb, index
        self._of: dict[str, dict[str, set[str]]] = {}  # class -> each of its things -> the thing's classes
        self._chosen: dict[tuple[str, str | None], list[str]] = {}

    def named(self, requirement: Requirement) -> NamedThings:
        """The things ``requirement``'s inputs designate."""
        asked = sorted({p.type for p in requirement.inputs if p.type and p.type not in self._of})
        if asked:
            kb = self.kb
            rows = kb.queries.select_each(kb.store, [("designate", {"class": NamedNode(c)}) for c in asked])
            for concept, found in zip(asked, rows, strict=True):
                things: dict[str, set[str]] = {}
                for row in found:
                    things.setdefault(row["thing"].value, set()).add(row["type"].value)
                self._of[concept] = things
        named: dict[str, set[str]] = {}
        aims: set[str] = set()
        goals = (*requirement.effects, *requirement.deletes)
        for parameter in requirement.inputs:
            if parameter.type:
                candidates = self._of[parameter.type]
                chosen = self._choose(parameter.type, requirement.requested_by, candidates)
                for thing in chosen:
                    named.setdefault(thing, set()).update(candidates[thing], (parameter.type,))
                if any(self.index.is_a(parameter.type, side) for g in goals for side in (g.subject, g.object)):
                    aims.update(chosen)
        classes = {thing: frozenset(concepts) for thing, concepts in named.items()}
        return NamedThings(self.index, classes, frozenset(aims))

    def _choose(self, concept: str, prefer: str | None, candidates: Mapping[str, set[str]]) -> list[str]:
        """The one of ``candidates`` a run's input would take, else all of them (the run's choice)."""
        if len(candidates) <= 1:
            return sorted(candidates)
        key = (concept, prefer)
        if key not in self._chosen:
            try:
                self._chosen[key] = [designate(self.kb, concept, prefer=prefer)]
            except KnowledgeBaseError:
                self._chosen[key] = sorted(candidates)
        return self._chosen[key]
