"""A task's own preconditions, asked of the world once a run has perceived it, before the first step.

Composition takes a requirement's preconditions as given (SRI offers them, docs/composition.md): the
requester guarantees them, and no step is planned to make them hold. A run whose guarantee is false
would act on it anyway (DeliverFromTheBase drove to the person with nothing on the platform, then
re-planned the same), so ``run_task`` asks the environment's tests whether each holds and refuses the
task, before anything moves, when one is believed false (:class:`TaskPreconditionError`). One no test
can decide stays taken as given, and the run's result says so (:class:`PreconditionCheck`). One on a
status the store defines by a measured quantity (a room dark below 50 lx) is asked of a sensor instead
(``sense``, :mod:`actions.precondition_sensing`): a reading decides it, and where no sensor can, the run
says why it is taken as given. Why a false precondition is refused rather than planned for:
docs/execution.md, "A task's preconditions".
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import Any

from cbrs.actions.belief import Observation
from cbrs.actions.errors import ActionsError
from cbrs.actions.graph import statement_text
from cbrs.actions.precondition_sensing import Sensed
from cbrs.kb import Requirement, Statement
from cbrs.kb.namespaces import shorten

__all__ = ["PreconditionCheck", "TaskPreconditionError", "check_preconditions"]

IsA = Callable[[str, str], bool]
Sense = Callable[[Statement], Sensed | None]
"""A question to the store's sensors about a precondition (None: not one a reading decides)."""


class TaskPreconditionError(ActionsError):
    """A precondition of the task's own requirement is believed false when the run starts: the task takes
    it as given, so no plan would make it hold. Keeps the requirement, the statement and what the run
    believes instead (facts ``(subject, relation, object)`` of the statement's relation about things of
    its subject's class), or, for one a sensor decided, what it read (``sensed``)."""

    http_status = 409

    def __init__(
        self,
        requirement: str,
        statement: Statement,
        instead: Iterable[tuple[str, str, str]],
        sensed: Sensed | None = None,
    ) -> None:
        self.requirement = requirement
        self.statement = statement
        self.instead = tuple(instead)
        self.sensed = sensed
        if sensed is not None and sensed.stated:
            super().__init__(
                f"the task's precondition {statement_text(statement)} of {shorten(requirement)} does not hold:"
                f" the map states {sensed.reading} ({shorten(sensed.sensor)}), and {shorten(statement.object)}"
                f" holds {sensed.bound} ({sensed.rule}). A task takes its preconditions as given and plans"
                " nothing to make them hold: where the thing has changed, correct the map (cbrs update), or"
                " leave the precondition out of the requirement"
            )
            return
        if sensed is not None:
            super().__init__(
                f"the task's precondition {statement_text(statement)} of {shorten(requirement)} does not hold:"
                f" {sensed.device} ({shorten(sensed.sensor)}) reads {sensed.reading} in {shorten(statement.subject)},"
                f" and {shorten(statement.object)} holds {sensed.bound} (its home:holdsWhen). A task takes its"
                " preconditions as given and plans nothing to make them hold: start it once the reading says it"
                " holds (each run reads it again), or leave the precondition out of the requirement"
            )
            return
        if self.instead:
            believed = "the run believes " + "; ".join(
                " ".join(shorten(term) for term in fact) for fact in self.instead
            )
        else:
            believed = f"the run believes nothing of a {shorten(statement.subject)} by {shorten(statement.predicate)}"
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
    True where the robots perceive it holding or a sensor read it so (``sensed``: ``12 lx by
    SensorBoard01``; ``stated``: the map's statement decided it), None where nothing could check it (taken
    as given; ``why``, where sensing was tried: why no sensor decided it)."""

    statement: Statement
    believed: bool | None
    sensed: str = ""
    why: str = ""
    stated: bool = False  # ``sensed`` is what the map states, not a reading

    def to_dict(self) -> dict[str, Any]:
        found: dict[str, Any] = {"statement": statement_text(self.statement), "believed": self.believed}
        if self.sensed:
            found["sensed"] = self.sensed
        if self.stated:
            found["stated"] = True
        if self.why:
            found["why"] = self.why
        return found


def check_preconditions(
    environment: object, requirement: Requirement, seen: Observation, is_a: IsA, sense: Sense | None = None
) -> tuple[PreconditionCheck, ...]:
    """Each precondition of ``requirement`` as the environment's tests decide it now (the Environment
    protocol's optional ``holds``, a question that believes nothing; without it, none is checked), and one
    no test decides as ``sense`` reads it where it can; raise :class:`TaskPreconditionError` for the first
    believed false, with the facts of ``seen`` (the run's first perception) that stand in its place, or
    the reading that decided it."""
    holds = getattr(environment, "holds", None)
    checks = []
    for statement in requirement.preconditions:
        found = holds(statement) if callable(holds) else None
        if found is not None and not found:
            raise TaskPreconditionError(requirement.iri, statement, _instead(statement, seen, is_a))
        sensed = sense(statement) if found is None and sense is not None else None
        if sensed is None:
            checks.append(PreconditionCheck(statement, None if found is None else True))
        elif sensed.holds is None:
            checks.append(PreconditionCheck(statement, None, why=sensed.how))
        elif sensed.holds:
            checks.append(PreconditionCheck(statement, True, sensed=sensed.how, stated=sensed.stated))
        else:
            raise TaskPreconditionError(requirement.iri, statement, (), sensed)
    return tuple(checks)


def _instead(statement: Statement, seen: Observation, is_a: IsA) -> list[tuple[str, str, str]]:
    """What ``seen`` holds of things of the statement's subject class by its relation (or one below it)."""
    return sorted(
        fact
        for fact in seen.facts
        if is_a(fact[1], statement.predicate) and fact[0] in seen.types and is_a(seen.types[fact[0]], statement.subject)
    )
