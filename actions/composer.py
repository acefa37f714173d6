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

When the requirement alone cannot be composed and its action class has KnowRob-style sub-actions,
each sub-action is composed in their partial order and the plans are concatenated ("decomposed").
"""

from __future__ import annotations

import re
from collections import deque
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from enum import Enum
from typing import TYPE_CHECKING, Any

import networkx as nx
import pyoxigraph as ox

from cbrs.actions.areas import AreaRule, WorldPlaces
from cbrs.actions.errors import OrderingConflictError
from cbrs.actions.graph import (
    SRE,
    SRI,
    SRO,
    Edge,
    Matcher,
    Need,
    ServicePool,
    ServiceResourceGraph,
    parameter_names,
    statement_text,
)
from cbrs.actions.model import ActionLibrary, Task, resolve_task
from cbrs.actions.plan import Binding, Plan, PlanStep, Source
from cbrs.actions.search import SearchTrace, bidirectional_search
from cbrs.kb import Advertisement, KnowledgeBase, Requirement, Statement
from cbrs.kb.namespaces import GraphName, shorten
from cbrs.kb.shapes import nearest_term
from cbrs.reasoner.config import MatchConfig
from cbrs.reasoner.degrees import Degree, degree_of_match

if TYPE_CHECKING:
    from cbrs.reasoner.matchmaker import EntityPair, Matchmaker
from cbrs.reasoner.taxonomy import TaxonomyIndex

GOAL = "GOAL"  # the extraction's virtual consumer: SRO's and SRE's needs together
MAX_DEPTH = 4  # how many levels of sub-actions a task may be decomposed into

_AT_OR_BELOW = frozenset({Degree.EXACT, Degree.SUBCLASS_OF})
"""Degrees at which a fact is as specific as a goal, side by side (a subclass, a subproperty)."""


class Objective(Enum):
    SIMILARITY = "similarity"  # highest similarity first, cost breaks ties
    COST = "cost"  # lowest cost first, similarity breaks ties


@dataclass(frozen=True)
class ComposeConfig:
    objective: Objective = Objective.SIMILARITY
    default_cost: float = 1.0  # seconds, for components that advertise no response time
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


class PlanStatus(Enum):
    PLANNED = "planned"
    UNSOLVABLE = "unsolvable"


@dataclass(frozen=True)
class Unsatisfied:
    """A need no qualified vertex meets, and the chain of needs that led to it."""

    need: str
    consumer: str
    chain: tuple[str, ...] = ()  # from the requirement's goal down to this need
    cycle: bool = False  # providers exist, but each needs (through others) what this need blocks
    undeclared: tuple[str, ...] = ()  # classes the need names that the ontology does not have
    near: tuple[tuple[str, str], ...] = ()  # (undeclared class, the declared class its name is closest to)
    unrunnable: tuple[tuple[str, str], ...] = ()  # (component, why): planned for it, but cannot run here
    out_of_area: tuple[tuple[str, str], ...] = ()  # (component, why): provides it, but not where it is needed

    def text(self) -> str:
        found = self._text()
        for component, why in self.out_of_area:
            found += f"; {shorten(component)} was passed over: {why}"
        for component, why in self.unrunnable:
            found += f"; {shorten(component)} was planned for it but cannot run here: {why}"
        return found

    def _text(self) -> str:
        consumer = "the requirement" if self.consumer in (SRO, SRE, GOAL) else shorten(self.consumer)
        via = f" (on the way to {' <- '.join(self.chain)})" if len(self.chain) > 1 else ""
        need = self.need
        if self.consumer == SRE and need.startswith("precondition "):  # the goal is the end's precondition
            need = "effect " + need.removeprefix("precondition ")
        if self.cycle:
            return f"only a cycle of components provides {need} of {consumer}{via}"
        if self.consumer == SRI:  # the task gives it: nothing to provide, but its class is unknown
            return f"the requirement gives {need}; {self.remedy()}"
        if self.out_of_area:
            return f"no component effective where it is needed provides {need} of {consumer}{via}; {self.remedy()}"
        return f"no component provides {need} of {consumer}{via}; {self.remedy()}"

    def remedy(self) -> str:
        """What to register or state so that this need is met (first, a class to declare: no component
        can be matched against a class the ontology does not have)."""
        if self.undeclared:
            names = ", ".join(shorten(c) for c in self.undeclared)
            example = shorten(self.undeclared[0])
            meant = "; ".join(f"{shorten(typed)}: did you mean {shorten(known)}?" for typed, known in self.near)
            return (
                f"{names} {'is no class' if len(self.undeclared) == 1 else 'are no classes'} of the ontology"
                f"{f' ({meant})' if meant else ''}: "
                f"declare {'it' if len(self.undeclared) == 1 else 'them'} under a class the components know "
                f"(e.g. {example} rdfs:subClassOf home:PersonalItem, loaded into the ontology graph), "
                f"or {self._remedy()}"
            )
        return self._remedy()

    def _remedy(self) -> str:
        if self.out_of_area:
            return (
                "register a component that provides it whose effective area (cbrs:hasSEAModel) covers the things "
                "named, or compose without the area rule (ComposeConfig.respect_area)"
            )
        if self.consumer == SRI:
            return "correct the input's cbrs:parameterType"
        if self.consumer == GOAL:  # the task states nothing to plan towards
            return (
                "state what the task wants as an output (cbrs:hasOutput) or an effect (cbrs:hasEffect): "
                "composition plans towards those; delete effects alone are no goal it plans for"
            )
        if self.need.startswith("precondition "):
            statement = self.need.removeprefix("precondition ")
            return (
                f"register a component whose effect is {statement}, or state it as a precondition of the task "
                "or a fact of the semantic map"
            )
        concept = self.need.rsplit("(", 1)[-1].rstrip(")") if "(" in self.need else self.need
        return f"register a component whose output is a {concept}, or give one as an input of the task"

    def to_dict(self) -> dict[str, Any]:
        return {
            "need": self.need,
            "consumer": self.consumer,
            "chain": list(self.chain),
            "cycle": self.cycle,
            "text": self.text(),
            "remedy": self.remedy(),
            "unrunnable": [{"component": component, "why": why} for component, why in self.unrunnable],
            "out_of_area": [{"component": component, "why": why} for component, why in self.out_of_area],
        }


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
    attempts: tuple[Attempt, ...]  # the direct attempt, then one per sub-action when decomposed

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
        if self.plan is not None:
            found.update(self.plan.to_dict())
            found["unused_inputs"] = [{"name": name, "type": type_} for name, type_ in self.unused_inputs]
        found["unsatisfied"] = [u.to_dict() for u in self.unsatisfied]
        return found


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
        self._places: WorldPlaces | None = None  # where things are, read once per compose (if needed)
        self._places_at: tuple[tuple[object, bool], WorldPlaces] | None = None  # and kept while the store is unchanged
        self._matchmaker: Matchmaker | None = None  # for _matched, made on first use

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
            self._pool = ServicePool(self.advertisements, self.matcher, self.config.default_cost)
        return self._pool

    def task(self, name: str) -> Task:
        return resolve_task(self.kb, self.actions, name)

    def graph(self, requirement: Requirement) -> ServiceResourceGraph:
        holding = self.world_state() if self.config.world_state else ()
        return ServiceResourceGraph(requirement, self.pool, holding)

    def world_state(self) -> list[Statement]:
        """What holds, as statements between classes: in the semantic map, and in the belief state when
        composing for a run that has just perceived it (``compose(task, belief=True)``); a belief left by
        an earlier run is not the state of the next one."""
        if self._state is not None:  # composing: read once for all its attempts
            return self._state
        graphs = [GraphName.MAP, GraphName.WORLD] if self._belief else [GraphName.MAP]
        return [
            Statement(row["subjectType"].value, row["relation"].value, row["objectType"].value)
            for graph in graphs
            for row in self.kb.select("world_state", {"graph": graph.iri})
        ]

    def compose(self, task: str | Task | Requirement, belief: bool = False) -> CompositionResult:
        """Plan ``task``; with ``belief``, from what the belief graph says holds now as well."""
        self._belief, self._state, self._places = belief, None, None
        try:
            self._state = self.world_state() if self.config.world_state else []
            return self._compose(task)
        finally:
            self._belief, self._state, self._places = False, None, None

    def _compose(self, task: str | Task | Requirement) -> CompositionResult:
        if isinstance(task, str):
            task = self.task(task)
        elif isinstance(task, Requirement):
            task = Task(task.iri, task, self.actions.actions.get(task.for_task or ""))
        direct = self.attempt(task.requirement, task)
        unknown = [p for p in task.requirement.inputs if p.type and p.type not in self.index]
        if unknown and direct.plan is not None:  # planned without the thing given: it fetches some other (a marker)
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
        if direct.plan is not None and not task.requirement.outputs and _shared_goals(direct.plan, self.index):
            return self._per_goal(task, direct)  # (outputs are no goal's: a task asking for one stays whole)
        if direct.plan is not None:
            return self._result(task, direct.plan, direct.unsatisfied, (direct,))
        if self.config.matched:
            plan = self._matched(task)
            if plan is not None:
                return self._result(task, plan, (), (direct,))
        return result or self._result(task, None, direct.unsatisfied, (direct,))

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
        """The plan of ``ad`` alone for ``requirement``, its inputs and outputs bound as the matchmaker paired them."""
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
                    given.degree,
                    given.similarity,
                    parameter.type,
                )
            )
        holding = [*requirement.preconditions, *(self.world_state() if self.config.world_state else [])]
        for wanted in ad.preconditions:
            bound = self._statement_binding(wanted, holding, lambda met: Source(met, None, requirement.iri))
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
                    pair.degree,
                    pair.similarity,
                    wanted_output.type,
                )
            )
        for effect in requirement.effects:
            bound = self._statement_binding(effect, ad.effects, lambda stated: Source(stated, 1))
            if bound is None:
                return None
            goals.append(bound)
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
            cost=self.pool.vertices[ad.iri].cost if ad.iri in self.pool.vertices else self.config.default_cost,
        )
        return Plan(task.name, requirement.iri, "matched", (step,), tuple(goals), score, step.cost)

    def _statement_binding(
        self, wanted: Statement, offered: Sequence[Statement], source: Callable[[str], Source]
    ) -> Binding | None:
        """A binding of ``wanted`` to the first of ``offered`` that meets it, or None."""
        for candidate in offered:
            match = self.matcher.statement(wanted, candidate)
            if match is not None:
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
        stated = {r.for_task for r in self.kb.requirements()}
        return all(sub in stated for sub in task.action.sub_actions)

    def attempt(self, requirement: Requirement, task: Task | None = None) -> Attempt:
        graph = self.graph(requirement)
        trace = bidirectional_search(graph)
        areas = self.area_rule(requirement)
        extraction = _Extraction(graph, trace, self.config.objective, self.config.max_steps, areas)
        if not extraction.solved:
            return Attempt(requirement, graph, trace, None, tuple(extraction.unsatisfied))
        orderings = self._orderings(task)
        plan = extraction.plan(task.name if task else requirement.iri, self.index, orderings)
        return Attempt(requirement, graph, trace, plan, ())

    def area_rule(self, requirement: Requirement) -> AreaRule | None:
        """The SEA rule for ``requirement``'s steps: where its things are (the belief's positions when
        composing for a run), and its own area; None when it is off or can refuse none of the components."""
        if not self.config.respect_area or not any(ad.area for ad in self.advertisements):
            return None
        world = self._places or self._world_places()
        if self._state is not None:  # composing: kept for its other attempts
            self._places = world
        places = world.locate(self.kb, self.index, requirement, parameter_names(requirement.inputs))
        rule = AreaRule(self.index, places, requirement.area, self.config.area_boxes)
        return rule if rule.relevant(self.advertisements) else None

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

    def _decomposed(self, task: Task, direct: Attempt, depth: int = 0) -> CompositionResult:
        """Compose each sub-action on its own, in order, and concatenate the plans. A sub-action that
        is a task with sub-actions of its own is decomposed in turn (two-level tasks), at most
        ``MAX_DEPTH`` levels down."""
        assert task.action is not None
        attempts = [direct]
        plans: list[Plan] = []
        holding = self.world_state() if self.config.world_state else []
        for sub in task.action.ordered_sub_actions():
            sub_task = resolve_task(self.kb, self.actions, sub)
            if self._achieved(sub_task.requirement, holding):
                continue  # its effects hold already (a re-plan keeps what the last plan achieved)
            attempt = self.attempt(sub_task.requirement, sub_task)
            attempts.append(attempt)
            plan = attempt.plan
            unsatisfied = attempt.unsatisfied
            if plan is None and depth < MAX_DEPTH and self._decomposable(sub_task):
                nested = self._decomposed(sub_task, attempt, depth + 1)
                attempts += nested.attempts[1:]
                plan, unsatisfied = nested.plan, nested.unsatisfied or unsatisfied
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
            plans.append(plan)
        if not plans:  # every part is achieved: nothing to do but check
            return self._result(task, _achieved_plan(task), (), tuple(attempts))
        return self._result(task, _concatenate(task, plans), (), tuple(attempts))

    def _per_goal(self, task: Task, direct: Attempt) -> CompositionResult:
        """Plan each goal on its own, in the requirement's order, and concatenate the plans: the direct
        plan credited one step's effect with goals about different things (the cup on the tray and the
        remote on its spot, both to one put-down), and one step moves one thing. Each goal's part takes
        the inputs of its own things (a class at or below the goal's subject or object) and those of no
        goal's (the robot's), so the cup's part fetches the cup; a goal that holds already is skipped."""
        requirement = task.requirement
        goals = requirement.effects
        attempts = [direct]
        plans: list[Plan] = []
        holding = self._state if self._state is not None else []
        for n, goal in enumerate(goals, start=1):
            others = [g for g in goals if g != goal]
            inputs = tuple(
                p
                for p in requirement.inputs
                if self._about(p.type, goal) or not any(self._about(p.type, other) for other in others)
            )
            part = replace(requirement, inputs=inputs, outputs=(), effects=(goal,))
            if self._achieved(part, holding):
                continue
            sub_task = Task(f"{task.name}/goal{n}", part, None)
            attempt = self.attempt(part, sub_task)
            attempts.append(attempt)
            if attempt.plan is None:
                unsatisfied = tuple(
                    replace(u, chain=(f"goal {n} {statement_text(goal)}", *u.chain[1:]), undeclared=(), near=())
                    for u in attempt.unsatisfied
                )
                return self._result(task, None, unsatisfied, tuple(attempts))
            plans.append(attempt.plan)
        if not plans:
            return self._result(task, _achieved_plan(task), (), tuple(attempts))
        return self._result(task, _concatenate(task, plans), (), tuple(attempts))

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
        if requirement.outputs or not requirement.effects:
            return False
        return all(any(self._entails(h, e) for h in holding) for e in requirement.effects)

    def _entails(self, fact: Statement, goal: Statement) -> bool:
        sides = ((goal.subject, fact.subject), (goal.predicate, fact.predicate), (goal.object, fact.object))
        return all(degree_of_match(self.index, wanted, held) in _AT_OR_BELOW for wanted, held in sides)

    def _result(
        self, task: Task, plan: Plan | None, unsatisfied: tuple[Unsatisfied, ...], attempts: tuple[Attempt, ...]
    ) -> CompositionResult:
        status = PlanStatus.PLANNED if plan is not None else PlanStatus.UNSOLVABLE
        if plan is None:
            unsatisfied = tuple(self._undeclared(task.requirement, u) for u in unsatisfied)
        return CompositionResult(task.name, task.requirement.iri, status, plan, unsatisfied, attempts)

    def _undeclared(self, requirement: Requirement, unsatisfied: Unsatisfied) -> Unsatisfied:
        """``unsatisfied`` with the classes of the requirement it names that the ontology lacks (a task
        about a home:Frisbee nobody declared): the likeliest reason nothing provides it."""
        named = {p.type for p in (*requirement.inputs, *requirement.outputs)}
        for statement in (*requirement.preconditions, *requirement.effects):
            named |= {statement.subject, statement.object}
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
        near = tuple((c, found) for c in missing if (found := nearest_term(c, self.index.nodes(), 0.6)) is not None)
        return replace(unsatisfied, undeclared=missing, near=near)


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


