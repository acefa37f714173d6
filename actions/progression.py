"""A plan checked by progression: its steps' add and delete effects applied in order from the state it
starts in, every precondition and every goal must hold when it is needed.

The statements are between classes, as composition's are. A precondition or a goal holds when a fact of
the state meets it as an effect would (``Matcher.statement``: the degrees composition accepts); a delete
effect removes every fact it may falsify (the same relation between things of which one is a kind of the
other on both ends, the rule the extraction orders threats by). A step's deletes apply before its adds,
as in STRIPS, so a step that deletes and adds the same statement leaves it true.

Composition checks each plan it extracts this way (``actions.extraction``): a statement that held at the
start, or that a step made, and that a later step deletes before it is needed, is achieved again or the
plan is refused naming it (docs/composition.md, "A statement a later step undoes"). A plan joined from
parts (a decomposed task's sub-actions, a requirement's goals one by one) is checked as it will run, part
after part from the state the previous one left, each part's goals when that part ends
(:func:`progress_parts`; ``actions.composer``).
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass

from cbrs.actions.graph import Matcher, statement_text
from cbrs.actions.plan import Plan
from cbrs.kb import Statement
from cbrs.reasoner.taxonomy import TaxonomyIndex


@dataclass(frozen=True)
class Clobbered:
    """A statement needed when it no longer holds: a precondition of step ``consumer`` (None: a goal of the
    plan, needed at its end), deleted by step ``deleter`` (None: no step deleted it; it never held)."""

    statement: Statement
    consumer: int | None
    deleter: int | None
    part: int = 0  # the part of a joined plan that needs it, counted from 0 (progress_parts)

    def text(self, plan: Plan) -> str:
        need = f"goal {statement_text(self.statement)}"
        if self.consumer is not None:
            need = f"precondition {statement_text(self.statement)} of step {self.consumer}"
            need += f" ({plan.step(self.consumer).component})"
        if self.deleter is None:
            return f"the {need} does not hold when it is needed"
        deleter = plan.step(self.deleter).component
        return f"the {need} was deleted by step {self.deleter} ({deleter}) and not achieved again"


def threatens(index: TaxonomyIndex, deleted: Statement, needed: Statement) -> bool:
    """Whether deleting ``deleted`` may falsify ``needed``: the same relation, between things of which
    one is a kind of the other on both ends."""
    if deleted.predicate != needed.predicate:
        return False
    return all(
        index.is_a(a, b) or index.is_a(b, a)
        for a, b in ((deleted.subject, needed.subject), (deleted.object, needed.object))
    )


def progress(plan: Plan, initial: Iterable[Statement], matcher: Matcher) -> list[Clobbered]:
    """Every precondition and goal of ``plan`` that does not hold when it is needed, in plan order, with
    the step that deleted it; ``initial``: what holds when the plan starts (the requirement's
    preconditions and the world state composition offered)."""
    return progress_parts((plan,), initial, matcher)


def progress_parts(parts: Sequence[Plan], initial: Iterable[Statement], matcher: Matcher) -> list[Clobbered]:
    """:func:`progress` over the plans of ``parts`` run one after the other, as the plan joined from them
    (``actions.composer``): steps numbered as in the joined plan, each part's goals needed when that part
    ends (a sub-action's goal, such as being near the table, is for the sub-actions after it, not for the
    end of the whole task), each found statement with the part that needs it."""
    state: list[Statement] = list(dict.fromkeys(initial))
    deleted_by: dict[Statement, int] = {}  # fact -> the step that deleted it last
    found: list[Clobbered] = []
    offset = 0
    for part, plan in enumerate(parts):
        for step in plan.steps:
            index = step.index + offset
            for binding in step.preconditions:
                if binding.statement is not None and not _holds(binding.statement, state, matcher):
                    found.append(_clobbered(binding.statement, index, deleted_by, matcher, part))
            removed = [f for f in state if any(threatens(matcher.index, d, f) for d in step.deletes)]
            for fact in removed:
                deleted_by[fact] = index
            state = [f for f in state if f not in removed]
            state += [e for e in step.effects if e not in state]
        for goal in plan.goals:
            if goal.role == "deletion":  # a delete effect wanted: its step is planned; the run checks it
                continue
            if goal.statement is not None and not _holds(goal.statement, state, matcher):
                found.append(_clobbered(goal.statement, None, deleted_by, matcher, part))
        offset += len(plan.steps)
    return found


def consumed_goals(parts: Sequence[Plan], initial: Iterable[Statement], matcher: Matcher) -> list[bool]:
    """For each goal of ``parts`` in order, whether it is a goal of a part before the last that no longer
    holds when the joined plan ends: a sub-action's goal that a later sub-action deletes (the pen on the
    base's platform, delivered from it to the person) was a means to the sub-actions after it, checked
    when its part ended (:func:`progress_parts`), not an end of the whole task for the run to check."""
    state: list[Statement] = list(dict.fromkeys(initial))
    for plan in parts:
        for step in plan.steps:
            state = [f for f in state if not any(threatens(matcher.index, d, f) for d in step.deletes)]
            state += [e for e in step.effects if e not in state]
    last = len(parts) - 1
    return [
        n < last and g.role != "deletion" and g.statement is not None and not _holds(g.statement, state, matcher)
        for n, plan in enumerate(parts)
        for g in plan.goals
    ]


def _holds(needed: Statement, state: Sequence[Statement], matcher: Matcher) -> bool:
    return any(matcher.statement(needed, fact) is not None for fact in state)


def _clobbered(
    needed: Statement, consumer: int | None, deleted_by: dict[Statement, int], matcher: Matcher, part: int
) -> Clobbered:
    """The latest step that deleted a fact which would have met ``needed``."""
    deleters = [step for fact, step in deleted_by.items() if matcher.statement(needed, fact) is not None]
    return Clobbered(needed, consumer, max(deleters) if deleters else None, part)


__all__ = ["Clobbered", "consumed_goals", "progress", "progress_parts", "threatens"]
