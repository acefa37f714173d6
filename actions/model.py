"""The action model: action classes, their sub-actions and ordering constraints (KnowRob style).

Read from the action ontology in the store; no composition or execution code lives here, so the
engines can change without touching what an action is.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass, field

import networkx as nx

from cbrs.actions.errors import UnknownTaskError
from cbrs.kb import KnowledgeBase, NotFoundError, Requirement
from cbrs.kb.errors import BlankNodeError
from cbrs.kb.namespaces import expand
from cbrs.reasoner.names import local_name


@dataclass(frozen=True)
class Ordering:
    """A strict partial ordering constraint: ``before`` happens before ``after``."""

    constraint: str
    before: str
    after: str


@dataclass(frozen=True)
class ActionClass:
    """An action class with its direct parents, sub-actions and the orderings it declares."""

    iri: str
    label: str | None = None
    parents: tuple[str, ...] = ()
    sub_actions: tuple[str, ...] = ()
    orderings: tuple[Ordering, ...] = ()
    dangling: tuple[str, ...] = ()  # ordering constraints that name no act:occursBefore and act:occursAfter

    def ordered_sub_actions(self) -> list[str]:
        """The sub-actions in an order that respects every ordering constraint (IRI order breaks ties);
        ``ActionLibrary`` stores them in that order when it reads them."""
        return list(self.sub_actions)


@dataclass
class ActionLibrary:
    """Every action class in the store, read once."""

    actions: dict[str, ActionClass] = field(default_factory=dict)

    @classmethod
    def from_kb(cls, kb: KnowledgeBase) -> ActionLibrary:
        parents: dict[str, set[str]] = {}
        subs: dict[str, list[str]] = {}
        labels: dict[str, str | None] = {}
        action_rows, ordering_rows = kb.select_each(("actions", "action_ordering"))  # one request to a remote store
        for row in action_rows:
            iri = row["action"].value
            labels[iri] = row["label"].value if "label" in row else None
            parents.setdefault(iri, set())
            if "parent" in row:
                parents[iri].add(row["parent"].value)
            if "subActions" in row and row["subActions"].value:
                subs[iri] = sorted(set(row["subActions"].value.split()))
        orderings: dict[str, list[Ordering]] = {}
        dangling: dict[str, list[str]] = {}
        for row in ordering_rows:
            if "before" not in row or "after" not in row:  # a misspelt constraint: said, not followed
                dangling.setdefault(row["action"].value, []).append(row["constraint"].value)
                continue
            orderings.setdefault(row["action"].value, []).append(
                Ordering(row["constraint"].value, row["before"].value, row["after"].value)
            )
        library = cls()
        for iri in parents:
            ordering = tuple(orderings.get(iri, ()))
            declared = _ordered(subs.get(iri, []), ordering)
            loose = tuple(sorted(set(dangling.get(iri, ()))))
            library.actions[iri] = ActionClass(iri, labels[iri], tuple(sorted(parents[iri])), declared, ordering, loose)
        return library

    def __contains__(self, iri: object) -> bool:
        return iri in self.actions

    def __iter__(self) -> Iterator[ActionClass]:
        return iter(self.actions.values())

    def get(self, iri: str) -> ActionClass:
        try:
            return self.actions[iri]
        except KeyError:
            raise NotFoundError(iri, "action class") from None

    def ancestors(self, iri: str) -> list[str]:
        """``iri`` and every action class above it, nearest first."""
        seen: list[str] = []
        queue = [iri]
        while queue:
            current = queue.pop(0)
            if current in seen or current not in self.actions:
                continue
            seen.append(current)
            queue.extend(self.actions[current].parents)
        return seen

    def orderings_for(self, iri: str) -> list[Ordering]:
        """The ordering constraints of ``iri`` and of the actions it specialises."""
        return [o for action in self.ancestors(iri) for o in self.actions[action].orderings]


def _ordered(subs: list[str], orderings: tuple[Ordering, ...]) -> tuple[str, ...]:
    """Sub-actions sorted by the ordering constraints, then by IRI, for a stable declared order."""
    graph: nx.DiGraph[str] = nx.DiGraph()
    graph.add_nodes_from(subs)
    graph.add_edges_from((o.before, o.after) for o in orderings if o.before in graph and o.after in graph)
    if not nx.is_directed_acyclic_graph(graph):
        return tuple(subs)
    return tuple(nx.lexicographical_topological_sort(graph))


@dataclass(frozen=True)
class Task:
    """What to plan for: a requirement, and the action class it asks for when there is one."""

    name: str
    requirement: Requirement
    action: ActionClass | None = None


def resolve_task(
    kb: KnowledgeBase,
    library: ActionLibrary,
    name: str,
    requirements: Callable[[], list[Requirement]] | None = None,
) -> Task:
    """A task from a requirement or action IRI, a prefixed name, or a bare local name.

    A bare name is tried as a requirement first (``req:NAME``), then as an action (``act:NAME``). An
    action is planned through the requirement that names it with ``cbrs:forTask`` when there is one,
    otherwise from the inputs, outputs, preconditions and effects the action class carries.
    ``requirements`` gives every requirement when one is needed (a composer reads them once per
    composition); by default they are read here.
    """
    listed: list[Requirement] | None = None

    def every() -> list[Requirement]:  # every requirement: only for an action or an unknown name
        nonlocal listed
        if listed is None:
            listed = requirements() if requirements is not None else kb.requirements()
        return listed

    candidates = [name] if ":" in name else [f"req:{name}", f"act:{name}"]
    for candidate in candidates:
        try:
            iri = expand(candidate)
        except ValueError:
            continue
        requirement = _stated(kb, iri) or next((r for r in every() if r.iri == iri), None)
        if requirement is not None:
            action = library.actions.get(requirement.for_task or "")
            return Task(iri, requirement, action)
        if iri in library:
            action = library.get(iri)
            stated = sorted((r for r in every() if r.for_task == iri), key=lambda r: r.iri)
            requirement = stated[0] if stated else kb.action_requirement(iri, action.label)
            return Task(iri, requirement, action)
    if ":" not in name:  # a bare name of the lab's own namespace (lab:TidyUp): one requirement or action of that name
        named = sorted({r.iri for r in every() if local_name(r.iri) == name})
        named = named or sorted(a.iri for a in library if local_name(a.iri) == name)
        if len(named) == 1:
            return resolve_task(kb, library, named[0], requirements)
        if named:
            raise UnknownTaskError(name, named, ambiguous=True)
    known = sorted({local_name(r.iri) for r in every()} | {local_name(a.iri) for a in library if a.sub_actions})
    raise UnknownTaskError(name, known)


def _stated(kb: KnowledgeBase, iri: str) -> Requirement | None:
    """The requirement ``iri`` read alone (its own rows: a millisecond), or None to look it up among all.

    Reading every requirement to pick one cost about 80% of a warm composition (their rows come with
    every advertisement's); anything but a readable requirement falls back to that list, which is
    what decides."""
    try:
        found = kb.description(iri)
    except (NotFoundError, BlankNodeError):
        return None
    return found if isinstance(found, Requirement) else None
