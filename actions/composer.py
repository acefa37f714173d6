"""Composition: from a task to a plan, through the service resource graph (paper section 4).

1. Build the SRG for the task's requirement and search it both ways (``search``).
2. Extract the plan backwards from SRO/SRE. Each need of a step is bound, in this order of
   preference, to: what the requirement supplies (SRI); for an input, the output of a *sibling*, a
   step created for the same consumer (a pre-service prepares data for that consumer, so it takes
   that consumer's context first: the path planner feeding "navigate to person" takes the person's
   position as its goal); otherwise a new step of the best qualified provider of a lower forward
   level (so the extraction cannot loop). "Best" is the highest similarity, then the lowest cost
   (``objective="similarity"``), or the other way round (``objective="cost"``).
3. Merge invocations of static-data and method components that have identical bindings.
4. Order the steps: a producer before its consumers, the action ontology's ordering constraints
   respected, each step as late as possible (right before the first step that uses it, so perceived
   data is fresh when it is used).
5. For every step, list the drop-in alternatives: components that accept the same bindings and meet
   the same needs (the executor fails over to them).
6. Check the plan by progression over its steps' add and delete effects (``actions.progression``): a
   statement a step or goal needs that an earlier step deleted is achieved again after it, by a new
   step, or the plan is refused naming it (``ComposeConfig.protect``).

When the requirement alone cannot be composed and its action class has KnowRob-style sub-actions,
each sub-action is composed in their partial order and the plans are concatenated ("decomposed"). A
plan joined from parts (these, or a requirement's goals planned one by one) is checked by progression as
it will run: a statement one part takes from the world that an earlier part deletes is achieved again
by composing that part once more without it, or the plan is refused naming it.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from enum import Enum
from functools import partial
from typing import TYPE_CHECKING, Any

import pyoxigraph as ox

from cbrs.actions.areas import AreaRule, Leads, WorldPlaces
from cbrs.actions.decomposition_notes import UnfollowedOrdering, decomposition_notes, unfollowed_ordering
from cbrs.actions.errors import OrderingConflictError
from cbrs.actions.extraction import THING, Extraction, Objective
from cbrs.actions.graph import (
    SRE,
    SRI,
    SRO,
    Matcher,
    ServicePool,
    ServiceResourceGraph,
    parameter_names,
    statement_text,
)
from cbrs.actions.model import ActionLibrary, Task, resolve_task
from cbrs.actions.named_things import AchievedGoal, Designations, NamedThings, WorldFact
from cbrs.actions.near_misses import NearMiss, near_misses
from cbrs.actions.plan import Binding, Plan, PlanStep, Source
from cbrs.actions.progression import Clobbered, consumed_goals, progress_parts
from cbrs.actions.search import SearchTrace, bidirectional_search
from cbrs.actions.undeclared_terms import described
from cbrs.actions.unmet import GOAL, Unsatisfied
from cbrs.kb import Advertisement, KnowledgeBase, Requirement, Statement
from cbrs.kb.namespaces import PREFIXES, GraphName, shorten
from cbrs.kb.shapes import nearest_term
from cbrs.reasoner.config import MatchConfig
from cbrs.reasoner.degrees import Degree, degree_of_match

if TYPE_CHECKING:
    from cbrs.reasoner.matchmaker import EntityPair, Matchmaker
from cbrs.reasoner.taxonomy import TaxonomyIndex

MAX_DEPTH = 4  # how many levels of sub-actions a task may be decomposed into
NEAR_MISS_NEEDS = 8  # how many needs of an unmet need's chain a "no plan" answer looks for near misses at

_AT_OR_BELOW = frozenset({Degree.EXACT, Degree.SUBCLASS_OF})
"""Degrees at which a fact is as specific as a goal, side by side (a subclass, a subproperty)."""


@dataclass(frozen=True)
class ComposeConfig:
    objective: Objective = Objective.SIMILARITY
    default_cost: float = 1.0  # seconds, for components that advertise no response time
    # objective "cost" ranks by the stated cbrs:cost (no unit, not seconds): None compares by it only when every
    # candidate states one, else by response time as before; a number is the cost of one that states none
    unstated_cost: float | None = None
    decompose: bool = True  # plan a task whose sub-actions are each stated as a requirement part by part
    # A step is one invocation, made per use; past this many steps, uses share an existing invocation
    # of the same component, so deep pools cannot make the plan grow exponentially.
    max_steps: int = 200
    match: MatchConfig = field(default_factory=MatchConfig)
    world_state: bool = True  # preconditions may be met by what holds in the map and belief graphs
    matched: bool = True  # when nothing composes, one advertisement the matchmaker accepts for the whole requirement
    # a step's component must be effective where the task's things it handles are (SEA; actions.areas)
    respect_area: bool = True
    # ... compared by their rooms when both name one; with area_boxes, by bounding boxes first (matchmaking's order)
    area_boxes: bool = False
    # a step given a value derived from a thing must be where the thing is when the value leads to it
    # (docs/composition.md): None reads which classes lead and which only inform from the store's
    # cbrs:areaRole marks (home.ttl marks home:InformationEntity, home:SpatialData, home:Feature); lists override
    area_informs: tuple[str, ...] | None = None
    area_leads: tuple[str, ...] | None = None
    # check each extracted plan, and each plan joined from parts, by progression over its add and delete
    # effects: a statement a step needs (or a goal) that an earlier step deletes is achieved again after
    # it, or the plan is refused naming it
    protect: bool = True
    max_reachieved: int = 8  # statements achieved again per extraction, and per joined plan, before refusing
    # a "no plan" answer names, per unmet need, at most this many components that come close: their output or
    # effect is a near concept of the need's (actions.near_misses; docs/composition.md); 0: none
    near_misses: int = 3
    # ... looked for at the unmet need and at each need above it on the chain the answer follows down (the
    # requirement's output a lab's sensor nearly gives), at most this many in all per unmet need
    near_misses_total: int = 6
    # an input of this class or below designates a thing: it takes only a value of the class the statements its
    # step is planned for name for it (the bell's home:Cup), or below (Extraction._things_wanted); None: any
    # value of the input's class (docs/composition.md, "The thing an input is for")
    thing_class: str | None = THING


class PlanStatus(Enum):
    PLANNED = "planned"
    UNSOLVABLE = "unsolvable"


@dataclass(frozen=True)
class Attempt:
    """One composition: its graph, the search, and the outcome."""

    requirement: Requirement
    graph: ServiceResourceGraph
    trace: SearchTrace
    plan: Plan | None
    unsatisfied: tuple[Unsatisfied, ...]


@dataclass(frozen=True)
class CompositionResult:
    task: str
    requirement: str
    status: PlanStatus
    plan: Plan | None
    unsatisfied: tuple[Unsatisfied, ...]
    # the direct attempt, then one per sub-action when decomposed; left out of the repr (each holds its graph
    # and search trace: 31,000 characters for an eight-step plan in a notebook cell)
    attempts: tuple[Attempt, ...] = field(repr=False)
    objective: Objective = Objective.SIMILARITY  # what ranked providers (each step's ranked_by says what decided)
    # what of the task's written decomposition composition does not follow, and why (actions.decomposition_notes)
    notes: tuple[str, ...] = ()

    @property
    def unused_inputs(self) -> tuple[tuple[str, str], ...]:
        """The (name, class) of inputs the task gives that no step of its plan takes: the plan does something
        other than asked with what it was given (a side table given as the destination, of a class no
        component takes for one, while the carry went to the object's own place). Empty for a plan with
        nothing to do, and for one decomposed into sub-actions, whose requirements give their own."""
        plan = self.plan
        if plan is None or not plan.steps or not self.attempts:
            return ()
        given = [b.source for step in plan.steps for b in step.bindings if b.source.step is None]
        if any(source.requirement != self.requirement for source in given):
            return ()
        used = {source.name for source in given}
        inputs = self.attempts[0].requirement.inputs
        named = zip(parameter_names(inputs), inputs, strict=True)
        return tuple((name, parameter.type) for name, parameter in named if name not in used)

    def to_dict(self) -> dict[str, Any]:
        found: dict[str, Any] = {"task": self.task, "requirement": self.requirement, "status": self.status.value}
        found["objective"] = self.objective.value
        if self.plan is not None:
            found.update(self.plan.to_dict())
            found["unused_inputs"] = [{"name": name, "type": type_} for name, type_ in self.unused_inputs]
        found["unsatisfied"] = [u.to_dict() for u in self.unsatisfied]
        found["notes"] = list(self.notes)
        return found


_Composed = tuple[Plan | None, tuple[Unsatisfied, ...], list[Attempt]]
"""A part's plan (None: none), why not, and the attempts made for it."""


@dataclass
class _Part:
    """One part of a joined plan: a sub-action or a goal, composed again without the statements an
    earlier part undoes (``undone``: those facts of the world and of its requirement are left out)."""

    label: str  # "sub-action act:X" or "goal 2 (...)", as reasons name it
    compose: Callable[[frozenset[Statement]], _Composed]
    plan: Plan
    undone: frozenset[Statement] = frozenset()


class Composer:
    """Plans tasks over the advertisements in a knowledge base."""

    def __init__(
        self,
        kb: KnowledgeBase,
        config: ComposeConfig | None = None,
        *,
        index: TaxonomyIndex | None = None,
        actions: ActionLibrary | None = None,
        advertisements: Sequence[Advertisement] | None = None,
    ) -> None:
        self.kb = kb
        self.config = config or ComposeConfig()
        self.index = index or TaxonomyIndex.from_kb(kb)
        self.matcher = Matcher(self.index, self.config.match)
        self.actions = actions or ActionLibrary.from_kb(kb)
        self._advertisements = list(advertisements) if advertisements is not None else None
        self._pool: ServicePool | None = None
        self._belief = False
        self._state: list[Statement] | None = None  # what holds, read once per compose
        self._facts: list[tuple[WorldFact, str]] | None = None  # ... between which things, in which graph
        self._lifted: dict[Statement, list[WorldFact]] = {}  # each statement held: the facts lifted to it
        self._designations: Designations | None = None  # the things inputs name, read once per compose (if needed)
        self._named: dict[tuple[object, ...], NamedThings] = {}  # by input classes, requester and goals
        self._places: WorldPlaces | None = None  # where things are, read once per compose (if needed)
        self._places_at: tuple[tuple[object, bool], WorldPlaces] | None = None  # and kept while the store is unchanged
        self._matchmaker: Matchmaker | None = None  # for _matched, made on first use
        self._roles: Leads | None = None  # area_roles, read on first use
        self._composing = False
        self._requirements: list[Requirement] | None = None  # every requirement, read once per compose

    @property
    def advertisements(self) -> list[Advertisement]:
        if self._advertisements is None:
            self._advertisements = self.kb.advertisements()
        return self._advertisements

    @property
    def pool(self) -> ServicePool:
        """The components and the edges among them, built on first use and kept (they do not depend
        on the requirement). Make a new Composer after registering or deregistering components."""
        if self._pool is None:
            config = self.config
            self._pool = ServicePool(self.advertisements, self.matcher, config.default_cost, config.unstated_cost)
        return self._pool

    def task(self, name: str) -> Task:
        return resolve_task(self.kb, self.actions, name, self.requirements)

    def graph(
        self,
        requirement: Requirement,
        undone: frozenset[Statement] = frozenset(),
        before: tuple[AchievedGoal, ...] = (),
    ) -> ServiceResourceGraph:
        """The SRG for ``requirement``, from what holds but for the facts that meet a statement of ``undone``
        (an earlier part of the plan deleted them: see :meth:`_joined`), and with ``before``, the goals an
        earlier part of the plan achieves (the sub-actions before it: :meth:`_decomposed`), each offered to
        the statements about the things it is about, as a world fact is."""
        holding = self._holding(undone) if self.config.world_state else []
        achieved: dict[Statement, list[AchievedGoal]] = {}
        for goal in before:
            achieved.setdefault(goal.statement, []).append(goal)
        holding += [s for s in achieved if s not in holding and not self._meets(s, undone)]
        admits = partial(self._admits, requirement, achieved=achieved)
        return ServiceResourceGraph(self._without(requirement, undone), self.pool, holding, admits)

    def _holding(self, undone: frozenset[Statement] = frozenset()) -> list[Statement]:
        """What holds (:meth:`world_state`), but for the facts that meet a statement of ``undone``."""
        return [fact for fact in self.world_state() if not self._meets(fact, undone)]

    def _without(self, requirement: Requirement, undone: frozenset[Statement]) -> Requirement:
        """``requirement`` without the preconditions that meet a statement of ``undone``."""
        if not undone:
            return requirement
        kept = tuple(p for p in requirement.preconditions if not self._meets(p, undone))
        return requirement if kept == requirement.preconditions else replace(requirement, preconditions=kept)

    def _meets(self, fact: Statement, undone: frozenset[Statement]) -> bool:
        return any(self.matcher.statement(needed, fact) is not None for needed in undone)

    def world_state(self) -> list[Statement]:
        """What holds, as statements between classes: in the semantic map, and in the belief state when
        composing for a run that has just perceived it (``compose(task, belief=True)``); a belief left by
        an earlier run is not the state of the next one."""
        if self._state is not None:  # composing: read once for all its attempts
            return self._state
        by_graph: dict[str, dict[Statement, None]] = {}
        for fact, graph in self._facts if self._facts is not None else self._world_facts():
            by_graph.setdefault(graph, {})[fact.statement] = None
        return [statement for held in by_graph.values() for statement in held]

    def world_facts(self) -> list[WorldFact]:
        """What holds between which things (:meth:`world_state` lifts each to their classes)."""
        return [fact for fact, _ in (self._facts if self._facts is not None else self._world_facts())]

    def _world_facts(self) -> list[tuple[WorldFact, str]]:
        graphs = [GraphName.MAP, GraphName.WORLD] if self._belief else [GraphName.MAP]
        return [
            (
                WorldFact(
                    Statement(row["subjectType"].value, row["relation"].value, row["objectType"].value),
                    row["subject"].value,
                    row["object"].value,
                ),
                graph.iri,
            )
            for graph in graphs
            for row in self.kb.select("world_state", {"graph": graph.iri})
        ]

    def named(self, requirement: Requirement) -> NamedThings:
        """The things ``requirement``'s inputs designate (``actions.named_things``), read once per composition."""
        inputs = tuple(p.type or "" for p in requirement.inputs)
        key = (inputs, requirement.requested_by, requirement.effects, requirement.deletes)
        if key not in self._named:
            if self._designations is None:
                self._designations = Designations(self.kb, self.index)
            self._named[key] = self._designations.named(requirement)
        return self._named[key]

    def _admits(
        self,
        requirement: Requirement,
        wanted: Statement,
        held: Statement,
        achieved: Mapping[Statement, list[AchievedGoal]] | None = None,
    ) -> bool:
        """Whether ``held``, a statement the world offers or an earlier part achieves (``achieved``) that meets
        ``wanted`` by its classes, is about the thing ``wanted`` concerns in ``requirement``
        (:class:`NamedThings`); one neither a fact of the world nor a part is behind (a subclass's
        assumption) meets it as its classes do."""
        facts, goals = self._lifted.get(held), (achieved or {}).get(held)
        if not facts and not goals:
            return True
        named = self.named(requirement)
        if facts and named.admits(wanted, facts):
            return True
        return any(named.meets_achieved(wanted, goal) for goal in goals or ())

    def compose(self, task: str | Task | Requirement, belief: bool = False) -> CompositionResult:
        """Plan ``task``; with ``belief``, from what the belief graph says holds now as well."""
        self._belief, self._state, self._places = belief, None, None
        self._composing, self._requirements = True, None
        try:
            self._facts = self._world_facts() if self.config.world_state else []
            for fact, _ in self._facts:
                self._lifted.setdefault(fact.statement, []).append(fact)
            self._state = self.world_state() if self.config.world_state else []
            return self._compose(task)
        finally:
            self._belief, self._state, self._places = False, None, None
            self._composing, self._requirements = False, None
            self._facts, self._lifted, self._designations, self._named = None, {}, None, {}

    def requirements(self) -> list[Requirement]:
        """Every requirement: read once per composition, for the task, its sub-actions and every attempt
        (as what holds is; a requirement registered meanwhile counts from the next composition, as a
        component does), else read each time."""
        if self._requirements is not None:
            return self._requirements
        found = self.kb.requirements()
        if self._composing:
            self._requirements = found
        return found

    def _compose(self, task: str | Task | Requirement) -> CompositionResult:
        if isinstance(task, str):
            task = self.task(task)
        elif isinstance(task, Requirement):
            task = Task(task.iri, task, self.actions.actions.get(task.for_task or ""))
        direct = self.attempt(task.requirement, task)
        unknown = [p for p in task.requirement.inputs if p.type and p.type not in self.index]
        # planned without the thing given, it would fetch some other (a marker); unplanned for want of the thing
        # the goal is about (Extraction._things_wanted), the input of no known class is why
        if unknown and (direct.plan is not None or any(u.things for u in direct.unsatisfied)):
            needs = tuple(Unsatisfied(f"input {p.name} ({shorten(p.type)})", SRI) for p in unknown)
            return self._result(task, None, needs, (replace(direct, plan=None, unsatisfied=needs),))
        holding = self._state if self._state is not None else []
        if self._achieved(task.requirement, holding):
            return self._result(task, _achieved_plan(task), (), (direct,))
        # A task its author split into sub-actions, each stated as a requirement, is planned part by part:
        # the author said how it decomposes (two cups, one after the other), which a direct plan may not
        # follow (it credited both cups' goals to one put-down). Without a plan that way, directly.
        result = self._decomposed(task, direct) if self._decomposable(task) else None
        if result is not None and result.plan is not None:
            return result
        found = self._undecomposed(task, direct, holding)
        if result is None:
            return found
        if found.plan is None:
            return result
        # planned otherwise than by its parts: say why, as for a decomposition written so it cannot be followed
        why = "; ".join(u.text() for u in result.unsatisfied) or "no plan"
        note = f"{shorten(task.name)} is not planned by its sub-actions, nor in their order: {why}"
        return replace(found, notes=(*found.notes, note))

    def _undecomposed(self, task: Task, direct: Attempt, holding: Sequence[Statement]) -> CompositionResult:
        """``task`` planned otherwise than by its sub-actions: whole, goal by goal, or matched to one component."""
        if direct.plan is not None and not task.requirement.outputs and _shared_goals(direct.plan, self.index):
            return self._per_goal(task, direct)  # (outputs are no goal's: a task asking for one stays whole)
        if direct.plan is None and not task.requirement.outputs and self._holds_some(task.requirement, holding):
            # a goal that holds already wants no step: planned whole, it was asked of the components, and
            # a goal nothing provides (a cup "on" a table) refused a task the world had half done
            return self._per_goal(task, direct)
        if direct.plan is not None:
            return self._result(task, direct.plan, direct.unsatisfied, (direct,))
        if self.config.matched:
            plan = self._matched(task)
            if plan is not None:
                return self._result(task, plan, (), (direct,))
        return self._result(task, None, direct.unsatisfied, (direct,))

    def _matched(self, task: Task) -> Plan | None:
        """The paper's own answer when no plan composes: one advertisement the matchmaker accepts for
        the whole requirement (Sem-Str, paper Table 3: the ceiling camera's RobotLocation for a robot
        asking its RobotPosition), run on its own, if the requirement gives each of its inputs and the
        requirement or the world its preconditions, and it states every effect the requirement wants."""
        from cbrs.reasoner.matchmaker import Matchmaker  # only when composition found nothing

        requirement = task.requirement
        if self._matchmaker is None:  # kept: it lays the advertisements out as arrays once
            self._matchmaker = Matchmaker(self.kb, index=self.index, advertisements=self.advertisements)
        ranking = self._matchmaker.rank(requirement, explain=5)
        offered = {ad.iri: ad for ad in self.advertisements}
        top_level = {p.type for p in requirement.outputs}
        for candidate in ranking.candidates[:5]:
            ad = offered.get(candidate.advertisement)
            if ad is None or not candidate.acceptable or candidate.lacks:
                continue
            # Every pair is-a related, except an output whose parts all are (the paper's Position for
            # Location): a concept with no matched parts and no is-a link is no match to act on.
            failed = [p for p in candidate.pairs if p.degree == "Fail"]
            parts = [
                p for p in candidate.pairs if p.role == "output" and p.degree != "Fail" and p.requested not in top_level
            ]
            if any(p.role != "output" or p.requested not in top_level for p in failed) or (failed and not parts):
                continue
            plan = self._single_step(task, requirement, ad, candidate.pairs, candidate.score)
            if plan is None:
                continue
            areas = self.area_rule(requirement)  # the matchmaker's filter compared its area with the task's only
            if areas is None or areas.why_not(ad, {b.source.name for b in plan.steps[0].inputs}) is None:
                return plan
        return None

    def _single_step(
        self, task: Task, requirement: Requirement, ad: Advertisement, pairs: Sequence[EntityPair], score: float
    ) -> Plan | None:
        """The plan of ``ad`` alone for ``requirement``, its inputs and outputs bound as the matchmaker paired
        them, each with the degree its explanation shows ("Similar" for a pair Sem-Str matched without an
        is-a link, the paper's Position for Location, not the logic's "Fail")."""
        threshold = (self._matchmaker.config if self._matchmaker is not None else MatchConfig()).pair_threshold
        bindings: list[Binding] = []
        requirement_inputs = list(zip(parameter_names(requirement.inputs), requirement.inputs, strict=True))
        for name, parameter in zip(parameter_names(ad.inputs), ad.inputs, strict=True):
            given = next((p for p in pairs if p.role == "input" and p.advertised == parameter.type), None)
            source = next((n for n, r in requirement_inputs if given is not None and r.type == given.requested), None)
            if given is None or source is None:
                return None
            bindings.append(
                Binding(
                    "input",
                    name,
                    Source(source, None, requirement.iri),
                    given.shown_degree(threshold),
                    given.similarity,
                    parameter.type,
                )
            )
        holding = [*requirement.preconditions, *(self.world_state() if self.config.world_state else [])]
        guaranteed = set(requirement.preconditions)
        for wanted in ad.preconditions:
            admitted = partial(self._given_or_admitted, requirement, guaranteed, wanted)
            bound = self._statement_binding(wanted, holding, lambda met: Source(met, None, requirement.iri), admitted)
            if bound is None:
                return None
            bindings.append(bound)
        goals: list[Binding] = []
        offered_outputs = list(zip(parameter_names(ad.outputs), ad.outputs, strict=True))
        for wanted_name, wanted_output in zip(parameter_names(requirement.outputs), requirement.outputs, strict=True):
            pair = next((p for p in pairs if p.role == "output" and p.requested == wanted_output.type), None)
            output = next((n for n, o in offered_outputs if pair is not None and o.type == pair.advertised), None)
            if pair is None or output is None:
                return None
            goals.append(
                Binding(
                    "input",
                    wanted_name,
                    Source(output, 1),
                    pair.shown_degree(threshold),
                    pair.similarity,
                    wanted_output.type,
                )
            )
        for effect in requirement.effects:
            bound = self._statement_binding(effect, ad.effects, lambda stated: Source(stated, 1))
            if bound is None:
                return None
            goals.append(bound)
        for gone in requirement.deletes:  # what is to stop being true: the component must delete it
            bound = self._statement_binding(gone, ad.deletes, lambda stated: Source(stated, 1))
            if bound is None:
                return None
            goals.append(replace(bound, role="deletion", name=f"not {bound.name}"))
        step = PlanStep(
            index=1,
            component=ad.iri,
            label=ad.label,
            kind=ad.kind,
            device=ad.device,
            action=ad.realizes_action,
            bindings=tuple(bindings),
            outputs=tuple((n, o.type) for n, o in offered_outputs),
            effects=ad.effects,
            deletes=ad.deletes,
            cost=self.pool.vertices[ad.iri].cost if ad.iri in self.pool.vertices else self.config.default_cost,
        )
        return Plan(task.name, requirement.iri, "matched", (step,), tuple(goals), score, step.cost)

    def _given_or_admitted(
        self, requirement: Requirement, given: set[Statement], wanted: Statement, held: Statement
    ) -> bool:
        """Whether ``held`` may meet ``wanted``: a precondition of ``requirement`` (``given``), or what holds in
        the world about the thing ``wanted`` concerns (:meth:`_admits`)."""
        return held in given or self._admits(requirement, wanted, held)

    def _statement_binding(
        self,
        wanted: Statement,
        offered: Sequence[Statement],
        source: Callable[[str], Source],
        admitted: Callable[[Statement], bool] | None = None,
    ) -> Binding | None:
        """A binding of ``wanted`` to the first of ``offered`` that meets it (and that ``admitted`` lets), or None."""
        for candidate in offered:
            match = self.matcher.statement(wanted, candidate)
            if match is not None and (admitted is None or admitted(candidate)):
                degree, similarity = match
                return Binding(
                    "precondition",
                    statement_text(wanted),
                    source(statement_text(candidate)),
                    degree.value,
                    similarity,
                    statement=wanted,
                )
        return None

    def _decomposable(self, task: Task) -> bool:
        """Whether every sub-action of the task is stated as a requirement of its own.

        A sub-action's requirement says what is given when that step starts (the tap, the region
        below it); an action's bare IOPE would take as given what the plan must still produce.
        """
        if not (self.config.decompose and task.action and task.action.sub_actions):
            return False
        stated = {r.for_task for r in self.requirements()}
        return all(sub in stated for sub in task.action.sub_actions)

    def attempt(
        self,
        requirement: Requirement,
        task: Task | None = None,
        undone: frozenset[Statement] = frozenset(),
        before: tuple[AchievedGoal, ...] = (),
    ) -> Attempt:
        """Compose ``requirement`` in one extraction; ``undone``: statements that do not hold when it starts,
        although the world or the requirement says so (an earlier part of the plan deleted them); ``before``:
        statements that hold when it starts, although the world does not say so (an earlier part achieves them)."""
        graph = self.graph(requirement, undone, before)
        trace = bidirectional_search(graph)
        areas = self.area_rule(requirement)
        config = self.config
        extraction = Extraction(
            graph,
            trace,
            config.objective,
            config.max_steps,
            areas,
            config.protect,
            config.max_reachieved,
            config.thing_class,
        )
        if not extraction.solved:
            return Attempt(requirement, graph, trace, None, tuple(extraction.unsatisfied))
        orderings = self._orderings(task)
        try:
            plan = extraction.plan(task.name if task else requirement.iri, self.index, orderings)
        except OrderingConflictError as error:  # no plan, and why: as every other task that cannot be planned
            assert task is not None and task.action is not None  # only a task's action class has orderings
            ordering = unfollowed_ordering(error, task.action.iri, self.actions.orderings_for(task.action.iri))
            return Attempt(requirement, graph, trace, None, (ordering,))
        return Attempt(requirement, graph, trace, plan, tuple(extraction.unsatisfied) if plan is None else ())

    def area_rule(self, requirement: Requirement) -> AreaRule | None:
        """The SEA rule for ``requirement``'s steps: where its things are (the belief's positions when
        composing for a run), and its own area; None when it is off or can refuse none of the components."""
        if not self.config.respect_area or not any(ad.area for ad in self.advertisements):
            return None
        world = self._places or self._world_places()
        if self._state is not None:  # composing: kept for its other attempts
            self._places = world
        places = world.locate(self.kb, self.index, requirement, parameter_names(requirement.inputs))
        rule = AreaRule(self.index, places, requirement.area, self.config.area_boxes, self.area_roles())
        return rule if rule.relevant(self.advertisements) else None

    def area_roles(self) -> Leads:
        """Which values given to a step lead it to their thing: the classes ``ComposeConfig.area_informs`` and
        ``area_leads`` list when set, else those the store marks with ``cbrs:areaRole``, read once, as the
        taxonomy index they are checked against is (a class marked later is not in that index either)."""
        if self._roles is None:
            informs, leads = self.config.area_informs, self.config.area_leads
            if informs is not None or leads is not None:
                self._roles = Leads.of(self.index, informs or (), leads or ())
            else:
                roles = {row["class"].value: row["role"].value for row in self.kb.select("area_roles")}
                self._roles = Leads(self.index, roles)
        return self._roles

    def _world_places(self) -> WorldPlaces:
        """Where things are, read again only when an embedded store has been written since (a remote
        store's writes are not counted: it is read for every composition)."""
        generation = getattr(self.kb.store, "generation", None)
        key = (generation, self._belief)
        if generation is not None and self._places_at is not None and self._places_at[0] == key:
            return self._places_at[1]
        world = WorldPlaces.read(self.kb, self.index, self._belief)
        if generation is not None:
            self._places_at = (key, world)
        return world

    def _orderings(self, task: Task | None) -> list[tuple[str, str, str]]:
        if task is None or task.action is None:
            return []
        return [(o.constraint, o.before, o.after) for o in self.actions.orderings_for(task.action.iri)]

    def _decomposed(
        self,
        task: Task,
        direct: Attempt,
        depth: int = 0,
        undone: frozenset[Statement] = frozenset(),
        before: tuple[AchievedGoal, ...] = (),
    ) -> CompositionResult:
        """Compose each sub-action on its own, in order, and join the plans (:meth:`_joined`), each from what
        holds with the goals of the sub-actions before it. A sub-action that is a task with sub-actions of its
        own is decomposed in turn (two-level tasks), at most ``MAX_DEPTH`` levels down; ``undone``: statements
        an earlier part of an enclosing plan deleted; ``before``: the goals of the enclosing plan's parts before it."""
        assert task.action is not None
        attempts = [direct]
        parts: list[_Part] = []
        holding = self._holding(undone) if self.config.world_state else []
        achieved: tuple[AchievedGoal, ...] = before  # the goals of the sub-actions before this one
        for sub in task.action.ordered_sub_actions():
            sub_task = resolve_task(self.kb, self.actions, sub, self.requirements)
            if self._achieved(sub_task.requirement, holding):
                continue  # its effects hold already (a re-plan keeps what the last plan achieved)
            # it starts where the sub-actions before it leave the world: their goals hold (the table set, the
            # dinner bell's precondition); composed from the world as the task starts, it planned them again
            compose = partial(self._sub_action, sub_task, depth, before=achieved)
            plan, unsatisfied, tried = compose(undone)
            attempts += tried
            if plan is None:
                unsatisfied = direct.unsatisfied + tuple(
                    replace(
                        u,
                        chain=(f"sub-action {shorten(sub)}", *u.chain[1:], shorten(u.consumer)),
                        undeclared=(),
                        near=(),
                    )
                    for u in unsatisfied
                )
                return self._result(task, None, unsatisfied, tuple(attempts))
            parts.append(_Part(f"sub-action {shorten(sub)}", compose, plan, undone))
            # each about the things the part names: the cup it keeps in a hand is not the pen a later part sets
            # down (a goal about no thing met every statement of its classes: the pen's put-down took the cup)
            named = self.named(sub_task.requirement)
            goals = (
                AchievedGoal(g, named.bound(g.subject), named.bound(g.object)) for g in sub_task.requirement.effects
            )
            achieved += tuple(goal for goal in goals if goal not in achieved)
        if not parts:  # every part is achieved: nothing to do but check
            return self._result(task, _achieved_plan(task), (), tuple(attempts))
        return self._joined(task, parts, attempts, holding)

    def _sub_action(
        self, sub_task: Task, depth: int, undone: frozenset[Statement], before: tuple[AchievedGoal, ...] = ()
    ) -> _Composed:
        """One sub-action's plan, from what holds with ``before`` (the goals of the parts before it): part by
        part when it is split into sub-actions each stated as a requirement, as a task is (:meth:`_compose`: a
        direct plan may not follow its author's parts, and credited the saucer's and the cup's goals to one
        put-down), else directly."""
        attempt = self.attempt(sub_task.requirement, sub_task, undone, before)
        tried = [attempt]
        plan, unsatisfied = attempt.plan, attempt.unsatisfied
        if depth < MAX_DEPTH and self._decomposable(sub_task):
            nested = self._decomposed(sub_task, attempt, depth + 1, undone, before)
            tried += nested.attempts[1:]
            if nested.plan is not None or plan is None:
                plan, unsatisfied = nested.plan, nested.unsatisfied or unsatisfied
        return plan, unsatisfied, tried

    def _per_goal(self, task: Task, direct: Attempt) -> CompositionResult:
        """Plan each goal on its own, in the requirement's order, and join the plans (:meth:`_joined`): the
        direct plan credited one step's effect with goals about different things (the cup on the tray and
        the remote on its spot, both to one put-down), and one step moves one thing. Each goal's part takes
        the inputs of its own things (a class at or below the goal's subject or object) and those of no
        goal's (the robot's), so the cup's part fetches the cup. A goal that holds already is a part of no
        step, after the others: the world meets it, the runner checks it at the end, and a part before it
        that undoes it has it achieved again or the plan refused (:meth:`_joined`)."""
        requirement = task.requirement
        goals = requirement.effects
        attempts = [direct]
        parts: list[_Part] = []
        held: list[_Part] = []
        holding = self._state if self._state is not None else []
        for n, goal in enumerate(goals, start=1):
            others = [g for g in goals if g != goal]
            inputs = tuple(
                p
                for p in requirement.inputs
                if self._about(p.type, goal) or not any(self._about(p.type, other) for other in others)
            )
            part = replace(requirement, inputs=inputs, outputs=(), effects=(goal,), deletes=())
            sub_task = Task(f"{task.name}/goal{n}", part, None)
            compose = partial(self._goal_part, sub_task)
            if self._achieved(part, holding):
                held.append(_Part(f"goal {n} {statement_text(goal)}", compose, _achieved_plan(sub_task)))
                continue
            plan, unsatisfied, tried = compose(frozenset())
            attempts += tried
            if plan is None:
                unsatisfied = tuple(
                    replace(u, chain=(f"goal {n} {statement_text(goal)}", *u.chain[1:]), undeclared=(), near=())
                    for u in unsatisfied
                )
                return self._result(task, None, unsatisfied, tuple(attempts))
            parts.append(_Part(f"goal {n} {statement_text(goal)}", compose, plan))
        for n, deleted in enumerate(requirement.deletes, start=len(goals) + 1):  # after the goals' parts
            part = replace(requirement, outputs=(), effects=(), deletes=(deleted,))
            sub_task = Task(f"{task.name}/goal{n}", part, None)
            compose = partial(self._goal_part, sub_task)
            label = f"goal {n} not {statement_text(deleted)}"
            if self._achieved(part, holding):
                held.append(_Part(label, compose, _achieved_plan(sub_task)))
                continue
            plan, unsatisfied, tried = compose(frozenset())
            attempts += tried
            if plan is None:
                unsatisfied = tuple(
                    replace(u, chain=(label, *u.chain[1:]), undeclared=(), near=()) for u in unsatisfied
                )
                return self._result(task, None, unsatisfied, tuple(attempts))
            parts.append(_Part(label, compose, plan))
        if not parts:
            return self._result(task, _achieved_plan(task), (), tuple(attempts))
        return self._joined(task, parts + held, attempts, holding)

    def _goal_part(self, sub_task: Task, undone: frozenset[Statement]) -> _Composed:
        attempt = self.attempt(sub_task.requirement, sub_task, undone)
        return attempt.plan, attempt.unsatisfied, [attempt]

    def _joined(
        self, task: Task, parts: list[_Part], attempts: list[Attempt], holding: Sequence[Statement]
    ) -> CompositionResult:
        """The parts' plans concatenated, checked by progression as they will run, part after part from
        ``holding`` and the task's preconditions (``ComposeConfig.protect``). Each part was checked on its
        own, from what holds when the whole plan starts; a statement a later part took from the world (or
        from its requirement) that an earlier part deletes is achieved again by composing that part once
        more without it, so a step of its own provides it, at most ``max_reachieved`` times; else the plan
        is refused naming the statement, the step that needs it and the step that deletes it."""
        initial = [*task.requirement.preconditions, *holding]
        achieved_again = 0
        while True:
            plan = _concatenate(task, [part.plan for part in parts])
            undone = self._undone_between(parts, initial) if self.config.protect else None
            if undone is None:
                consumed = consumed_goals([part.plan for part in parts], initial, self.matcher)
                goals = tuple(g for g, gone in zip(plan.goals, consumed, strict=True) if not gone)
                return self._result(task, replace(plan, goals=goals), (), tuple(attempts))
            part = parts[undone.part]
            exhausted = achieved_again >= self.config.max_reachieved
            again: Plan | None = None
            if not exhausted:
                again, _, tried = part.compose(part.undone | {undone.statement})
                attempts += tried
            if again is None or again == part.plan:
                refusal = _deleted_between(plan, part, undone, exhausted)
                return self._result(task, None, (refusal,), tuple(attempts))
            part.plan, part.undone = again, part.undone | {undone.statement}
            achieved_again += 1

    def _undone_between(self, parts: Sequence[_Part], initial: Sequence[Statement]) -> Clobbered | None:
        """The first statement a part needs that an earlier part deleted, in the joined plan's numbering.
        A statement undone within one part is that part's extraction's to achieve again."""
        ends: list[int] = []  # the joined plan's index of each part's last step
        for part in parts:
            ends.append((ends[-1] if ends else 0) + len(part.plan.steps))
        for found in progress_parts([part.plan for part in parts], initial, self.matcher):
            if found.deleter is not None and next(n for n, end in enumerate(ends) if found.deleter <= end) < found.part:
                return found
        return None

    def _about(self, concept: str | None, goal: Statement) -> bool:
        """Whether an input of class ``concept`` names a thing of ``goal``: at or below its subject or object."""
        if not concept:
            return False
        return any(degree_of_match(self.index, side, concept) in _AT_OR_BELOW for side in (goal.subject, goal.object))

    def _achieved(self, requirement: Requirement, holding: Sequence[Statement]) -> bool:
        """Whether a sub-task is done: it wants effects only, and each holds in the world now. A fact holds
        a goal when it is as specific on every side (the remote on a side table holds "on a table"), not
        when it is more general: a remote on the kitchen table, a home:Table, is not on a lab:SideTable,
        although the two would match as services do (a superclass is an accepted degree there)."""
        if requirement.outputs or not (requirement.effects or requirement.deletes):
            return False
        held = partial(self._held, requirement, holding=holding)
        gone = not any(held(d) for d in requirement.deletes)  # what is to stop being true is not
        return gone and all(held(e) for e in requirement.effects)

    def _holds_some(self, requirement: Requirement, holding: Sequence[Statement]) -> bool:
        """Whether some of the requirement's goals hold already (all of them: :meth:`_achieved`)."""
        held = partial(self._held, requirement, holding=holding)
        return any(held(e) for e in requirement.effects) or any(not held(d) for d in requirement.deletes)

    def _held(self, requirement: Requirement, goal: Statement, holding: Sequence[Statement]) -> bool:
        """Whether a fact of ``holding`` holds ``goal`` of ``requirement``: as specific on every side, and about
        the things the requirement names where the goal concerns them (:meth:`_admits`)."""
        return any(self._entails(fact, goal) and self._admits(requirement, goal, fact) for fact in holding)

    def _entails(self, fact: Statement, goal: Statement) -> bool:
        sides = ((goal.subject, fact.subject), (goal.predicate, fact.predicate), (goal.object, fact.object))
        return all(degree_of_match(self.index, wanted, held) in _AT_OR_BELOW for wanted, held in sides)

    def _result(
        self, task: Task, plan: Plan | None, unsatisfied: tuple[Unsatisfied, ...], attempts: tuple[Attempt, ...]
    ) -> CompositionResult:
        status = PlanStatus.PLANNED if plan is not None else PlanStatus.UNSOLVABLE
        if plan is None:
            unsatisfied = tuple(
                self._near_missed(self._of_the_world(task.requirement, self._undeclared(task.requirement, u)), attempts)
                for u in unsatisfied
            )
        stated = (r.for_task for r in self.requirements() if r.for_task)
        notes = decomposition_notes(task.action, self.actions, stated) if self.config.decompose else ()
        return CompositionResult(
            task.name, task.requirement.iri, status, plan, unsatisfied, attempts, self.config.objective, notes
        )

    def _of_the_world(self, requirement: Requirement, unsatisfied: Unsatisfied) -> Unsatisfied:
        """``unsatisfied`` marked when it is an output the task asks for whose class is a kind of physical
        thing (a cup): no component gives cups, but the store says which there are (eighth round, "which
        cups are in the kitchen?" written as a task)."""
        if unsatisfied.consumer != SRO:
            return unsatisfied
        physical = PREFIXES["home"] + "PhysicalObject"
        for output in requirement.outputs:
            concept = output.type
            if (
                concept
                and concept in self.index
                and physical in self.index.is_a_ancestors(concept)
                and unsatisfied.need.endswith(f"({shorten(concept)})")
            ):
                return replace(unsatisfied, world_things=True)
        return unsatisfied

    def _undeclared(self, requirement: Requirement, unsatisfied: Unsatisfied) -> Unsatisfied:
        """``unsatisfied`` with the classes of the requirement it names that the ontology lacks (a task
        about a home:Frisbee nobody declared): the likeliest reason nothing provides it."""
        named = {p.type for p in (*requirement.inputs, *requirement.outputs)}
        predicates = set()
        for statement in (*requirement.preconditions, *requirement.effects, *requirement.deletes):
            named |= {statement.subject, statement.object, statement.predicate}
            predicates.add(statement.predicate)
        given = {p.type for p in requirement.inputs}  # an input of no known class feeds no component at all
        missing = tuple(
            sorted(
                c
                for c in named
                if c
                and c not in self.index
                and (c in given or re.search(rf"\b{re.escape(shorten(c))}\b", unsatisfied.need))
            )
        )
        if not missing:
            return unsatisfied
        near = tuple(
            (c, found)
            for c in missing  # a property by the did-you-mean's spelling only: home:isOn is no slip of home:isNear
            if (found := nearest_term(c, self.index.nodes(), 0.75 if c in predicates else 0.6)) is not None
        )
        properties = tuple(c for c in missing if c in predicates)
        reason = replace(unsatisfied, undeclared=missing, near=near, properties=properties)
        return described(reason, requirement, self.index, self.kb, self.advertisements)  # a thing, or a new class

    def _near_missed(self, unsatisfied: Unsatisfied, attempts: Sequence[Attempt]) -> Unsatisfied:
        """``unsatisfied`` with the components that come close to meeting it (:mod:`actions.near_misses`),
        in the attempt that found it unmet: those that attempt's search enabled and its area rule admits."""
        u = unsatisfied
        if self.config.near_misses <= 0 or u.cycle or u.deleted_by or u.consumer in (SRI, GOAL):
            return u
        if isinstance(u, UnfollowedOrdering):  # every need was met: the order is what cannot be
            return u
        for attempt in attempts:
            if all((u.need, u.consumer) != (found.need, found.consumer) for found in attempt.unsatisfied):
                continue
            graph = attempt.graph
            need = next((n for n in graph.needs(u.consumer) if n.text() == u.need), None)
            if need is None:
                continue
            named = {c for c, _ in (*u.out_of_area, *u.unrunnable)}  # (what they provide about it: said again)
            refused = partial(_refused, self.area_rule(attempt.requirement), graph)
            found: list[NearMiss] = []
            # the need reported, the requirement's own, then those between, nearest first: a chain can be
            # thousands of needs long, so at most NEAR_MISS_NEEDS of them are asked
            above = [*u.along[:1], *reversed(u.along[1:])]
            for consumer, text in [(u.consumer, u.need), *above][:NEAR_MISS_NEEDS]:
                wanted = need if consumer == u.consumer and text == u.need else None
                wanted = wanted or next((n for n in graph.needs(consumer) if n.text() == text), None)
                room = min(self.config.near_misses, self.config.near_misses_total - len(found))
                if room <= 0:
                    break
                if wanted is None:
                    continue
                skip = named | {m.component for m in found}
                more = near_misses(graph, consumer, wanted, attempt.trace.enabled, refused, skip, room)
                found += [m if consumer == u.consumer else replace(m, consumer=consumer) for m in more]
            return replace(u, near_misses=tuple(found)) if found else u
        return u


def store_plan(kb: KnowledgeBase, plan: Plan) -> None:
    """Write ``plan`` to the plans graph, replacing an earlier plan for the same task, in one transaction."""
    graph = GraphName.PLANS.node
    old = [
        q
        for q in kb.store.quads(graph=graph)
        if isinstance(q.subject, ox.NamedNode)
        and (q.subject.value == plan.iri or q.subject.value.startswith(plan.iri + "/"))
    ]
    kb.store.replace(old, plan.to_quads())


def _refused(areas: AreaRule | None, graph: ServiceResourceGraph, component: str, things: Iterable[str]) -> bool:
    """Whether ``areas`` refuses ``component`` for a step handling the requirement inputs ``things``."""
    return areas is not None and areas.why_not(graph.vertices[component].advertisement, things) is not None


def _shared_goals(plan: Plan, index: TaxonomyIndex) -> list[tuple[Binding, Binding]]:
    """Pairs of goals the plan credits to the same effect of the same step although they are about
    different things: subjects of classes neither of which is the other's (a Cup, a RemoteControl)."""
    shared = []
    goals = [g for g in plan.goals if g.source.step is not None and g.statement is not None]
    for i, first in enumerate(goals):
        for second in goals[i + 1 :]:
            if (first.source.step, first.source.name) != (second.source.step, second.source.name):
                continue
            assert first.statement is not None and second.statement is not None
            a, b = first.statement.subject, second.statement.subject
            if degree_of_match(index, a, b) is Degree.FAIL:
                shared.append((first, second))
    return shared


def _achieved_plan(task: Task) -> Plan:
    """The plan of a task whose every effect holds already: no step, and its goals met by the world
    (the runner still checks them). Planning towards them moved what was where it should be: the cup
    asked to stand on the table top was picked up and carried to the table's centre, out of reach."""
    requirement = task.requirement
    goals = tuple(
        Binding(
            "precondition", statement_text(effect), Source("world", None, requirement.iri), "Exact", 1.0, None, effect
        )
        for effect in requirement.effects
    ) + tuple(
        Binding(
            "deletion", f"not {statement_text(gone)}", Source("world", None, requirement.iri), "Exact", 1.0, None, gone
        )
        for gone in requirement.deletes
    )
    return Plan(task.name, requirement.iri, "achieved", (), goals, 1.0, 0.0)


def _deleted_between(plan: Plan, part: _Part, undone: Clobbered, exhausted: bool) -> Unsatisfied:
    """The reason a joined ``plan`` is refused: ``undone``, a statement ``part`` needs, deleted by a step of
    an earlier part, that composing the part again without it could not provide (``exhausted``: each
    part composed again undid another statement, ``max_reachieved`` times)."""
    assert undone.deleter is not None
    need = f"precondition {statement_text(undone.statement)}"
    if undone.consumer is None:  # a goal of the part, needed when the part ends
        return Unsatisfied(need, SRE, (part.label,), exhausted, deleted_by=(plan.step(undone.deleter).component,))
    consumer = plan.step(undone.consumer).component
    chain = (part.label, shorten(consumer))
    return Unsatisfied(need, consumer, chain, exhausted, deleted_by=(plan.step(undone.deleter).component,))


def _concatenate(task: Task, plans: list[Plan]) -> Plan:
    """One plan from the sub-action plans, renumbered, each step marked with its sub-action."""
    steps: list[PlanStep] = []
    goals: list[Binding] = []
    for plan in plans:
        offset = len(steps)
        # a precondition a part took as holding because a part before it achieves it: from that part's step
        achieved = {f"holds {g.name}": g.source for g in goals if g.source.step is not None}
        for step in plan.steps:
            bindings = tuple(
                replace(b, source=achieved[b.source.name])
                if b.source.step is None and b.role == "precondition" and b.source.name in achieved
                else _shift(b, offset)
                for b in step.bindings
            )
            steps.append(
                PlanStep(
                    index=step.index + offset,
                    component=step.component,
                    label=step.label,
                    kind=step.kind,
                    device=step.device,
                    action=step.action,
                    bindings=bindings,
                    outputs=step.outputs,
                    effects=step.effects,
                    cost=step.cost,
                    part_of=step.part_of or plan.task,
                    alternatives=step.alternatives,
                    deletes=step.deletes,
                    ranked_by=step.ranked_by,
                )
            )
        goals += [_shift(g, offset) for g in plan.goals]
    everything = [b for s in steps for b in s.bindings] + goals
    similarity = sum(b.similarity for b in everything) / len(everything) if everything else 0.0
    return Plan(
        task.name,
        task.requirement.iri,
        "decomposed",
        tuple(steps),
        tuple(goals),
        similarity,
        sum(s.cost for s in steps),
        tuple(p.task for p in plans),
    )


def _shift(binding: Binding, offset: int) -> Binding:
    if binding.source.step is None:
        return binding
    source = Source(binding.source.name, binding.source.step + offset)
    return Binding(
        binding.role, binding.name, source, binding.degree, binding.similarity, binding.concept, binding.statement
    )


__all__ = ["ComposeConfig", "Composer", "CompositionResult", "Objective", "PlanStatus", "Unsatisfied", "store_plan"]