# -- extraction ------------------------------------------------------------------------------------


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


@dataclass(frozen=True)
class _Judged:
    """What a component would handle as a new step (requirement input names), and why it cannot (None: it can)."""

    things: frozenset[str]
    why: str | None
    blocked: Need | None = None  # the need none of whose providers can serve (else its own area is the why)


class _Extraction:
    """Backward extraction of one plan from a searched SRG."""

    def __init__(
        self,
        graph: ServiceResourceGraph,
        trace: SearchTrace,
        objective: Objective,
        max_steps: int,
        areas: AreaRule | None = None,
    ) -> None:
        self.graph = graph
        self.trace = trace
        self.objective = objective
        self.max_steps = max_steps
        self.areas = areas
        self._judged: dict[tuple[str, tuple[str, ...]], _Judged] = {}  # see _judge
        self._things: dict[int, frozenset[str]] = {}  # see _handled
        self._explained: set[str] = set()  # vertices whose blocked needs _why has followed
        self._best: dict[tuple[str, str], dict[str, Edge]] = {}  # see _best_from
        self.steps: dict[int, _Step] = {}
        self.unsatisfied: list[Unsatisfied] = []
        goal_needs = [(SRO, n) for n in graph.needs(SRO)] + [(SRE, n) for n in graph.needs(SRE)]
        if not goal_needs:
            self.unsatisfied.append(Unsatisfied("an output or effect", GOAL, ("the requirement states none",)))
            return
        self._goal_needs = goal_needs
        self._goal_concepts = {
            c for _, n in goal_needs if n.statement is not None for c in (n.statement.subject, n.statement.object)
        }
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
        self._expand()
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
        on_path: set[str] = set()
        stack: list[tuple[str, Need] | None] = [(node, need)]  # None: back up from the last provider followed
        while stack:
            item = stack.pop()
            if item is None:
                on_path.discard(followed.pop())
                continue
            node, need = item
            providers = [e for e in self.graph.providers(node, need) if e.source != node]
            if not providers:
                causes.append(Unsatisfied(need.text(), node, self._chain(chain, followed)))
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
                causes.append(Unsatisfied(need.text(), node, self._chain(chain, followed)))
                continue
            followed.append(best.source)
            on_path.add(best.source)
            stack.append(None)
            stack.extend((best.source, sub) for sub in reversed(blocked))
        return causes

    @staticmethod
    def _chain(start: tuple[str, ...], followed: list[str]) -> tuple[str, ...]:
        return (*start, *map(shorten, followed))

    def _key(self, edge: Edge) -> tuple[Any, ...]:
        cost = self.trace.costs[edge.source]
        level = self.trace.levels[edge.source]
        if self.objective is Objective.COST:
            return (round(cost, 9), -round(edge.similarity, 9), level, edge.source, edge.offer.name)
        return (-round(edge.similarity, 9), round(cost, 9), level, edge.source, edge.offer.name)

    def _new(self, node: str, made_for: int | None) -> _Step:
        step = _Step(len(self.steps), node, made_for)
        self.steps[step.id] = step
        return step

    def _expand(self) -> None:
        goal = self._new(GOAL, None)
        queue: deque[int] = deque([goal.id])
        while queue:
            step = self.steps[queue.popleft()]
            needs = self._goal_needs if step.node == GOAL else [(step.node, n) for n in self.graph.needs(step.node)]
            # pre-actions (P-E) first, then pre-services (I-O), as in the paper's backward search
            needs.sort(key=lambda item: item[1].role != "precondition")
            below = 10**9 if step.node == GOAL else self.trace.levels[step.node]
            for node, need in needs:
                options = self._options(node, need, below)
                given = [e for e in options if e.source == SRI]
                if given and len(given) < len(options):
                    # another goal's thing (the tray the cup goes to) is no value for the steps of this
                    # one (where the base parks to load the pen), which have a provider of their own
                    given = [e for e in given if not self._foreign(step, e)]
                if given:
                    step.bindings.append(
                        _Bound(need, min(given, key=lambda e: (self._aboutness(step, e), *self._key(e))), None)
                    )
                    continue
                mine = [(e, p) for p in step.producers for e in options if e.source == self.steps[p].node]
                if mine:  # a step already made for this consumer meets this need too
                    edge, producer_id = min(mine, key=lambda item: (self._key(item[0]), item[1]))
                    step.bindings.append(_Bound(need, edge, producer_id))
                    continue
                sibling = self._sibling(step, node, need)
                if sibling is not None:
                    step.bindings.append(sibling)
                    continue
                served = (need.statement.subject, need.statement.object) if need.statement is not None else ()
                about = (*served, *step.about)
                candidates = [e for e in options if e.source != SRI]
                if self.areas is not None:
                    fit = [e for e in candidates if self._judge(e.source, about).why is None]
                    if not fit:
                        self._pass_over(step, node, need, candidates, about)
                        continue
                    candidates = fit
                best = min(candidates, key=self._key)
                if len(self.steps) > self.max_steps:
                    existing = next((other for other in self.steps.values() if other.node == best.source), None)
                    if existing is not None:
                        step.bindings.append(_Bound(need, best, existing.id))
                        continue
                producer = self._new(best.source, step.id)
                producer.about = about
                step.producers.append(producer.id)
                step.bindings.append(_Bound(need, best, producer.id))
                queue.append(producer.id)

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

    def _sibling(self, step: _Step, node: str, need: Need) -> _Bound | None:
        """An output of a step made for the same consumer, if one meets this input."""
        if need.role != "input" or step.made_for is None:
            return None
        level = self.trace.levels[step.node]
        found: list[tuple[tuple[Any, ...], _Bound]] = []
        for other_id in self.steps[step.made_for].producers:
            other = self.steps[other_id]
            if other.id == step.id or self.trace.levels[other.node] >= level:
                continue
            for edge in self.graph.providers(node, need):
                if edge.source == other.node and edge.offer.role == "output":
                    found.append(((-edge.similarity, other.id, edge.offer.name), _Bound(need, edge, other.id)))
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
            given = [e for e in options if e.source == SRI]
            if given and len(given) < len(options):
                given = [e for e in given if not self._foreign(probe, e)]
            chosen = min(given, key=lambda e: (self._aboutness(probe, e), *self._key(e))) if given else None
            served = (need.statement.subject, need.statement.object) if need.statement is not None else ()
            ways.append((need, chosen, (*served, *about), [e for e in options if e.source != SRI]))
        return ways

    def _judge_now(self, vertex: str, about: tuple[str, ...]) -> _Judged:
        """``_judge`` once every provider of ``vertex``'s needs has been judged."""
        assert self.areas is not None
        things: set[str] = set()
        for need, given, below, providers in self._ways(vertex, about):
            if given is not None:
                if need.role == "input":
                    things.add(given.offer.name)
                continue
            fit = [e for e in providers if self._judged[(e.source, below)].why is None]
            if not fit:
                why = f"no provider of its {need.text()} is effective where it is needed"
                return _Judged(frozenset(things), why, need)
            if need.role == "input":
                things |= self._judged[(min(fit, key=self._key).source, below)].things
        why_not = self.areas.why_not(self.graph.vertices[vertex].advertisement, things)
        return _Judged(frozenset(things), why_not)

    def _pass_over(self, step: _Step, node: str, need: Need, candidates: list[Edge], about: tuple[str, ...]) -> None:
        """``need`` of ``step`` has providers, none of which can serve: an unmet need naming each and why.
        While every one fails only for want of a provider of its own, the best is followed down (as ``_why``
        does), so the report names the components whose areas do not cover the things."""
        chain = self._path(step, need)
        while True:
            judged = {e.source: self._judge(e.source, about) for e in sorted(candidates, key=self._key)}
            best = next(iter(judged))
            lower = judged[best].blocked
            if lower is None or any(j.blocked is None for j in judged.values()):
                break
            served = (lower.statement.subject, lower.statement.object) if lower.statement is not None else ()
            deeper = [e for e in self._options(best, lower, self._level(best)) if e.source != SRI]
            if not deeper:
                break
            node, need, about, candidates = best, lower, (*served, *about), deeper
            chain = (*chain, shorten(node))
        passed = tuple(sorted((iri, j.why or "") for iri, j in judged.items()))
        self.unsatisfied.append(Unsatisfied(need.text(), node, chain, out_of_area=passed))

    def _check_areas(self) -> None:
        """Refuse the plan if a step's component is not effective where the things it handles are: the
        choice predicted them, and a step given an existing step's value may handle others."""
        assert self.areas is not None
        for step in sorted(self.steps.values(), key=lambda s: s.id):
            if step.made_for is None:
                continue
            why = self.areas.why_not(self.graph.vertices[step.node].advertisement, self._handled(step.id))
            if why is None:
                continue
            consumer = self.steps[step.made_for]
            bound = next(b for b in consumer.bindings if b.source == step.id)
            node = self._goal_node(bound.need) if consumer.node == GOAL else consumer.node
            chain = self._path(consumer, bound.need)
            self.unsatisfied.append(Unsatisfied(bound.need.text(), node, chain, out_of_area=((step.node, why),)))

    def _handled(self, step_id: int) -> frozenset[str]:
        """The requirement inputs whose things ``step_id`` handles: those it is given, directly or through
        the steps that feed its inputs (on a stack of its own: a plan can be thousands of steps deep)."""
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

    def plan(self, task: str, index: TaxonomyIndex, orderings: list[tuple[str, str, str]]) -> Plan:
        self._merge_shared()
        order = self._order(index, orderings)
        number = {step_id: n for n, step_id in enumerate(order, start=1)}
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
                )
            )
        goals = tuple(self._binding(b, number, requirement.iri) for b in self.steps[0].bindings)
        everything = [b for s in steps for b in s.bindings] + list(goals)
        similarity = sum(b.similarity for b in everything) / len(everything)
        return Plan(task, requirement.iri, "direct", tuple(steps), goals, similarity, sum(s.cost for s in steps))

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
            firsts = [s for s, a in actions.items() if _is_a(index, a, before)]
            seconds = [s for s, a in actions.items() if _is_a(index, a, after)]
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
        left, and execution's verification catches it."""
        deleting = {
            s.id: ad.deletes
            for s in self.steps.values()
            if s.id != 0 and (ad := self.graph.vertices[s.node].advertisement) is not None and ad.deletes
        }
        for consumer in sorted(self.steps.values(), key=lambda s: s.id):
            for bound in consumer.bindings:
                needed = bound.need.statement
                if needed is None:
                    continue
                for threat, deletes in sorted(deleting.items()):
                    if threat in (consumer.id, bound.source) or not any(
                        _threatens(index, deleted, needed) for deleted in deletes
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


def _goal_text(need: Need) -> str:
    """A need of SRO or SRE as the requirement's goal: its output or effect."""
    return "the requirement's " + need.text().replace("precondition", "effect", 1).replace("input", "output", 1)


def _is_a(index: TaxonomyIndex, concept: str, ancestor: str) -> bool:
    if concept == ancestor:
        return True
    return concept in index and ancestor in index and index.canonical(ancestor) in index.is_a_ancestors(concept)


def _threatens(index: TaxonomyIndex, deleted: Statement, needed: Statement) -> bool:
    """Whether deleting ``deleted`` may falsify ``needed``: the same relation, between things of which
    one is a kind of the other on both ends."""
    if deleted.predicate != needed.predicate:
        return False
    return all(
        _is_a(index, a, b) or _is_a(index, b, a)
        for a, b in ((deleted.subject, needed.subject), (deleted.object, needed.object))
    )


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
        Binding("precondition", f"goal{n}", Source("world", None, requirement.iri), "Exact", 1.0, None, effect)
        for n, effect in enumerate(requirement.effects, start=1)
    )
    return Plan(task.name, requirement.iri, "achieved", (), goals, 1.0, 0.0)


def _concatenate(task: Task, plans: list[Plan]) -> Plan:
    """One plan from the sub-action plans, renumbered, each step marked with its sub-action."""
    steps: list[PlanStep] = []
    goals: list[Binding] = []
    for plan in plans:
        offset = len(steps)
        for step in plan.steps:
            steps.append(
                PlanStep(
                    index=step.index + offset,
                    component=step.component,
                    label=step.label,
                    kind=step.kind,
                    device=step.device,
                    action=step.action,
                    bindings=tuple(_shift(b, offset) for b in step.bindings),
                    outputs=step.outputs,
                    effects=step.effects,
                    cost=step.cost,
                    part_of=step.part_of or plan.task,
                    alternatives=step.alternatives,
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
