"""Backward extraction of one plan from a searched service resource graph (paper section 4).

From SRO and SRE down, each need of a step is bound, in this order of preference, to what the
requirement supplies (SRI); for an input, the output of a sibling (a step made for the same consumer);
otherwise a new step of the best qualified provider of a lower forward level, so the extraction cannot
loop. Then identical invocations of static-data and method components are merged, the steps ordered
(producers first, the action ontology's orderings respected, each step as late as it can be) and every
step's drop-in alternatives listed; a statement a step needs that an earlier one deletes is achieved
again by a new step after it (``actions.progression`` finds it). ``actions.composer`` says when and for
what it is run.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from enum import Enum
from functools import partial
from typing import Any

import networkx as nx

from cbrs.actions.areas import AreaRule
from cbrs.actions.errors import OrderingConflictError
from cbrs.actions.graph import SRE, SRI, SRO, Edge, Need, ServiceResourceGraph, statement_text
from cbrs.actions.plan import Binding, Plan, PlanStep, Source
from cbrs.actions.progression import Clobbered, progress, threatens
from cbrs.actions.search import SearchTrace
from cbrs.actions.unmet import GOAL, Unsatisfied
from cbrs.kb import Statement
from cbrs.kb.namespaces import PREFIXES, shorten
from cbrs.reasoner.degrees import degree_of_match
from cbrs.reasoner.taxonomy import TaxonomyIndex


class Objective(Enum):
    SIMILARITY = "similarity"  # highest similarity first, estimated response time breaks ties
    # lowest stated cbrs:cost first when every candidate states one (then response time), else lowest
    # estimated response time; similarity breaks ties (docs/composition.md, "Which cost")
    COST = "cost"


_Key = Callable[[Edge], tuple[Any, ...]]

THING = PREFIXES["home"] + "PhysicalObject"
"""An input of this class or below designates a thing of the world (see :meth:`Extraction._things_wanted`)."""


@dataclass
class _Bound:
    need: Need
    edge: Edge
    source: int | None  # producing step id; None: the requirement


@dataclass
class _Step:
    id: int
    node: str
    made_for: int | None
    bindings: list[_Bound] = field(default_factory=list)
    producers: list[int] = field(default_factory=list)
    about: tuple[str, ...] = ()  # the classes of the statements this step serves, down from the goal
    # what a class of its component's statements stands for here: the more specific class of the statement it
    # serves, side by side (the put-down's PhysicalObject is the bell's Cup); an input's producer, its consumer's
    refines: dict[str, str] = field(default_factory=dict)


@dataclass(frozen=True)
class _Judged:
    """What a component would handle as a new step (requirement input names), and why it cannot (None: it can)."""

    things: frozenset[str]
    why: str | None
    blocked: Need | None = None  # the need none of whose providers can serve (else its own area is the why)


class Extraction:
    """Backward extraction of one plan from a searched SRG."""

    def __init__(
        self,
        graph: ServiceResourceGraph,
        trace: SearchTrace,
        objective: Objective,
        max_steps: int,
        areas: AreaRule | None = None,
        protect: bool = True,
        max_reachieved: int = 8,
        thing_class: str | None = THING,
    ) -> None:
        self.graph = graph
        self.thing_class = thing_class  # None: an input that designates a thing takes any value of its class
        self.protect = protect  # check the plan by progression and achieve again what a step undoes
        self.max_reachieved = max_reachieved
        self._after: list[tuple[int, int]] = []  # (deleter, step achieving again what it deleted, or a feeder)
        self._number: dict[int, int] = {}  # step id -> its index in the last draft
        self.trace = trace
        self.objective = objective
        self.max_steps = max_steps
        self.areas = areas
        self._judged: dict[tuple[str, tuple[str, ...]], _Judged] = {}  # see _judge
        self._things: dict[int, frozenset[str]] = {}  # see _about
        self._explained: set[str] = set()  # vertices whose blocked needs _why has followed
        self._best: dict[tuple[str, str], dict[str, Edge]] = {}  # see _best_from
        self._ranked: dict[int, str | None] = {}  # step id -> what decided its component (see _decided)
        self.steps: dict[int, _Step] = {}
        self._next_id = 0
        self.unsatisfied: list[Unsatisfied] = []
        goal_needs = [(SRO, n) for n in graph.needs(SRO)] + [(SRE, n) for n in graph.needs(SRE)]
        if not goal_needs:
            self.unsatisfied.append(Unsatisfied("an output or effect", GOAL, ("the requirement states none",)))
            return
        self._goal_needs = goal_needs
        self._goal_concepts = {
            c for _, n in goal_needs if n.statement is not None for c in (n.statement.subject, n.statement.object)
        }
        self._goal_subjects = {n.statement.subject for _, n in goal_needs if n.statement is not None}
        blocked = [(node, n) for node, n in goal_needs if not self._ready(node, n)]
        if blocked:
            for node, need in blocked:
                wanted = need.text()
                if node in (SRO, SRE):
                    wanted = wanted.replace("precondition", "effect", 1).replace("input", "output", 1)
                for cause in self._why(node, need, (f"the requirement's {wanted}",)):
                    if all((cause.need, cause.consumer) != (u.need, u.consumer) for u in self.unsatisfied):
                        self.unsatisfied.append(cause)
            return
        self._expand(deque([self._new(GOAL, None).id]))
        self._bind_deletions()
        if self.areas is not None and not self.unsatisfied:
            self._check_areas()

    @property
    def solved(self) -> bool:
        return not self.unsatisfied

    # a need is ready when some enabled vertex (below the consumer's level) meets it
    def _ready(self, node: str, need: Need) -> bool:
        return bool(self._options(node, need, self._level(node)))

    def _level(self, node: str) -> int:
        return self.trace.levels.get(node, len(self.graph.vertices) + 1) if node not in (SRO, SRE) else 10**9

    def _options(self, node: str, need: Need, below: int) -> list[Edge]:
        return [
            e
            for e in self.graph.providers(node, need)
            if e.source in self.trace.levels and self.trace.levels[e.source] < below
        ]

    def _why(self, node: str, need: Need, chain: tuple[str, ...]) -> list[Unsatisfied]:
        """Why ``need`` of ``node`` cannot be met: follow the best blocked provider down to a root cause.

        Depth first, on a stack of its own: a chain of blocked providers can be thousands long."""
        causes: list[Unsatisfied] = []
        followed: list[str] = []  # the providers followed down to the need on top of the stack
        along: list[tuple[str, str]] = []  # (consumer, need) that each of them was followed for
        on_path: set[str] = set()
        stack: list[tuple[str, Need] | None] = [(node, need)]  # None: back up from the last provider followed
        while stack:
            item = stack.pop()
            if item is None:
                on_path.discard(followed.pop())
                along.pop()
                continue
            node, need = item
            providers = [e for e in self.graph.providers(node, need) if e.source != node]
            if not providers:
                causes.append(
                    Unsatisfied(
                        need.text(),
                        node,
                        self._chain(chain, followed),
                        provided=self._provided(need),
                        unlike=self._unlike(need),
                        along=tuple(along),
                    )
                )
                continue
            best = providers[0]
            if best.source in on_path:
                causes.append(Unsatisfied(need.text(), node, self._chain(chain, followed), cycle=True))
                continue
            if best.source in self._explained:  # its causes are reported already, down another chain
                continue
            self._explained.add(best.source)
            blocked = [
                sub
                for sub in self.graph.needs(best.source)
                if not self._options(best.source, sub, self._level(best.source))
            ]
            if not blocked:
                causes.append(Unsatisfied(need.text(), node, self._chain(chain, followed), along=tuple(along)))
                continue
            followed.append(best.source)
            along.append((node, need.text()))
            on_path.add(best.source)
            stack.append(None)
            stack.extend((best.source, sub) for sub in reversed(blocked))
        return causes

    def _provided(self, need: Need, most: int = 4) -> tuple[tuple[str, str], ...]:
        """For a statement no component provides: the effects components do provide about things of its
        subject's class (their subject the same or above it), those whose predicate, then whose object,
        would match first, at most ``most``. A goal ``(TeaTin, isLocatedOn, Counter)`` then shows
        ``(PhysicalObject, isLocated, Place)`` by PutDownObject: what the counter must also be."""
        wanted = need.statement
        index = self.graph.matcher.index
        if wanted is None or wanted.subject not in index:
            return ()
        above = {*index.is_a_ancestors(wanted.subject), index.canonical(wanted.subject)}

        def differs(wanted_term: str, offered_term: str) -> bool:
            return not degree_of_match(index, wanted_term, offered_term).accepted

        offers = (
            self.graph.pool.deletions
            if need.role == "deletion"  # what components delete about it
            else [(v.iri, offer) for v in self.graph.pool.vertices.values() for offer in v.offers]
        )
        found = {
            (
                differs(wanted.predicate, offer.statement.predicate),
                differs(wanted.object, offer.statement.object),
                iri,
                statement_text(offer.statement),
            )
            for iri, offer in offers
            if offer.statement is not None
            and offer.role in ("effect", "delete")
            and offer.statement.subject in index
            and index.canonical(offer.statement.subject) in above
        }
        return tuple((iri, text) for *_, iri, text in sorted(found)[:most])

    def _unlike(self, need: Need) -> tuple[str, tuple[str, ...]] | None:
        """For a statement no component provides: the objects of the effects components provide about its
        subject's class by its predicate (or one above it) that its own object is not, when it is none of
        them. The ninth round's goal (StorageBox, isLocatedOn, Book) listed what the put-down, the hand-over
        and the delivery provide, but not that a book is no place, no platform and no person."""
        wanted = need.statement
        index = self.graph.matcher.index
        if need.role == "deletion" or wanted is None or wanted.subject not in index or wanted.object not in index:
            return None
        above = {*index.is_a_ancestors(wanted.subject), index.canonical(wanted.subject)}
        objects: dict[str, bool] = {}
        for vertex in self.graph.pool.vertices.values():
            for offer in vertex.offers:
                said = offer.statement
                if said is None or offer.role != "effect" or said.subject not in index:
                    continue
                if index.canonical(said.subject) not in above:
                    continue
                if not degree_of_match(index, wanted.predicate, said.predicate).accepted:
                    continue
                objects[said.object] = degree_of_match(index, wanted.object, said.object).accepted
        if not objects or any(objects.values()):
            return None
        return wanted.object, tuple(sorted(objects))

    @staticmethod
    def _chain(start: tuple[str, ...], followed: list[str]) -> tuple[str, ...]:
        return (*start, *map(shorten, followed))

    def _key(self, edge: Edge, stated: bool = False) -> tuple[Any, ...]:
        """How good a provider ``edge`` is, lowest best; ``stated``: its ``cbrs:cost`` first (see :meth:`_ranker`)."""
        cost = round(self.trace.costs[edge.source], 9)
        tail = (self.trace.levels[edge.source], edge.source, edge.offer.name)
        if self.objective is not Objective.COST:
            return (-round(edge.similarity, 9), cost, *tail)
        stated_cost = self.graph.stated_cost(edge.source)
        head = (round(stated_cost, 9),) if stated and stated_cost is not None else ()
        return (*head, cost, -round(edge.similarity, 9), *tail)

    def _ranker(self, edges: Sequence[Edge]) -> _Key:
        """The key ``edges`` are ranked by among themselves: with objective cost, their providers' stated
        ``cbrs:cost`` first when every one states one; a figure without a unit is not compared with
        seconds, so when any states none they are ranked by estimated response time, as before."""
        return partial(self._key, stated=self._stated(edges))

    def _stated(self, edges: Sequence[Edge]) -> bool:
        return self.objective is Objective.COST and all(self.graph.stated_cost(e.source) is not None for e in edges)

    def _decided(self, best: Edge, candidates: Sequence[Edge], rank: _Key) -> str | None:
        """What told ``best`` from the best candidate of another component: the first part of the key
        where they differ (None: no other component could)."""
        others = [e for e in candidates if e.source != best.source]
        if not others:
            return None
        mine, theirs = rank(best), rank(min(others, key=rank))
        names: tuple[str, ...] = ("similarity", "responseTime", "level", "iri", "iri")
        if self.objective is Objective.COST:
            names = ("responseTime", "similarity", "level", "iri", "iri")
            names = ("cbrs:cost", *names) if self._stated(candidates) else names
        return next((name for name, a, b in zip(names, mine, theirs, strict=True) if a != b), "iri")

    def _new(self, node: str, made_for: int | None) -> _Step:
        step = _Step(self._next_id, node, made_for)
        self._next_id += 1  # not len(steps): merging shared invocations removes steps
        self.steps[step.id] = step
        return step

    def _expand(self, queue: deque[int]) -> None:
        while queue:
            step = self.steps[queue.popleft()]
            needs = (
                [(node, n) for node, n in self._goal_needs if n.role != "deletion"]
                if step.node == GOAL
                else [(step.node, n) for n in self.graph.needs(step.node)]
            )
            # pre-actions (P-E) first, then pre-services (I-O), as in the paper's backward search
            needs.sort(key=lambda item: item[1].role != "precondition")
            for node, need in needs:
                self._bind(step, node, need, queue)

    def _bind_deletions(self) -> None:
        """Bind each delete effect the requirement wants, once the rest of the plan is extracted: to a step
        already planned whose delete effect meets it (the pick-up that takes the pen off the table on the
        way to the shelf), else to a new step of its best provider, extracted in turn."""
        goal = self.steps[0]
        for node, need in self._goal_needs:
            if need.role != "deletion":
                continue
            options = [e for e in self._options(node, need, 10**9) if e.source != SRI]
            rank = self._ranker(options)
            planned = [(rank(e), step.id, e) for step in self.steps.values() for e in options if e.source == step.node]
            if planned:
                *_, step_id, edge = min(planned, key=lambda item: item[:2])
                goal.bindings.append(_Bound(need, edge, step_id))
                continue
            queue: deque[int] = deque()
            if self._bind(goal, node, need, queue):
                self._expand(queue)

    def _bind(self, step: _Step, node: str, need: Need, queue: deque[int], again: bool = False) -> bool:
        """Bind ``need`` of ``step`` by the preferences above; ``again``: to a new step, never to what the
        task gives or an existing step (the need was undone after those: see :meth:`_achieve_again`).
        False when no provider can serve (the reason is in ``unsatisfied``, unless ``again``)."""
        below = 10**9 if step.node == GOAL else self.trace.levels[step.node]
        options = self._options(node, need, below)
        wanted = self._things_wanted(step, need)
        if wanted:
            fitting = [e for e in options if self._is_wanted(e, wanted)]
            if not fitting:
                self._no_thing(step, node, need, wanted, options)
                return False
            options = fitting
        if not again:
            given = [e for e in options if e.source == SRI]
            if given and len(given) < len(options):
                # another goal's thing (the tray the cup goes to) is no value for the steps of this
                # one (where the base parks to load the pen), which have a provider of their own
                given = [e for e in given if not self._foreign(step, e)]
            taken = self._taken(step, need)
            if given:
                chosen = min(given, key=partial(self._given_key, step, need, taken))
                step.bindings.append(_Bound(need, chosen, None))
                return True
            mine = [(e, p) for p in step.producers for e in options if e.source == self.steps[p].node]
            if mine:  # a step already made for this consumer meets this need too
                rank = self._ranker([e for e, _ in mine])
                edge, producer_id = min(
                    mine, key=lambda item: ((item[1], item[0].offer.name) in taken, rank(item[0]), item[1])
                )
                step.bindings.append(_Bound(need, edge, producer_id))
                return True
            sibling = self._sibling(step, node, need, taken, wanted)
            if sibling is not None:
                step.bindings.append(sibling)
                return True
        served = (need.statement.subject, need.statement.object) if need.statement is not None else ()
        about = (*served, *step.about)
        candidates = [e for e in options if e.source != SRI]
        if not candidates:
            return False
        if self.areas is not None:
            fit = [e for e in candidates if self._judge(e.source, about).why is None]
            if not fit:
                self._pass_over(step, node, need, candidates, about)
                return False
            candidates = fit
        rank = self._ranker(candidates)
        best = min(candidates, key=rank)
        if len(self.steps) > self.max_steps and not again:
            existing = next((other for other in self.steps.values() if other.node == best.source), None)
            if existing is not None:
                step.bindings.append(_Bound(need, best, existing.id))
                return True
        producer = self._new(best.source, step.id)
        producer.about = about
        producer.refines = self._refined(step, need, best)
        self._ranked[producer.id] = self._decided(best, candidates, rank)
        step.producers.append(producer.id)
        step.bindings.append(_Bound(need, best, producer.id))
        queue.append(producer.id)
        return True

    def _given_key(self, step: _Step, need: Need, taken: set[tuple[int | None, str]], edge: Edge) -> tuple[Any, ...]:
        """The order of the values the task gives for ``need`` of ``step``, best first: one not ``taken`` by
        another input of the step of the same class (:meth:`_taken`), then :meth:`_fit`, then one named as
        the input (:meth:`_named`), then :meth:`_key`, whose last part is the value's name: twin inputs, in
        the order the component declares them, take the task's things of their class in the order of their
        names (``_TrainStation0`` the first)."""
        return (
            (None, edge.offer.name) in taken,
            *self._fit(step, edge),
            self._named(step, need, edge),
            *self._key(edge),
        )

    def _named(self, step: _Step, need: Need, edge: Edge) -> int:
        """For an input with twins (other inputs of the step of its class, :meth:`_twins`), how the name of a
        value the task gives tells them apart: named as this input (0), as none of them (1), as another of
        them (2), the case aside. A component's ``departure`` takes the task's ``departure``, and its
        ``arrival`` the task's other station, where the order of the names gave ``arrival`` the departure.
        Other inputs read no names (0): their class tells their values apart (docs/composition.md)."""
        if need.role != "input" or step.node == GOAL:
            return 0
        twins = [other.name.casefold() for other in self.graph.needs(step.node) if self._twins(need, other)]
        if not twins:
            return 0
        name = edge.offer.name.casefold()
        return 0 if name == need.name.casefold() else 2 if name in twins else 1

    def _fit(self, step: _Step, edge: Edge) -> tuple[int, int]:
        """The order of the values the task gives for a need of ``step``: one whose class falls under the
        subject of a goal the step serves (0) before one that does not (1), then the most about what it
        serves (:meth:`_aboutness`). A statement is about its subject: in (TeaTin, isLocated, Counter) the
        tin is what is moved and the counter where to, though a counter that is furniture as well as a
        place is as much a physical object as the tin. The subject comes first whatever the depths: in
        (Apple, isLocatedOn, FruitBowl), a lab's apple straight under home:PhysicalObject and a bowl under
        home:Bowl, home:Container and home:Artifact, the deeper bowl was the more about the arm's steps,
        and the arm was sent to pick up the bowl (docs/tasks.md, "An eighth round"). Before that, the
        tie of two as deep went to the input whose name sorts first."""
        about = self._aboutness(step, edge)
        concept = edge.offer.concept
        index = self.graph.pool.matcher.index
        if concept is None or concept not in index:
            return (1, about)
        ancestors = index.is_a_ancestors(concept)
        return (0 if any(c in ancestors for c in self._goal_subjects.intersection(step.about)) else 1, about)

    def _aboutness(self, step: _Step, edge: Edge) -> int:
        """How well a value the task gives fits what ``step`` is for: minus the depth of the most specific
        class, among the statements it serves, that the value's class falls under (0 if none).

        Descriptions link no input to a statement, so the data flow alone cannot tell which of the
        task's things a step handles: given a mug and a tap, both physical objects, the grasp for
        filling the mug must be the mug's, because the step serves (Drinkware, isLocated, BelowOfTap)
        for (Mug, contains, Water). Goals name their things; this carries their classes down the plan."""
        concept = edge.offer.concept
        if concept is None or not step.about:
            return 0
        index = self.graph.pool.matcher.index
        if concept not in index:
            return 0
        ancestors = index.is_a_ancestors(concept)
        depths = [index.depth(c) for c in step.about if c in ancestors and c in index]
        return -max(depths) if depths else 0

    def _things_wanted(self, step: _Step, need: Need, loose: bool = False) -> tuple[str, ...]:
        """For an input of ``step`` that designates a thing (its class at or below ``thing_class``): the most
        specific classes its class stands for in the statements the step is planned for (``refines``). The
        value must be of one of them: the pick-up's chain for the bell's (Cup, isLocated, PlaceMat) wants a
        home:Cup, where its input's home:PhysicalObject took the base's colour marker a ceiling camera finds.
        ``loose``: any class, at or below the input's, of the statements it serves (``about``), for judging
        a component before it is chosen (:meth:`_ways`). Empty: any value of the input's class will do
        (docs/composition.md, "The thing an input is for")."""
        concept, thing = need.concept, self.thing_class
        if thing is None or need.role != "input" or step.node == GOAL or concept is None:
            return ()
        index = self.graph.matcher.index
        if concept not in index or not index.is_a(concept, thing):
            return ()
        if loose:
            return tuple(sorted({index.canonical(c) for c in step.about if c in index and index.is_a(c, concept)}))
        under = {
            index.canonical(specific)
            for general, specific in step.refines.items()
            if index.is_a(specific, concept) and (index.is_a(general, concept) or index.is_a(concept, general))
        }
        return tuple(sorted(c for c in under if not any(o != c and index.is_a(o, c) for o in under)))

    def _refined(self, consumer: _Step, need: Need, edge: Edge) -> dict[str, str]:
        """What the classes of ``edge``'s provider stand for, made a step for ``need`` of ``consumer``: for an
        input, what the consumer's do (it prepares data about the consumer's things); for a precondition, the
        need's class on each side where it is below the offer's, the need read as the consumer's classes
        stand for (the carry's (PhysicalObject, isGraspedBy, Gripper), for the bell's cup, makes the
        pick-up's PhysicalObject a Cup)."""
        wanted, offered = need.statement, edge.offer.statement
        if wanted is None or offered is None:
            return dict(consumer.refines)
        index = self.graph.matcher.index
        found: dict[str, str] = {}
        for mine, theirs in ((wanted.subject, offered.subject), (wanted.object, offered.object)):
            if mine not in index or theirs not in index:
                continue
            mine = consumer.refines.get(index.canonical(mine), mine)
            if index.canonical(mine) != index.canonical(theirs) and index.is_a(mine, theirs):
                found[index.canonical(theirs)] = mine
        return found

    def _is_wanted(self, edge: Edge, wanted: tuple[str, ...]) -> bool:
        """Whether the value ``edge`` offers is of a class of ``wanted`` or below (none wanted: any is)."""
        if not wanted:
            return True
        concept = edge.offer.concept
        index = self.graph.matcher.index
        return concept is not None and any(index.is_a(concept, c) for c in wanted)

    def _no_thing(self, step: _Step, node: str, need: Need, wanted: tuple[str, ...], options: list[Edge]) -> None:
        """``need``, an input for a thing of a class of ``wanted``, as unmet: the task gives none and no step
        gives one; the values of its class passed over (what the task gives, what providers output), by class."""
        passed = tuple(
            sorted(
                {
                    ("the task" if e.source == SRI else e.source, f"{e.offer.name} ({shorten(e.offer.concept or '')})")
                    for e in options
                }
            )
        )
        served = next(
            (s for s in self._served(step) if any(self._canonical(side) in wanted for side in (s.subject, s.object))),
            None,
        )
        self.unsatisfied.append(
            Unsatisfied(
                need.text(),
                node,
                self._path(step, need),
                things=wanted,
                things_for=statement_text(served) if served is not None else "",
                passed_over=passed,
            )
        )

    def _canonical(self, concept: str) -> str:
        index = self.graph.matcher.index
        return index.canonical(concept) if concept in index else concept

    def _served(self, step: _Step) -> list[Statement]:
        """The statements ``step`` is planned for, nearest first: the need it was made for, up to the goal."""
        found: list[Statement] = []
        current = step
        while current.made_for is not None:
            parent = self.steps[current.made_for]
            bound = next((b for b in parent.bindings if b.source == current.id), None)
            if bound is not None and bound.need.statement is not None:
                found.append(bound.need.statement)
            current = parent
        return found

    def _foreign(self, step: _Step, edge: Edge) -> bool:
        """Whether a value the task gives belongs to another goal than the ones ``step`` serves: its class
        falls under a class another goal names more specifically than under any class of the statements
        ``step`` serves (a PenTray is an ObjectPlace, but the tray goal names it as a PenTray)."""
        concept = edge.offer.concept
        index = self.graph.pool.matcher.index
        if concept is None or concept not in index or not step.about:
            return False
        ancestors = index.is_a_ancestors(concept)
        others = [index.depth(c) for c in self._goal_concepts - set(step.about) if c in ancestors and c in index]
        return bool(others) and max(others) > -self._aboutness(step, edge)

    def _twins(self, need: Need, other: Need) -> bool:
        """Whether ``other`` is another input of the same class as input ``need`` (see :meth:`_taken`)."""
        mine, theirs = need.concept, other.concept
        if need.role != "input" or other.role != "input" or other == need or mine is None or theirs is None:
            return False
        index = self.graph.pool.matcher.index
        if mine in index and theirs in index:
            return index.canonical(mine) == index.canonical(theirs)
        return mine == theirs

    def _taken(self, step: _Step, need: Need) -> set[tuple[int | None, str]]:
        """The values (producing step, or None for the task; and the name) already bound to ``step``'s other
        inputs of ``need``'s class. A component that takes two things of one class (a fare's two stations)
        means two things: each is given one not taken yet where there is one, and shares only when what
        the task and the steps give is fewer (docs/composition.md, "Extracting the plan")."""
        return {(b.source, b.edge.offer.name) for b in step.bindings if self._twins(need, b.need)}

    def _sibling(
        self, step: _Step, node: str, need: Need, taken: set[tuple[int | None, str]], wanted: tuple[str, ...] = ()
    ) -> _Bound | None:
        """An output of a step made for the same consumer, if one meets this input (one not ``taken`` first;
        of a class of ``wanted``, when it names any: :meth:`_things_wanted`)."""
        if need.role != "input" or step.made_for is None:
            return None
        level = self.trace.levels[step.node]
        found: list[tuple[tuple[Any, ...], _Bound]] = []
        for other_id in self.steps[step.made_for].producers:
            other = self.steps[other_id]
            if other.id == step.id or self.trace.levels[other.node] >= level:
                continue
            for edge in self.graph.providers(node, need):
                if edge.source == other.node and edge.offer.role == "output" and self._is_wanted(edge, wanted):
                    rank = ((other.id, edge.offer.name) in taken, -edge.similarity, other.id, edge.offer.name)
                    found.append((rank, _Bound(need, edge, other.id)))
        return min(found, key=lambda item: item[0])[1] if found else None

    # -- service effective areas (actions.areas) --------------------------------------------------

    def _judge(self, vertex: str, about: tuple[str, ...]) -> _Judged:
        """What ``vertex`` would handle as a new step serving ``about``, by the extraction's own preferences
        (a value the task gives first, else the best provider that fits), and why it cannot serve (its
        area, or none of a need's providers fits): a component is passed over before it is chosen.

        Providers are judged first, on a stack of its own (a chain of providers can be thousands long)."""
        stack = [(vertex, about)]
        while stack:
            key = stack[-1]
            if key in self._judged:
                stack.pop()
                continue
            missing = [
                (e.source, below)
                for _, given, below, providers in self._ways(*key)
                if given is None
                for e in providers
                if (e.source, below) not in self._judged
            ]
            if missing:
                stack += missing
                continue
            self._judged[key] = self._judge_now(*key)
            stack.pop()
        return self._judged[(vertex, about)]

    def _ways(self, vertex: str, about: tuple[str, ...]) -> list[tuple[Need, Edge | None, tuple[str, ...], list[Edge]]]:
        """For each need of ``vertex`` serving ``about``: the value the task gives that a new step would take
        (None: none), the classes its providers would serve, and its providers other than the task."""
        probe = _Step(-1, vertex, None, about=about)
        ways: list[tuple[Need, Edge | None, tuple[str, ...], list[Edge]]] = []
        for need in self.graph.needs(vertex):
            options = self._options(vertex, need, self._level(vertex))
            wanted = self._things_wanted(probe, need, loose=True)
            options = [e for e in options if self._is_wanted(e, wanted)]
            given = [e for e in options if e.source == SRI]
            if given and len(given) < len(options):
                given = [e for e in given if not self._foreign(probe, e)]
            taken = self._taken(probe, need)
            key = partial(self._given_key, probe, need, taken)
            chosen = min(given, key=key) if given else None
            if chosen is not None:
                probe.bindings.append(_Bound(need, chosen, None))
            served = (need.statement.subject, need.statement.object) if need.statement is not None else ()
            ways.append((need, chosen, (*served, *about), [e for e in options if e.source != SRI]))
        return ways

    def _judge_now(self, vertex: str, about: tuple[str, ...]) -> _Judged:
        """``_judge`` once every provider of ``vertex``'s needs has been judged."""
        assert self.areas is not None
        things: set[str] = set()
        bound: set[str] = set()  # those of its things it must be where they are (see _handled)
        via: dict[str, tuple[str, str | None]] = {}  # a thing not given directly: the input that leads to it
        given_here: set[str] = set()
        for need, given, below, providers in self._ways(vertex, about):
            if given is not None:
                if need.role == "input":
                    things.add(given.offer.name)
                    bound.add(given.offer.name)
                    given_here.add(given.offer.name)
                continue
            if not providers:  # no value of the thing it is for (_things_wanted): _bind says so, not the area
                continue
            fit = [e for e in providers if self._judged[(e.source, below)].why is None]
            if not fit:
                why = f"no provider of its {need.text()} is effective where it is needed"
                return _Judged(frozenset(things), why, need)
            if need.role == "input":
                fed = self._judged[(min(fit, key=self._ranker(fit)).source, below)].things
                things |= fed
                if self.areas.passes_on(need.concept):
                    bound |= fed
                    for thing in fed:
                        via.setdefault(thing, (need.name, need.concept))
        led = {t: way for t, way in via.items() if t not in given_here}  # one it is given itself ties it anyway
        why_not = self.areas.why_not(self.graph.vertices[vertex].advertisement, bound, led)
        return _Judged(frozenset(things), why_not)

    def _pass_over(self, step: _Step, node: str, need: Need, candidates: list[Edge], about: tuple[str, ...]) -> None:
        """``need`` of ``step`` has providers, none of which can serve: an unmet need naming each and why.
        While every one fails only for want of a provider of its own, the best is followed down (as ``_why``
        does), so the report names the components whose areas do not cover the things."""
        chain = self._path(step, need)
        along: list[tuple[str, str]] = []  # the needs above the one reported, each with its consumer
        while True:
            judged = {e.source: self._judge(e.source, about) for e in sorted(candidates, key=self._ranker(candidates))}
            best = next(iter(judged))
            lower = judged[best].blocked
            if lower is None or any(j.blocked is None for j in judged.values()):
                break
            served = (lower.statement.subject, lower.statement.object) if lower.statement is not None else ()
            deeper = [e for e in self._options(best, lower, self._level(best)) if e.source != SRI]
            if not deeper:
                break
            along.append((node, need.text()))
            node, need, about, candidates = best, lower, (*served, *about), deeper
            chain = (*chain, shorten(node))
        passed = tuple(sorted((iri, j.why or "") for iri, j in judged.items()))
        self.unsatisfied.append(Unsatisfied(need.text(), node, chain, out_of_area=passed, along=tuple(along)))

    def _check_areas(self) -> None:
        """Refuse the plan if a step's component is not effective where the things it handles are: the
        choice predicted them, and a step given an existing step's value may handle others."""
        assert self.areas is not None
        for step in sorted(self.steps.values(), key=lambda s: s.id):
            if step.made_for is None:
                continue
            why = self.areas.why_not(self.graph.vertices[step.node].advertisement, *self._handled_via(step.id))
            if why is None:
                continue
            consumer = self.steps[step.made_for]
            bound = next(b for b in consumer.bindings if b.source == step.id)
            node = self._goal_node(bound.need) if consumer.node == GOAL else consumer.node
            chain = self._path(consumer, bound.need)
            self.unsatisfied.append(Unsatisfied(bound.need.text(), node, chain, out_of_area=((step.node, why),)))

    def _handled(self, step_id: int) -> frozenset[str]:
        """The requirement inputs whose things ``step_id`` handles, so must be effective where they are:
        those it is given directly, and those its other inputs are about when the input's class leads to
        its thing (``AreaRule.passes_on``: a position, a feature; not a weight, which only informs)."""
        return self._handled_via(step_id)[0]

    def _handled_via(self, step_id: int) -> tuple[frozenset[str], dict[str, tuple[str, str | None]]]:
        """:meth:`_handled`, with the (name, class) of the input that leads to each thing not given directly."""
        assert self.areas is not None
        inputs = [b for b in self.steps[step_id].bindings if b.need.role == "input"]
        direct = {b.edge.offer.name for b in inputs if b.source is None}
        via: dict[str, tuple[str, str | None]] = {}
        for b in inputs:
            if b.source is not None and self.areas.passes_on(b.need.concept):
                for thing in sorted(self._about(b.source) - direct):
                    via.setdefault(thing, (b.need.name, b.need.concept))
        return frozenset(direct | via.keys()), via

    def _about(self, step_id: int) -> frozenset[str]:
        """The requirement inputs whose things the values ``step_id`` puts out are about: those it is given,
        directly or through the steps that feed its inputs, whatever their class (a grasp pose computed
        from a pen's grasp type is the pen's). On a stack of its own: a plan can be thousands of steps deep."""
        stack = [step_id]
        while stack:
            current = stack[-1]
            if current in self._things:
                stack.pop()
                continue
            inputs = [b for b in self.steps[current].bindings if b.need.role == "input"]
            missing = [b.source for b in inputs if b.source is not None and b.source not in self._things]
            if missing:
                stack += missing
                continue
            found: set[str] = set()
            for b in inputs:
                found |= {b.edge.offer.name} if b.source is None else self._things[b.source]
            self._things[current] = frozenset(found)
            stack.pop()
        return self._things[step_id]

    def _path(self, step: _Step, need: Need) -> tuple[str, ...]:
        """The chain from the requirement's goal down to ``need`` of ``step``, as ``_why`` reports one."""
        below: list[str] = []
        current = step
        while current.made_for is not None:
            below.append(shorten(current.node))
            parent = self.steps[current.made_for]
            if parent.node == GOAL:
                goal = next(b.need for b in parent.bindings if b.source == current.id)
                return (_goal_text(goal), *reversed(below))
            current = parent
        return (_goal_text(need),)  # ``step`` is the goal: ``need`` is the requirement's

    # -- from the extraction to a Plan -----------------------------------------------------------

    def plan(self, task: str, index: TaxonomyIndex, orderings: list[tuple[str, str, str]]) -> Plan | None:
        """The plan, checked by progression from what SRI offers (the requirement's preconditions and the
        world state) when ``protect`` is set: a statement a step needs that an earlier step deletes is
        achieved again after that step, at most ``max_reachieved`` times. None when it cannot be (the
        statement and its deleter are in ``unsatisfied``)."""
        initial = [o.statement for o in self.graph.vertices[SRI].offers if o.statement is not None]
        achieved_again = 0
        while True:
            plan = self._draft(task, index, orderings)
            if not self.protect:
                return plan
            # only what a step deletes is this rule's: the extraction binds every need to what meets it
            undone = [u for u in progress(plan, initial, self.graph.matcher) if u.deleter is not None]
            exhausted = achieved_again >= self.max_reachieved
            if not undone:
                restated = _restated(plan, index)
                if restated is None:
                    return plan
                if exhausted or not self._delete_again(*restated):
                    self.unsatisfied.insert(0, self._restated_need(plan, *restated, exhausted))
                    return None
            elif exhausted or not self._achieve_again(undone[0]):
                self.unsatisfied.insert(0, self._undone(plan, undone[0], exhausted))
                return None
            achieved_again += 1

    def _draft(self, task: str, index: TaxonomyIndex, orderings: list[tuple[str, str, str]]) -> Plan:
        self._merge_shared()
        order = self._order(index, orderings)
        number = self._number = {step_id: n for n, step_id in enumerate(order, start=1)}
        requirement = self.graph.requirement
        steps: list[PlanStep] = []
        for step_id in order:
            step = self.steps[step_id]
            vertex = self.graph.vertices[step.node]
            ad = vertex.advertisement
            assert ad is not None
            steps.append(
                PlanStep(
                    index=number[step_id],
                    component=ad.iri,
                    label=ad.label,
                    kind=ad.kind,
                    device=ad.device,
                    action=ad.realizes_action,
                    bindings=tuple(self._binding(b, number, requirement.iri) for b in step.bindings),
                    outputs=tuple((o.name, o.concept or "") for o in vertex.offers if o.role == "output"),
                    effects=tuple(o.statement for o in vertex.offers if o.statement is not None),
                    cost=vertex.cost,
                    alternatives=tuple(self._alternatives(step)),
                    deletes=ad.deletes,
                    ranked_by=self._ranked.get(step_id),
                )
            )
        goals = tuple(self._binding(b, number, requirement.iri) for b in self.steps[0].bindings)
        everything = [b for s in steps for b in s.bindings] + list(goals)
        similarity = sum(b.similarity for b in everything) / len(everything)
        return Plan(task, requirement.iri, "direct", tuple(steps), goals, similarity, sum(s.cost for s in steps))

    def _achieve_again(self, undone: Clobbered) -> bool:
        """Bind the need ``undone`` names to a new step of its best provider, ordered after the step that
        deleted it, with the new steps that feed it (a perception step then sees the world after the
        deletion); a step that fed only the undone need is dropped. False when no provider can."""
        assert undone.deleter is not None
        by_index = {n: step_id for step_id, n in self._number.items()}
        consumer = self.steps[0 if undone.consumer is None else by_index[undone.consumer]]
        position = next(n for n, b in enumerate(consumer.bindings) if b.need.statement == undone.statement)
        return self._bind_after(consumer, position, by_index[undone.deleter])

    def _delete_again(self, statement: Statement, adder: int) -> bool:
        """Bind the delete effect the requirement wants of ``statement``, which step ``adder`` (its number in
        the draft) makes true again after the step it was bound to, to a new step of its best provider
        ordered after ``adder``: the base driven to the table before it drove to the person no longer
        leaves the person at the end. False when no provider can."""
        by_index = {n: step_id for step_id, n in self._number.items()}
        goal = self.steps[0]
        position = next(
            n for n, b in enumerate(goal.bindings) if b.need.role == "deletion" and b.need.statement == statement
        )
        return self._bind_after(goal, position, by_index[adder])

    def _restated_need(self, plan: Plan, statement: Statement, adder: int, exhausted: bool) -> Unsatisfied:
        """The delete effect wanted of ``statement`` as an unmet need: step ``adder`` makes it true again
        after the step that deleted it, and no new step can delete it after that one."""
        goal = self.steps[0]
        need = next(b.need for b in goal.bindings if b.need.role == "deletion" and b.need.statement == statement)
        why = f"step {adder} ({shorten(plan.step(adder).component)}) makes it true again and no step deletes it after"
        return Unsatisfied(need.text(), SRE, (*self._path(goal, need), why), cycle=exhausted)

    def _bind_after(self, consumer: _Step, position: int, before: int) -> bool:
        """Bind ``consumer``'s binding at ``position`` anew, to a new step of its best provider ordered after
        step ``before`` with the new steps that feed it (:meth:`_achieve_again`, :meth:`_delete_again`)."""
        deleter = before
        bound = consumer.bindings[position]
        node = self._goal_node(bound.need) if consumer.id == 0 else consumer.node
        unmet, first_new = len(self.unsatisfied), self._next_id
        del consumer.bindings[position]
        queue: deque[int] = deque()
        if not self._bind(consumer, node, bound.need, queue, again=True):
            consumer.bindings.insert(position, bound)
            return False
        consumer.bindings.insert(position, consumer.bindings.pop())  # where the need was declared
        self._expand(queue)
        self._prune()
        self._things.clear()  # what each step handles: the consumer's sources changed
        if self.areas is not None:
            self._check_areas()
        new = [s for s in self.steps if s >= first_new and not self.graph.vertices[self.steps[s].node].shareable]
        self._after += [(deleter, step_id) for step_id in new]
        return len(self.unsatisfied) == unmet

    def _prune(self) -> None:
        """Drop the steps no other step or goal takes anything from (the achiever an undone need had)."""
        while True:
            used = {b.source for s in self.steps.values() for b in s.bindings if b.source is not None}
            unused = [step_id for step_id in self.steps if step_id != 0 and step_id not in used]
            if not unused:
                return
            for step_id in unused:
                del self.steps[step_id]
            for step in self.steps.values():
                step.producers = [p for p in step.producers if p in self.steps]

    def _undone(self, plan: Plan, undone: Clobbered, exhausted: bool) -> Unsatisfied:
        """``undone`` (in the draft ``plan``) as an unmet need: the statement, its consumer, its deleter, and
        whether achieving statements again went round in circles (``exhausted``: ``max_reachieved`` times)."""
        by_index = {n: step_id for step_id, n in self._number.items()}
        consumer = self.steps[0 if undone.consumer is None else by_index[undone.consumer]]
        need = next(b.need for b in consumer.bindings if b.need.statement == undone.statement)
        node = self._goal_node(need) if consumer.id == 0 else consumer.node
        assert undone.deleter is not None
        deleter = plan.step(undone.deleter).component
        return Unsatisfied(need.text(), node, self._path(consumer, need), cycle=exhausted, deleted_by=(deleter,))

    def _binding(self, bound: _Bound, number: dict[int, int], requirement: str) -> Binding:
        need, edge = bound.need, bound.edge
        if bound.source is None:
            source = Source(edge.offer.name, None, requirement)
        else:
            source = Source(edge.offer.name, number[bound.source])
        return Binding(need.role, need.name, source, edge.degree.value, edge.similarity, need.concept, need.statement)

    def _merge_shared(self) -> None:
        """One invocation for shareable components bound to the same sources."""
        signatures: dict[int, tuple[Any, ...]] = {}

        def signature(step_id: int) -> tuple[Any, ...]:
            # producers before consumers, on a stack of its own: a plan can be thousands of steps deep
            stack = [step_id]
            while stack:
                current = stack[-1]
                if current in signatures:
                    stack.pop()
                    continue
                step = self.steps[current]
                if not self.graph.vertices[step.node].shareable:
                    signatures[current] = ("unique", current)
                    continue
                missing = [b.source for b in step.bindings if b.source is not None and b.source not in signatures]
                if missing:
                    stack += missing
                    continue
                parts = sorted(
                    (b.need.key, b.edge.offer.name, signatures[b.source] if b.source is not None else ("SRI",))
                    for b in step.bindings
                )
                signatures[current] = (step.node, tuple(parts))
            return signatures[step_id]

        keep: dict[tuple[Any, ...], int] = {}
        alias: dict[int, int] = {}
        for step_id in sorted(self.steps):
            if step_id == 0:
                continue
            sig = signature(step_id)
            alias[step_id] = keep.setdefault(sig, step_id)
        for step in self.steps.values():
            for bound in step.bindings:
                if bound.source is not None:
                    bound.source = alias[bound.source]
        for step_id, kept in alias.items():
            if kept != step_id:
                del self.steps[step_id]

    def _order(self, index: TaxonomyIndex, orderings: list[tuple[str, str, str]]) -> list[int]:
        """Producers before consumers, ordering constraints kept, each step as late as possible."""
        dag: nx.DiGraph[int] = nx.DiGraph()
        dag.add_nodes_from(s for s in self.steps if s != 0)
        for step in self.steps.values():
            for bound in step.bindings:
                if bound.source is not None and step.id != 0:
                    dag.add_edge(bound.source, step.id)
        actions = {
            s.id: ad.realizes_action
            for s in self.steps.values()
            if s.id != 0 and (ad := self.graph.vertices[s.node].advertisement) is not None and ad.realizes_action
        }
        for constraint, before, after in orderings:
            firsts = [s for s, a in actions.items() if index.is_a(a, before)]
            seconds = [s for s, a in actions.items() if index.is_a(a, after)]
            for first in firsts:
                for second in seconds:
                    if first == second or dag.has_edge(first, second):
                        continue
                    if nx.has_path(dag, second, first):
                        raise OrderingConflictError(
                            shorten(constraint),
                            shorten(self.steps[first].node),
                            shorten(self.steps[second].node),
                        )
                    dag.add_edge(first, second)
        for deleter, later in self._after:  # a step that achieves again what ``deleter`` deleted, and its feeders
            if deleter in dag and later in dag and not nx.has_path(dag, later, deleter):
                dag.add_edge(deleter, later)
        self._protect(index, dag)
        placed: dict[int, int] = {}  # step -> position counted from the end
        reverse: list[int] = []
        waiting = {s: set(dag.successors(s)) for s in dag.nodes}
        while len(reverse) < len(waiting):
            ready = [s for s, after in waiting.items() if s not in placed and after <= placed.keys()]
            # right before the consumer placed most recently; later-created steps first on ties,
            # so a consumer's inputs end up in their declared order
            chosen = max(ready, key=lambda s: (max((placed[c] for c in waiting[s]), default=-1), s))
            placed[chosen] = len(reverse)
            reverse.append(chosen)
        return list(reversed(reverse))

    def _protect(self, index: TaxonomyIndex, dag: nx.DiGraph[int]) -> None:
        """Order every step that deletes a statement a consumer relies on outside the span from its
        producer to its consumer: before the producer, or else after the consumer (a goal must still
        hold at the end, so its threats go before its producer). A threat that fits neither way is
        left to :meth:`plan`, whose check by progression achieves the statement again after it."""
        deleting = {
            s.id: ad.deletes
            for s in self.steps.values()
            if s.id != 0 and (ad := self.graph.vertices[s.node].advertisement) is not None and ad.deletes
        }
        for consumer in sorted(self.steps.values(), key=lambda s: s.id):
            for bound in consumer.bindings:
                needed = bound.need.statement
                if needed is None or bound.need.role == "deletion":  # a statement to stop being true
                    continue
                for threat, deletes in sorted(deleting.items()):
                    if threat in (consumer.id, bound.source) or not any(
                        threatens(index, deleted, needed) for deleted in deletes
                    ):
                        continue
                    options = []
                    if bound.source is not None:
                        options.append((threat, bound.source))
                    if consumer.id != 0:
                        options.append((consumer.id, threat))
                    for before, after in options:
                        if dag.has_edge(before, after) or not nx.has_path(dag, after, before):
                            dag.add_edge(before, after)
                            break

    def _alternatives(self, step: _Step) -> list[str]:
        """Components that accept this step's bindings and meet every need it serves."""
        served = [
            (consumer, bound.need)
            for consumer in self.steps.values()
            for bound in consumer.bindings
            if bound.source == step.id
        ]
        if not served:
            return []
        sources = {SRI} | {self.steps[b.source].node for b in step.bindings if b.source is not None}
        given = {  # the values the executor passes, by input name: which vertex's which offer
            b.need.name: (SRI if b.source is None else self.steps[b.source].node, b.edge.offer.name)
            for b in step.bindings
            if b.need.role == "input"
        }
        into = [
            self._best_from(self._goal_node(need) if consumer.id == 0 else consumer.node, need)
            for consumer, need in served
        ]
        found: list[tuple[tuple[Any, ...], str]] = []
        handled = self._handled(step.id) if self.areas is not None else frozenset()
        for iri in self.trace.levels:
            vertex = self.graph.vertices[iri]
            if iri == step.node or vertex.advertisement is None:
                continue
            feeds = []
            for best in into:
                edge = best.get(iri)
                if edge is None:
                    break
                feeds.append(edge.similarity)
            else:
                fed = all(self._fed(iri, need, sources, given) for need in vertex.needs)
                # it would get the same values, so handle the same things: it must be effective where they are
                fits = self.areas is None or self.areas.why_not(vertex.advertisement, handled) is None
                if fed and feeds and fits:
                    found.append(((-min(feeds), vertex.cost, iri), iri))
        return [iri for _, iri in sorted(found)]

    def _fed(self, iri: str, need: Need, sources: set[str], given: dict[str, tuple[str, str]]) -> bool:
        """Whether a would-be alternative gets ``need`` from the step as planned: an input by its name,
        the very value the step is given under that name (the executor passes the planned component's
        inputs as they are: InferObjectPlace's object is no position, however both come from the
        requirement), a precondition from any of the step's sources."""
        if need.role != "input":
            return any(e.source in sources for e in self.graph.providers(iri, need))
        origin = given.get(need.name)
        return origin is not None and any((e.source, e.offer.name) == origin for e in self.graph.providers(iri, need))

    def _best_from(self, target: str, need: Need) -> dict[str, Edge]:
        """Each provider's most similar edge into ``need`` of ``target`` (every step's alternatives ask)."""
        key = (target, need.key)
        best = self._best.get(key)
        if best is None:
            best = self._best[key] = {}
            for edge in self.graph.providers(target, need):  # most similar first
                best.setdefault(edge.source, edge)
        return best

    def _goal_node(self, need: Need) -> str:
        return SRO if need.role == "input" else SRE


def _restated(plan: Plan, index: TaxonomyIndex) -> tuple[Statement, int] | None:
    """The first delete effect the requirement wants that a step after the one it is bound to (or, held
    by the world, any step) makes true again, with that step's number: an effect of the same relation or
    one below it, between things as specific as the deleted statement's or more (the base driven to the
    person, for the base no longer by the person). A more general effect does not say it (the put-down's
    (PhysicalObject, isLocated, Place) does not put the pen back on the table the pick-up took it off), as a
    fact holds a goal only when it is at least as specific (docs/composition.md, "A goal that holds already")."""
    for goal in plan.goals:
        wanted = goal.statement
        if goal.role != "deletion" or wanted is None:
            continue
        after = goal.source.step or 0
        for step in plan.steps:
            if step.index > after and any(_restates(index, effect, wanted) for effect in step.effects):
                return wanted, step.index
    return None


def _restates(index: TaxonomyIndex, effect: Statement, deleted: Statement) -> bool:
    return all(
        index.is_a(mine, theirs)
        for mine, theirs in (
            (effect.subject, deleted.subject),
            (effect.predicate, deleted.predicate),
            (effect.object, deleted.object),
        )
    )


def _goal_text(need: Need) -> str:
    """A need of SRO or SRE as the requirement's goal: its output or effect."""
    return "the requirement's " + need.text().replace("precondition", "effect", 1).replace("input", "output", 1)


__all__ = ["Extraction", "Objective"]
