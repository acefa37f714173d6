"""What of a task's written decomposition composition cannot follow, said to its author.

A task that names an action class with sub-actions (``cbrs:forTask``) is planned part by part, in the order
of its ordering constraints, only when every sub-action is stated as a requirement of its own
(``actions.composer``); else it is planned whole, or goal by goal, and its order is not the author's. A
sub-action naming no declared action class (a misspelt ``owl:someValuesFrom``), an ordering constraint that
says nothing of what comes before what, or orders a class that is no sub-action of its own, or orders them in
a cycle, were each passed over without a word: the plan came out in another order than written (the fifteenth
round's cup before its saucer), and nothing said why. These notes say it, as ``cbrs plan`` prints them. An
ordering constraint no plan can follow is a reason of no plan (:class:`UnfollowedOrdering`), not a note.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

import networkx as nx

from cbrs.actions.errors import OrderingConflictError
from cbrs.actions.model import ActionClass, ActionLibrary, Ordering
from cbrs.actions.unmet import Unsatisfied
from cbrs.kb.namespaces import shorten
from cbrs.kb.shapes import nearest_term


def decomposition_notes(action: ActionClass | None, library: ActionLibrary, stated: Iterable[str]) -> tuple[str, ...]:
    """Notes on ``action``'s decomposition and its sub-actions', down the levels composition would follow;
    ``stated``: the action classes a requirement names by ``cbrs:forTask``. None when there is nothing to say."""
    if action is None:
        return ()
    tasks = set(stated)
    notes: list[str] = []
    seen: set[str] = set()
    pending = [action]
    while pending:
        current = pending.pop(0)
        if current.iri in seen or not current.sub_actions:
            continue
        seen.add(current.iri)
        notes += _orderings(current)
        notes += _unstated(current, library, tasks)
        pending += [library.actions[s] for s in current.sub_actions if s in library and s in tasks]
    return tuple(notes)


def _unstated(action: ActionClass, library: ActionLibrary, tasks: set[str]) -> list[str]:
    """A note of the sub-actions no requirement states, which keep ``action`` from being planned by its parts,
    when the author meant it to be: another of them is stated, or one names no declared action class. None
    stated of declared classes is the action ontology's own way (act:FetchMyPen's steps are found by their
    preconditions and effects, its sub-actions the reference they are checked against), and says nothing."""
    missing = [s for s in action.sub_actions if s not in tasks]
    if not missing or (len(missing) == len(action.sub_actions) and all(s in library for s in missing)):
        return []
    named = []
    for sub in missing:
        if sub in library:
            named.append(f"{shorten(sub)} (no cbrs:Requirement names it by cbrs:forTask)")
            continue
        near = nearest_term(sub, (a.iri for a in library), 0.6)
        guess = f"; did you mean {shorten(near)}?" if near else ""
        named.append(f"{shorten(sub)} (no action class the store declares{guess})")
    return [
        f"{shorten(action.iri)} is not planned by its sub-actions, nor in their order: its sub-action"
        f" {', '.join(named)} is stated as no requirement of its own; state each sub-action as a requirement"
        " (cbrs:forTask) with the inputs it is given and its effects (docs/composition.md, 'Decomposition')"
    ]


def _orderings(action: ActionClass) -> list[str]:
    """Notes of ``action``'s ordering constraints that order nothing among its sub-actions."""
    notes = [
        f"the ordering constraint {shorten(c)} of {shorten(action.iri)} says nothing of what comes first"
        " (no act:occursBefore and act:occursAfter): it is not followed; is its name misspelt?"
        for c in action.dangling
    ]
    subs = set(action.sub_actions)
    for o in action.orderings:
        outside = [c for c in (o.before, o.after) if c not in subs]
        if outside:
            notes.append(
                f"the ordering constraint {shorten(o.constraint)} of {shorten(action.iri)} orders"
                f" {', '.join(map(shorten, outside))}, no sub-action of it (act:subAction): it is not followed"
            )
    graph: nx.DiGraph[str] = nx.DiGraph()
    graph.add_edges_from((o.before, o.after) for o in action.orderings if o.before in subs and o.after in subs)
    if not nx.is_directed_acyclic_graph(graph):
        notes.append(
            f"the ordering constraints of {shorten(action.iri)} order its sub-actions in a cycle: none is"
            " followed, the sub-actions go in the order of their IRIs"
        )
    return notes


@dataclass(frozen=True)
class UnfollowedOrdering(Unsatisfied):
    """An ordering constraint no plan can follow, as a reason of no plan: the data flow needs ``after``'s
    component before ``before``'s (a put-down ordered before the approach that finds what it puts down).
    It ended ``cbrs plan`` with an error and status 1 (``OrderingConflictError``), where every other task
    that cannot be planned is answered "no plan" with its reasons, in the text, the JSON and the plans page.
    ``need``: the constraint; ``consumer``: the action class whose constraints the task follows;
    ``before``, ``after``: the components the constraint orders, as the error named them; ``ordered``:
    the action classes it orders, as its act:occursBefore and act:occursAfter say (none: not found)."""

    before: str = ""
    after: str = ""
    ordered: tuple[str, str] | None = None

    def _text(self) -> str:
        classes = ""
        if self.ordered is not None:
            first, then = map(shorten, self.ordered)
            classes = f" (act:occursBefore {first}, act:occursAfter {then})"
        return (
            f"the ordering constraint {shorten(self.need)} of {shorten(self.consumer)}{classes} puts"
            f" {self.before} before {self.after}, but the plan needs the opposite order; {self.remedy()}"
        )

    def to_dict(self) -> dict[str, Any]:
        found = super().to_dict()
        ordered = None if self.ordered is None else {"before": self.ordered[0], "after": self.ordered[1]}
        found["ordering"] = {"before": self.before, "after": self.after, "classes": ordered}
        return found

    def remedy(self) -> str:
        return (
            "correct the constraint (which sub-action comes first is its act:occursBefore), or remove it"
            " (docs/composition.md, 'Decomposition')"
        )


def unfollowed_ordering(error: OrderingConflictError, action: str, orderings: Iterable[Ordering]) -> UnfollowedOrdering:
    """``error`` as a reason of no plan for a task of ``action``, whose constraints (and its ancestors') are
    ``orderings``; the error names the constraint shortened, so it is found again by that name."""
    ordered = next(
        ((o.before, o.after) for o in orderings if error.constraint in (o.constraint, shorten(o.constraint))), None
    )
    found = next(
        (o.constraint for o in orderings if error.constraint in (o.constraint, shorten(o.constraint))), error.constraint
    )
    return UnfollowedOrdering(found, action, before=error.before, after=error.after, ordered=ordered)


__all__ = ["UnfollowedOrdering", "decomposition_notes", "unfollowed_ordering"]
