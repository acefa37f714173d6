"""Typed errors of composition and execution. Each keeps the offending input."""

from __future__ import annotations

from collections.abc import Sequence

from cbrs.kb import KnowledgeBaseError
from cbrs.kb.namespaces import shorten
from cbrs.reasoner.names import local_name


class ActionsError(KnowledgeBaseError):
    """Base of the errors composition and execution raise on purpose."""


class UnknownTaskError(ActionsError):
    """The name given as a task is neither a requirement nor an action class in the store."""

    http_status = 404

    def __init__(self, name: str, known: Sequence[str], ambiguous: bool = False) -> None:
        self.name = name
        self.known = tuple(known)
        if ambiguous:  # ``known``: the IRIs the bare name could mean
            super().__init__(f"{name!r} names more than one task; name it by its IRI: {', '.join(known)}")
        else:
            super().__init__(f"no requirement or action named {name!r}; known tasks: {', '.join(known)}")


class OrderingConflictError(ActionsError):
    """An ordering constraint of the action ontology contradicts the data flow a plan needs."""

    http_status = 409

    def __init__(self, constraint: str, before: str, after: str) -> None:
        self.constraint = constraint
        self.before = before
        self.after = after
        super().__init__(
            f"ordering constraint {constraint} puts {before} before {after}, but the plan needs the opposite order"
        )


class UngroundedGoalError(ActionsError):
    """A task's goal is about a class of which nothing in the world is: it can never hold, and a plan
    towards it would move things to another place of a wider class (the object's own)."""

    http_status = 422

    def __init__(self, goal: str, concept: str, elsewhere: Sequence[tuple[str, str]] = ()) -> None:
        self.goal = goal
        self.concept = concept
        self.elsewhere = tuple(elsewhere)
        """(thing, graph): things of the class the store states in graphs the world is not read from."""
        remedy = (
            "add an individual of that class to the semantic map (see docs/tasks.md), or correct the goal"
            if not self.elsewhere
            else "; ".join(f"{shorten(thing)} is one, but in {shorten(graph)}" for thing, graph in self.elsewhere)
            + ", which the world is not read from: load its file with --graph map"
        )
        super().__init__(
            f"the goal {goal} is about a {local_name(concept)} ({concept}), and nothing in the world is one: {remedy}"
        )
