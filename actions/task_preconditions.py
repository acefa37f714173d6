"""A task's own preconditions, asked of the world once a run has perceived it, before the first step.

Composition takes a requirement's preconditions as given (SRI offers them, docs/composition.md): the
requester guarantees them, and no step is planned to make them hold. A run whose guarantee is false
would act on it anyway (DeliverFromTheBase drove to the person with nothing on the platform, then
re-planned the same), so ``run_task`` asks the environment's tests whether each holds and refuses the
task, before anything moves, when one is believed false (:class:`TaskPreconditionError`). One no test
can decide stays taken as given, and the run's result says so (:class:`PreconditionCheck`). Why a
false precondition is refused rather than planned for: docs/execution.md, "A task's preconditions".
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import Any

from cbrs.actions.belief import Observation
from cbrs.actions.errors import ActionsError
from cbrs.actions.graph import statement_text
from cbrs.kb import Requirement, Statement
from cbrs.kb.namespaces import shorten

__all__ = ["PreconditionCheck", "TaskPreconditionError", "check_preconditions"]

IsA = Callable[[str, str], bool]


class TaskPreconditionError(ActionsError):
    """A precondition of the task's own requirement is believed false when the run starts: the task takes
    it as given, so no plan would make it hold. Keeps the requirement, the statement and what the run
    believes instead (facts ``(subject, relation, object)`` of the statement's relation about things of
    its subject's class)."""

    http_status = 409

    def __init__(self, requirement: str, statement: Statement, instead: Iterable[tuple[str, str, str]]) -> None:
        self.requirement = requirement
        self.statement = statement
        self.instead = tuple(instead)
        believed = (
            "the run believes " + "; ".join(" ".join(shorten(term) for term in fact) for fact in self.instead)
            if self.instead
            else f"the run believes nothing of a {shorten(statement.subject)} by {shorten(statement.predicate)}"
        )
        super().__init__(
            f"the task's precondition {statement_text(statement)} of {shorten(requirement)} does not hold: {believed}."
            " A task takes its preconditions as given and plans nothing to make them hold: run the task that"
            " achieves it in the same run (an action class with both as sub-actions, the achieving one first,"
            " as docs/examples/lab7_load_then_deliver.ttl), or leave the precondition out of the requirement so"
            " that the plan achieves it"
        )


@dataclass(frozen=True)
class PreconditionCheck:
    """One precondition of the task's requirement as the run found it before its first step: ``believed``
    True where the robots perceive it holding, None where nothing could check it (taken as given)."""

    statement: Statement
    believed: bool | None

    def to_dict(self) -> dict[str, Any]:
        return {"statement": statement_text(self.statement), "believed": self.believed}


def check_preconditions(
    environment: object, requirement: Requirement, seen: Observation, is_a: IsA
) -> tuple[PreconditionCheck, ...]:
    """Each precondition of ``requirement`` as the environment's tests decide it now (the Environment
    protocol's optional ``holds``, a question that believes nothing; without it, none is checked); raise
    :class:`TaskPreconditionError` for the first believed false, with the facts of ``seen`` (the run's
    first perception) that stand in its place."""
    holds = getattr(environment, "holds", None)
    checks = []
    for statement in requirement.preconditions:
        found = holds(statement) if callable(holds) else None
        if found is not None and not found:
            raise TaskPreconditionError(requirement.iri, statement, _instead(statement, seen, is_a))
        checks.append(PreconditionCheck(statement, None if found is None else True))
    return tuple(checks)


def _instead(statement: Statement, seen: Observation, is_a: IsA) -> list[tuple[str, str, str]]:
    """What ``seen`` holds of things of the statement's subject class by its relation (or one below it)."""
    return sorted(
        fact
        for fact in seen.facts
        if is_a(fact[1], statement.predicate) and fact[0] in seen.types and is_a(seen.types[fact[0]], statement.subject)
    )
