"""Plan, then execute: what ``cbrs run`` and the task services do, for any environment.

An ``Environment`` provides the component implementations, the values the task gives (the world's
cup, pen, person), the effect verifier, observations for the belief state, and a clock. The
simulation provides one (``sim.components``); tests provide stubs.
"""

from __future__ import annotations

import collections.abc
import contextlib
import json
import time
from collections.abc import Callable, Collection, Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, replace
from typing import Any, Protocol

from cbrs.actions.base_choice import (
    BaseChoice,
    BaseTies,
    MapDrives,
    choose_base,
    named_base,
    on_behalf,
    stated_costs,
)
from cbrs.actions.belief import BeliefState, Observation
from cbrs.actions.components import Container, Registry
from cbrs.actions.composer import ComposeConfig, Composer, CompositionResult, Objective, PlanStatus, store_plan
from cbrs.actions.errors import UngroundedGoalError
from cbrs.actions.events import Event, EventBus
from cbrs.actions.executor import ExecutionReport, Executor, RunStatus
from cbrs.actions.faults import Combined, FaultPolicy, FixedFaults
from cbrs.actions.graph import parameter_names, statement_text
from cbrs.actions.model import ActionLibrary
from cbrs.actions.plan import Plan, PlanStep
from cbrs.actions.precondition_sensing import PreconditionSensing, SensingConfig
from cbrs.actions.replanning import Failure, FailureMemory, ReplanPolicy
from cbrs.actions.task_preconditions import PreconditionCheck, check_preconditions
from cbrs.actions.unavailable import name_unavailable, would_serve
from cbrs.kb import Advertisement, KnowledgeBase, NotFoundError, Requirement, Statement
from cbrs.kb.namespaces import HOME, shorten
from cbrs.kb.semantic_map import AmbiguousDesignatorError, UnresolvedDesignatorError
from cbrs.kb.stated_quantities import StatedQuantities, guaranteed_statuses
from cbrs.kb.store import Term
from cbrs.reasoner.taxonomy import ROOT, TaxonomyIndex


class Environment(Protocol):
    registry: Registry
    context: Any

    def given(self, plan: Plan, requirements: Mapping[str, Requirement]) -> dict[str, Any]:
        """Values for the inputs the task's requirement(s) give, by parameter name."""

    def verify(self, step: PlanStep | None, statement: Statement, outputs: Mapping[str, Any]) -> bool | None:
        """Whether ``statement`` holds now in the environment; ``step`` None for a goal no step made (it
        held when the run started), which is about the things the task gives."""

    def observe(self) -> Observation:
        """The belief state to write to the world graph now."""

    def clock(self) -> float:
        """Seconds on the environment's clock (simulated time)."""

    # Optional: ``starting(step, known)`` (``executor.StepStart``), called before each step starts with
    # the inputs of every step known by then, for an environment that looks ahead (where a hold ends);
    # ``succeeded(step, component)`` (``executor.StepDone``), called when a step succeeded, for an
    # environment that keeps beliefs no sense can check (a door a remote motor opened); ``passed_over()``,
    # the components to compose without now, with why (remote ones whose calls timed out);
    # ``unimplemented(advertisements)``, why it has no implementation of some of them, where it knows
    # better than "no skill for its service" (a camera the simulated home lacks); ``holds(statement)``,
    # whether a statement about the task's things holds now by its tests, believing nothing (None: no test
    # decides it), asked of the task's own preconditions before the first step (actions.task_preconditions).


@dataclass(frozen=True)
class Replan:
    """A plan that was given up: what it was, how its execution went, and why it was replaced."""

    plan: Plan
    report: ExecutionReport
    reason: str
    failures: tuple[Failure, ...] = ()  # the failed step's attempts, as the re-planning memory keys them
    avoided: tuple[str, ...] = ()  # components the next plan was composed without (failed, nothing changed)
    passed_over: tuple[tuple[str, str], ...] = ()  # (component, why) the plan was composed without

    def to_dict(self) -> dict[str, Any]:
        return {
            "plan": {**self.plan.to_dict(), "passed_over": _passed_dicts(self.passed_over)},
            "execution": self.report.to_dict(),
            "reason": self.reason,
            "failures": [failure.to_dict() for failure in self.failures],
            "avoided": list(self.avoided),
        }


@dataclass(frozen=True)
class GoalCheck:
    """One goal of the task at the end of a run: what the robots believe, and what really holds (None
    where the environment cannot tell)."""

    statement: Statement
    believed: bool | None
    holds: bool | None
    deleted: bool = False  # a delete effect the task wants: the goal is that the statement no longer holds

    def text(self) -> str:
        return f"not {statement_text(self.statement)}" if self.deleted else statement_text(self.statement)

    def to_dict(self) -> dict[str, Any]:
        found = {"statement": self.text(), "believed": self.believed, "holds": self.holds}
        return {**found, "deleted": True} if self.deleted else found


@dataclass(frozen=True)
class Answer:
    """One output the task's requirement asks for, as the run found it: the requirement's name and class
    for it, the value (the JSON a component gives, ``docs/values.md``) and the step and component that
    gave it under the name ``output``. ``value`` is None when that component gave nothing by that name."""

    name: str
    concept: str | None
    value: Any
    step: int
    component: str
    output: str

    def text(self, width: int = 160) -> str:
        """One line: ``roomTemperature (home:RoomTemperature) = {"celsius": 21.5} from svc:...``; the value
        as compact JSON without the ``@type`` the class already says, numbers to a millimetre or a
        millisecond, cut at ``width`` characters (``to_dict`` keeps it whole and exact)."""
        what = f"{self.name} ({shorten(self.concept)})" if self.concept else self.name
        source = f"from {shorten(self.component)} (step {self.step})"
        if self.value is None:
            return f"{what}: no value; {shorten(self.component)} gave none named {self.output!r} (step {self.step})"
        shown = _compact(self.value, self.concept)
        if len(shown) > width:
            shown = f"{shown[: width - 1]}\u2026 ({len(shown)} characters in all)"
        return f"{what} = {shown} {source}"

    def to_dict(self) -> dict[str, Any]:
        return {
            "name": self.name,
            "class": self.concept,
            "value": _plain(self.value),
            "step": self.step,
            "component": self.component,
            "output": self.output,
            "text": self.text(),
        }


@dataclass(frozen=True)
class RunResult:
    """How a run went, as plain data: what a script reads (``succeeded``, ``answers``, ``goals``) and what
    ``cbrs run --json`` and the server's runs print (``to_dict``), so the three cannot disagree."""

    composition: CompositionResult  # the last composition: of the plan that ran last, or the one that failed
    report: ExecutionReport | None  # the last plan's execution; None when there was no plan to run
    replans: tuple[Replan, ...] = ()  # the plans replaced before it, in order
    goals: tuple[GoalCheck, ...] = ()  # the task's effects at the end, believed and in the world
    stopped: str = ""  # why re-planning stopped before its budget: the next plan would repeat a failure
    passed_over: tuple[tuple[str, str], ...] = ()  # (component, why) the last composition was made without
    base: BaseChoice | None = None  # in a home of several mobile bases, the one the plans work and why
    preconditions: tuple[PreconditionCheck, ...] = ()  # the task's own, before its first step (None: unchecked)

    @property
    def succeeded(self) -> bool:
        """The run succeeded: every step did and verified its effects on the robots' belief, and no
        goal is known not to hold in the world."""
        return self.executed and not self.refuted

    @property
    def executed(self) -> bool:
        """The executor finished the plan (by the robots' belief)."""
        return self.report is not None and self.report.status is RunStatus.SUCCEEDED

    @property
    def refuted(self) -> tuple[GoalCheck, ...]:
        """The goals the world contradicts (the robots may believe them)."""
        return tuple(goal for goal in self.goals if goal.holds is False)

    @property
    def answers(self) -> tuple[Answer, ...]:
        """The requirement's outputs the last plan's steps gave, in the plan's order: what a task that asks
        a question (a room's temperature, where the robot is) asked for. An output whose step did not
        succeed has none; a sub-action's output (a decomposed task's cup position) is none, nor is one
        the requirement gives itself."""
        plan = self.composition.plan
        if plan is None or self.report is None or not self.composition.attempts:
            return ()
        outputs = self.composition.attempts[0].requirement.outputs  # the task's own requirement
        asked = {(name, p.type) for name, p in zip(parameter_names(outputs), outputs, strict=True)}
        found = []
        for goal in plan.goals:
            step = goal.source.step
            if goal.statement is not None or step is None or step not in self.report.outputs:
                continue
            if (goal.name, goal.concept) not in asked:
                continue
            component = next((s.component for s in self.report.steps if s.index == step), plan.step(step).component)
            value = self.report.outputs[step].get(goal.source.name)
            found.append(Answer(goal.name, goal.concept, value, step, component, goal.source.name))
        return tuple(found)

    @property
    def unused_inputs(self) -> tuple[tuple[str, str], ...]:
        """The (name, class) of the task's inputs no plan of the run took (docs/composition.md). A re-plan,
        composed from what held (the eraser on the shelf), needs no more what an earlier plan did with it;
        the last composition's own list named it (docs/tasks.md, "A sixth round")."""
        requirement = self.composition.requirement
        taken = {
            binding.source.name
            for replan in self.replans
            for step in replan.plan.steps
            for binding in step.bindings
            if binding.source.step is None and binding.source.requirement == requirement
        }
        return tuple((name, type_) for name, type_ in self.composition.unused_inputs if name not in taken)

    def to_dict(self) -> dict[str, Any]:
        status = self.report.status.value if self.report else PlanStatus.UNSOLVABLE.value
        if self.executed and self.refuted:
            status = RunStatus.FAILED.value
        plan = {**self.composition.to_dict(), "passed_over": _passed_dicts(self.passed_over)}
        if "unused_inputs" in plan:  # those no plan of the run took, not the last plan's alone
            plan["unused_inputs"] = [{"name": name, "type": type_} for name, type_ in self.unused_inputs]
        found: dict[str, Any] = {"task": self.composition.task, "status": status, "plan": plan}
        if self.report is not None:
            found["execution"] = self.report.to_dict()
        found["replans"] = [replan.to_dict() for replan in self.replans]
        if self.stopped:
            found["stopped"] = self.stopped
        found["goals"] = [goal.to_dict() for goal in self.goals]
        found["answers"] = [answer.to_dict() for answer in self.answers]
        if self.base is not None:
            found["base"] = self.base.to_dict()
        if self.preconditions:  # the task's own, how each stood before the first step (believed None: unchecked)
            found["preconditions"] = [check.to_dict() for check in self.preconditions]
        return found


def _plain(value: Any) -> Any:
    """``value`` as JSON can carry it: as it is (the values between steps are JSON), else its ``repr``
    (a component in this process may give a Python object)."""
    try:
        json.dumps(value, allow_nan=False)
    except (TypeError, ValueError):
        return repr(value)
    return value


def _compact(value: Any, concept: str | None) -> str:
    """``value`` as one line of JSON for a person: without an ``@type`` equal to ``concept``, another
    one prefixed (``home:RobotLocation``)."""
    if isinstance(value, dict) and isinstance(value.get("@type"), str):
        kind = value["@type"]
        value = {key: item for key, item in value.items() if key != "@type"}
        if not concept or kind not in (concept, shorten(concept)):
            value = {"@type": shorten(kind), **value}
    return json.dumps(_rounded(_plain(value)), separators=(", ", ": "), ensure_ascii=False)


def _rounded(value: Any) -> Any:
    if isinstance(value, float):
        return round(value, 3) if abs(value) >= 1e-3 else float(f"{value:.3g}")
    if isinstance(value, dict):
        return {key: _rounded(item) for key, item in value.items()}
    if isinstance(value, list):
        return [_rounded(item) for item in value]
    return value


def run_task(
    kb: KnowledgeBase,
    task: str,
    environment: Environment,
    faults: Iterable[str] = (),
    composer: Composer | None = None,
    on_event: Callable[[Event], None] | None = None,
    max_ticks: int = 100_000,
    fault_policy: FaultPolicy | None = None,
    max_replans: int = 2,
    cancelled: Callable[[], bool] | None = None,
    replan_policy: ReplanPolicy | None = None,
    base_ties: BaseTies = BaseTies.NEAREST,
    objective: Objective | None = None,
    sensing: SensingConfig | None = None,
) -> RunResult:
    """Perceive, compose ``task`` from what holds now, run it in ``environment``, keep the world graph current.

    When a plan fails (a step failed or its effect was not reached, and no alternative was left) the
    world is perceived again and the task composed afresh from the current belief, with the components
    registered since: what is achieved is kept, since the belief offers it to the new plan's
    preconditions. At most ``max_replans`` times; each replaced plan is kept in the result with its
    reason. ``faults`` fail whenever invoked; ``fault_policy`` (e.g. ``RandomFaults``) may break others.
    ``cancelled`` is asked before the first step and whenever a step's attempt ends, succeeded or failed:
    once it says True the run stops there (status cancelled), with no alternative tried and no re-plan. A
    step under way is not cut short, but for a remote call out: that is asked every tick (and between a
    tick's short waits), and abandoned at once, what it would set made unknown and its answer dropped
    (``RemoteComponent.halt``).
    ``replan_policy`` says what a re-plan does about a failure nothing has changed since (the same
    component, inputs and kind of failure, with the things it depended on believed where they were):
    compose without its component first, and repeat it at most ``max_repeats`` times, else stop with
    ``RunResult.stopped`` saying why (``actions.replanning``). ``base_ties``: in a home of several mobile
    bases, how plans of one cost and similarity for different bases are told apart (``actions.base_choice``).
    ``objective``: what ranks the components that could do a step (``ComposeConfig.objective``), for a
    script that gives no ``composer``; a composer's own config says it, and a different one is refused.
    ``sensing``: whether a precondition on a measured state is asked of a sensor before the first step, and
    its timeout (``actions.precondition_sensing``); None: as the settings say.
    """
    if composer is not None and objective is not None and objective is not composer.config.objective:
        mine = composer.config.objective.value
        raise ValueError(f"objective {objective.value!r}: the composer given ranks by {mine!r}; give one or the other")
    composer = composer or Composer(kb, ComposeConfig(objective=objective or Objective.SIMILARITY))
    bus = EventBus()
    if on_event is not None:
        bus.subscribe("*", on_event)
    failing = FixedFaults.of(faults)
    policy = failing if fault_policy is None else Combined((failing, fault_policy))
    container = Container(environment.registry, environment.context, bus, policy, stopping=cancelled)
    belief = BeliefState(kb)
    _perceive(environment)
    before = belief.snapshot()
    seen = environment.observe()
    belief.write(seen)  # plan from what holds now, not from a past run's belief
    composition = composer.compose(task, belief=True)
    config = composer.config
    composition, chosen = _one_base(kb, config, task, composition, environment, bus, frozenset(), base_ties)
    passed = _passed_over(environment, bus, {})
    why_not = _why_not(environment)
    left_out = chosen.left_out if chosen is not None else frozenset()
    composition = _runnable(
        kb, config, task, composition, environment.registry, left_out, passed=passed, why_not=why_not
    )
    if composition.plan is None:
        belief.restore(before)  # nothing can be done and nothing was: the store is left as it was
        return RunResult(composition, None, passed_over=_pairs(passed), base=chosen)
    try:
        _check_grounded(kb, composer.index, composition.plan)
    except (UngroundedGoalError, UnresolvedDesignatorError):
        belief.restore(before)
        raise
    replans: list[Replan] = []
    memory = FailureMemory(replan_policy or ReplanPolicy())

    def compose(avoid: frozenset[str]) -> CompositionResult:
        """A fresh composition from the belief, without ``avoid``, what the environment cannot run and what
        it passes over now; with the base the first plan chose (``_kept_base``), else one base chosen now."""
        nonlocal passed, chosen
        passed = _passed_over(environment, bus, passed)
        if chosen is not None:
            avoid = avoid | _kept_base(environment, chosen)
            again = _compose(kb, config, task, avoid)
        else:
            again, chosen = _one_base(
                kb, config, task, _compose(kb, config, task, avoid), environment, bus, avoid, base_ties
            )
            avoid = avoid | (chosen.left_out if chosen is not None else frozenset())
        return _runnable(kb, config, task, again, environment.registry, avoid, passed, why_not=why_not)

    stopped = ""
    composed_without = _pairs(passed)
    report: ExecutionReport | None = None
    outputs: Mapping[int, Mapping[str, Any]] = {}
    checked: tuple[PreconditionCheck, ...] = ()
    try:
        while composition.plan is not None:
            plan = composition.plan
            try:
                given = environment.given(plan, on_behalf(_supplying(kb, composition), chosen))
                if not replans and composition.attempts:  # the task's own guarantees (actions.task_preconditions)
                    requirement = composition.attempts[0].requirement
                    sense = _sensing(kb, container, environment, composer, sensing, passed, given)
                    checked = check_preconditions(environment, requirement, seen, composer.index.is_a, sense)
            except Exception as error:
                if not replans:  # refused before anything moved: the store is left as it was
                    belief.restore(before)
                if isinstance(error, AmbiguousDesignatorError) and composition.attempts:
                    raise _undecided(error, composition.attempts[0].requirement, composer.index, kb) from error
                raise
            store_plan(kb, plan)
            starting = getattr(environment, "starting", None)  # optional: a look-ahead at the plan's values
            keeping = getattr(environment, "succeeded", None)  # optional: beliefs no sense can check
            executor = Executor(
                plan, container, given, environment.verify, environment.clock, on_start=starting, on_done=keeping
            )
            done = 0
            ended = 0
            _stop_if_cancelled(executor, cancelled, done)
            while executor.status is RunStatus.RUNNING and executor.ticks < max_ticks:
                executor.tick()
                if len(executor.results) != done:  # a step finished: the world changed
                    done = len(executor.results)
                    belief.write(environment.observe())
                if _attempts(executor) != ended:  # a step's attempt ended, however: a Stop takes effect now
                    ended = _attempts(executor)
                    _stop_if_cancelled(executor, cancelled, done)
                elif executor.waiting():  # a remote call out: a Stop ends the wait now
                    _stop_if_cancelled(executor, cancelled, done, "; the remote call under way was abandoned")
            report = executor.run(max_ticks)  # ends a run that hit max_ticks; otherwise just the report
            outputs = executor.results
            if report.status is not RunStatus.FAILED or len(replans) >= max_replans:
                break
            seen = environment.observe()  # the belief the failed step left, before anything is set down
            failures = memory.failures(executor, report, seen)
            _settle(environment)  # leave nothing half done (an object held in a hand) before looking again
            _perceive(environment)  # look again
            now = environment.observe()
            belief.write(now, whole=True)  # a re-plan reads it: exactly the belief, whoever wrote meanwhile
            container.recover()  # what failed for the world's sake may be tried again; the broken stay broken
            _await_return(kb, failures, memory.policy.reconnect_grace, bus)
            refresh = getattr(environment, "refresh", None)
            if callable(refresh):
                refresh()  # components registered since the last plan (or again, after a restart)
            decision = memory.decide(failures, seen, now, compose)
            if decision.composition is None:
                stopped = decision.stopped  # the result says why; listeners had the plan's failure
                break
            replaced = Replan(plan, report, report.reason, tuple(failures), decision.avoided, composed_without)
            replans.append(replaced)
            composed_without = _pairs(passed)
            message = {"event": "replanning", "plan": len(replans) + 1, "reason": report.reason}
            if decision.avoided:
                message["avoiding"] = list(decision.avoided)
            bus.publish("/cbrs/task_progress", message)
            composition = decision.composition
    finally:
        container.finalise_all()
    belief.write(environment.observe(), whole=True)  # what a run leaves is exactly its belief
    goals = _check_goals(environment, composition.plan, outputs) if report is not None else ()
    return RunResult(composition, report, tuple(replans), goals, stopped, composed_without, chosen, checked)


def _sensing(
    kb: KnowledgeBase,
    container: Container,
    environment: Environment,
    composer: Composer,
    config: SensingConfig | None,
    passed: Mapping[str, str],
    given: Mapping[str, Any] | None = None,
) -> PreconditionSensing | None:
    """The question a run's preconditions on measured states are asked through, unless sensing is off;
    ``given``: the values of the plan's inputs, whose things a precondition on a thing's stated quantity is
    asked of (the flask the run designated, not another of its class)."""
    config = config or SensingConfig.from_settings()
    if not config.enabled:
        return None
    return PreconditionSensing(kb, container, environment.registry, composer.index, config.timeout, passed, given=given)


def refusal_before_world(
    kb: KnowledgeBase,
    task: str,
    runnable: collections.abc.Container[str],
    composer: Composer | None = None,
    why_not: Callable[[Sequence[Advertisement]], Mapping[str, str]] | None = None,
    lacking: Mapping[str, str] | None = None,
    unseen: Collection[str] = (),
) -> RunResult | None:
    """The no-plan answer :func:`run_task` gives ``task``, found before its environment is built and has
    perceived the world (seconds, for the simulated home), when nothing perceived could change it; None
    when something might, and the run goes on as before.

    ``runnable``: the components the environment will implement, as far as is known before it is built
    (a superset is what keeps this sound). The run composes from what it perceives, so the answer is
    given early only when no plan composes even over the most the world could offer (:func:`_optimist`):
    every precondition any component states held, every goal held that a perception could find, no area
    refusing a component, no plan refused for a statement a step deletes. This takes an environment
    that perceives afresh only the relations a test decides (``home:computedBy``) and keeps the world
    graph's others, as the simulated home does. Only then is the task composed as the run composes it,
    but from the map (the world is built from it) rather than a belief perceived, for the same account
    of what no component provides and which components cannot run here (``why_not``, as the
    environment's ``unimplemented`` would say); should that plan after all, None.

    ``lacking``: components the environment will not implement for want of something of the home that a
    lab can add (a mobile base), each with why. A no-plan answer names those a plan would use were they
    there (:func:`_naming_the_lacking`): a map without the base lacks what their preconditions ask of it,
    and the answer named only another way that fails (a sonar no component gives).

    ``unseen``: the tests (``home:computedBy``) that never find a relation holding before a run acts, in a
    world the run builds afresh (the simulated home: nobody holds a thing the base has not handed over,
    no hand one it has not taken); the optimist assumes no goal they decide (:func:`_perceivable`).
    """
    composer = composer or Composer(kb)
    optimist = _optimist(kb, composer, runnable, unseen)
    if optimist.compose(task, belief=True).plan is not None:
        return None
    first = composer.compose(task)
    ads = composer.advertisements
    composition = _runnable(
        kb, composer.config, task, first, runnable, belief=False, why_not=why_not, advertisements=ads
    )
    if composition.plan is not None:  # the map alone offers more than the optimist was told: go and look
        return None
    named = _naming_the_lacking(kb, composer, task, runnable, composition, lacking or {}, unseen)
    return RunResult(named, None)


def _naming_the_lacking(
    kb: KnowledgeBase,
    composer: Composer,
    task: str,
    runnable: collections.abc.Container[str],
    composition: CompositionResult,
    lacking: Mapping[str, str],
    unseen: Collection[str] = (),
) -> CompositionResult:
    """``composition``, which has no plan, with the components of ``lacking`` (component -> why the
    environment lacks them) that a plan would use were they there, each with why, besides those it names:
    one more composition by the optimist, over ``runnable`` and ``lacking``, only on the way to a no-plan
    answer and only when something is lacking."""
    if not lacking:
        return composition
    named = {component for u in composition.unsatisfied for component, _ in u.unrunnable}
    more = {ad.iri for ad in composer.advertisements if ad.iri in runnable or ad.iri in lacking}
    would = _optimist(kb, composer, more, unseen).compose(task, belief=True).plan
    if would is None:
        return composition
    wanted = sorted({c for step in would.steps for c in step.candidates if c in lacking and c not in named})
    why = tuple((component, lacking[component]) for component in wanted)
    if not why:
        return composition
    unsatisfied = tuple(replace(u, unrunnable=(*u.unrunnable, *why)) for u in composition.unsatisfied)
    return replace(composition, unsatisfied=unsatisfied)


class _Assuming(Composer):
    """A composer to which ``assumed`` statements hold too, besides what the store says holds, over the
    ``requirements`` already read (the store's, read once for the assumptions and the composition)."""

    def __init__(
        self,
        kb: KnowledgeBase,
        config: ComposeConfig,
        assumed: Iterable[Statement],
        *,
        index: TaxonomyIndex,
        actions: ActionLibrary,
        advertisements: Sequence[Advertisement],
        requirements: Sequence[Requirement],
    ) -> None:
        super().__init__(kb, config, index=index, actions=actions, advertisements=advertisements)
        self.assumed = tuple(assumed)
        self.known = list(requirements)

    def world_state(self) -> list[Statement]:
        return list(dict.fromkeys([*super().world_state(), *self.assumed]))

    def requirements(self) -> list[Requirement]:
        return self.known


def _optimist(
    kb: KnowledgeBase, composer: Composer, runnable: collections.abc.Container[str], unseen: Collection[str] = ()
) -> Composer:
    """A composer over the components in ``runnable`` as if the world offered all it could: every
    precondition of theirs holding; every goal of a requirement holding that a perception could find
    (:func:`_perceivable`); no area rule (where things are is perceived); and no check by progression
    (``protect``: a statement the world offers may be deleted by a step, and the plan refused). A task it
    cannot plan has no plan from any perception either: its search only gains by more that holds and by
    fewer refusals. ``unseen``: tests whose relations no perception finds holding before the run acts
    (:func:`refusal_before_world`)."""
    ads = [ad for ad in composer.advertisements if ad.iri in runnable]
    assumed = [statement for ad in ads for statement in ad.preconditions]
    rows = kb.select("computables")
    decided = {row["relation"].value for row in rows if row["computable"].value not in unseen}
    found: dict[str, bool] = {}  # by class: whether the world has things of it
    requirements = composer.requirements()
    for requirement in requirements:
        assumed += [goal for goal in requirement.effects if _perceivable(kb, composer.index, goal, decided, found)]
    config = replace(composer.config, respect_area=False, protect=False)
    return _Assuming(
        kb,
        config,
        assumed,
        index=composer.index,
        actions=composer.actions,
        advertisements=ads,
        requirements=requirements,
    )


def _perceivable(
    kb: KnowledgeBase, index: TaxonomyIndex, goal: Statement, decided: set[str], found: dict[str, bool]
) -> bool:
    """Whether a perception of the world might find ``goal`` holding (a goal that holds is planned for by
    no step): its subject is of a class the world (map or belief) has things of, and a relation a test
    decides (``home:computedBy``: the only relations an environment perceives afresh, the others being
    kept from the world graph, which the optimist reads) is at or below its relation."""
    if not any(index.is_a(relation, goal.predicate) for relation in decided):
        return False
    if goal.subject not in found:
        found[goal.subject] = bool(kb.select("designate", {"class": goal.subject}))
    return found[goal.subject]


def _await_return(kb: KnowledgeBase, failures: Iterable[Failure], grace: float, bus: EventBus) -> None:
    """Wait up to ``grace`` seconds for the failed live components that are unavailable now (their
    program exited or hung) to register again, saying so on the progress topic. Components not
    registered live, and runs with no grace, do not wait."""
    states = kb.liveness.states()
    gone = sorted({f.component for f in failures if f.component in states and not states[f.component].live})
    if not gone or grace <= 0:
        return
    bus.publish("/cbrs/task_progress", {"event": "awaiting", "components": gone, "seconds": grace})
    deadline = time.monotonic() + grace
    while time.monotonic() < deadline:
        time.sleep(min(0.1, max(0.0, deadline - time.monotonic())))
        states = kb.liveness.states()
        if all(c in states and states[c].live for c in gone):
            return


def _runnable(
    kb: KnowledgeBase,
    config: ComposeConfig,
    task: str,
    composition: CompositionResult,
    registry: collections.abc.Container[str],
    avoid: frozenset[str] = frozenset(),
    passed: Mapping[str, str] | None = None,
    belief: bool = True,
    why_not: Callable[[Sequence[Advertisement]], Mapping[str, str]] | None = None,
    advertisements: Sequence[Advertisement] | None = None,
) -> CompositionResult:
    """``composition`` without the alternatives the environment cannot run; or, when a step's component
    is one it does not implement (the store advertises services the simulation does not perform,
    LocateRoomOfPosition say), the composition without those: such a step fails for sure, and only
    after the steps before it moved things (a goal-only task picked the cup up, then found no room
    locator, three times over). So too without the components the environment ``passed`` over
    (component -> why): a remote one whose calls timed out would make the run wait its timeout again
    (``actions.breaker``). ``belief``: compose again from the belief graph as well as the map (as
    ``composition`` was), else from the map alone. ``why_not``: why the environment has no
    implementation of some advertisements, where it knows (else :func:`_cannot_run` says).
    ``advertisements``: the store's, if the caller has just read them (else read here)."""
    plan = composition.plan
    passed = passed or {}
    if plan is None:
        return name_unavailable(kb, config, task, composition, avoid, belief)
    used = {c for step in plan.steps for c in step.candidates}
    if all(_can_run(step.component, registry, passed) for step in plan.steps):
        # Each step's first choice can run; an alternative that cannot would fail a failover for sure
        # (NoImplementationError after the others timed out), so the run keeps only those that can.
        steps = tuple(
            replace(step, alternatives=tuple(c for c in step.alternatives if _can_run(c, registry, passed)))
            for step in plan.steps
        )
        return composition if steps == plan.steps else replace(composition, plan=replace(plan, steps=steps))
    advertisements = kb.advertisements() if advertisements is None else advertisements
    missing = frozenset(ad.iri for ad in advertisements if ad.iri not in registry) | frozenset(passed)
    again = _compose(kb, config, task, avoid | missing, belief, advertisements)
    if again.plan is not None:
        return again
    # Say which components the first plan wanted: "no component provides" alone hid a registered one.
    wanted = {c for c in used if not _can_run(c, registry, passed)}
    known = why_not([ad for ad in advertisements if ad.iri in wanted]) if why_not is not None else {}
    why = tuple(
        (ad.iri, passed.get(ad.iri) or known.get(ad.iri) or _cannot_run(ad))
        for ad in sorted(advertisements, key=lambda ad: ad.iri)
        if ad.iri in wanted
    )
    named = replace(again, unsatisfied=tuple(replace(u, unrunnable=why) for u in again.unsatisfied))
    # And the unavailable live components a plan without those would use: named alone, the bundled
    # component the simulation cannot run hid the lab's one that is merely stopped.
    return name_unavailable(kb, config, task, named, avoid | missing, belief)


def unrunnable_steps(
    kb: KnowledgeBase,
    plan: Plan,
    registry: collections.abc.Container[str],
    passed: Mapping[str, str] | None = None,
    advertisements: Sequence[Advertisement] | None = None,
    config: ComposeConfig | None = None,
) -> tuple[tuple[PlanStep, str], ...]:
    """The steps of ``plan`` whose component ``registry`` has no implementation of (or the environment
    passes over), each with why: those :func:`run_task` composes the task without. ``cbrs plan`` says
    so, where it composes over every advertisement. ``advertisements``: those the plan was composed
    over, if the caller has them, instead of reading them again. The why also names the unavailable live
    components a plan without them would use (``config``: how ``plan`` was composed), as a run's no-plan
    answer does: named alone, a bundled component the simulation cannot run hid a lab's stopped one."""
    passed = passed or {}
    if all(_can_run(step.component, registry, passed) for step in plan.steps):
        return ()
    found = advertisements if advertisements is not None else kb.advertisements(include_unavailable=True)
    ads = {ad.iri: ad for ad in found}
    live = set(kb.liveness.states())  # the unavailable live components are left to name, not avoided
    avoid = frozenset(iri for iri in ads if iri not in live and not _can_run(iri, registry, passed))
    serving = would_serve(kb, config or ComposeConfig(), plan.task, avoid)
    instead = "; a plan without it would use " + ", ".join(f"{shorten(c)}, {why}" for c, why in serving)
    return tuple(
        (step, (passed.get(step.component) or _cannot_run(ads[step.component])) + (instead if serving else ""))
        for step in plan.steps
        if not _can_run(step.component, registry, passed)
    )


def _can_run(component: str, registry: collections.abc.Container[str], passed: Mapping[str, str]) -> bool:
    """Whether the environment implements ``component`` and does not pass it over now."""
    return component in registry and component not in passed


def _passed_over(environment: Environment, bus: EventBus, before: Mapping[str, str]) -> dict[str, str]:
    """The components the environment passes over now, with why (the Environment protocol's optional
    ``passed_over``: remote components whose calls timed out, ``actions.breaker``); said on the progress
    topic when they are not the ones passed over ``before``."""
    find = getattr(environment, "passed_over", None)
    passed = dict(find()) if callable(find) else {}
    if passed and set(passed) != set(before):
        bus.publish("/cbrs/task_progress", {"event": "passed_over", "components": passed})
    return passed


def _why_not(environment: Environment) -> Callable[[Sequence[Advertisement]], Mapping[str, str]] | None:
    """The environment's account of the advertisements it has no implementation of (the Environment
    protocol's optional ``unimplemented``), if it gives one."""
    found = getattr(environment, "unimplemented", None)
    return found if callable(found) else None


def _pairs(passed: Mapping[str, str]) -> tuple[tuple[str, str], ...]:
    return tuple(sorted(passed.items()))


def _passed_dicts(passed: Iterable[tuple[str, str]]) -> list[dict[str, str]]:
    return [{"component": component, "why": why} for component, why in passed]


def _cannot_run(ad: Advertisement) -> str:
    if ad.bridge_port is not None:
        return (
            f"it is a component in another process, answering {ad.bridge_port.topic} on a cbrs server's bridge,"
            " and this run reaches no bridge (cbrs run --bridge ws://HOST:PORT)"
        )
    return (
        f"the simulation has no skill for its service name {ad.service_name!r}, and it names no service port"
        " (cbrs:ServicePort with cbrs:topic and cbrs:messageType) to call it through (docs/components.md)"
    )


def _base_components(environment: Environment) -> dict[str, frozenset[str]]:
    """Each mobile base's own components, by the base's IRI (the Environment protocol's optional
    ``base_components``): more than one only in a home of several bases."""
    found = getattr(environment, "base_components", None)
    return dict(found()) if callable(found) else {}


def _one_base(
    kb: KnowledgeBase,
    config: ComposeConfig,
    task: str,
    composition: CompositionResult,
    environment: Environment,
    bus: EventBus,
    avoid: frozenset[str],
    ties: BaseTies = BaseTies.NEAREST,
) -> tuple[CompositionResult, BaseChoice | None]:
    """``composition``, or in a home of several bases the best composed with one base's components
    (``actions.base_choice``; plans alike told apart by ``ties``, measured in the store's map), said on
    the progress topic."""
    groups = _base_components(environment)
    if len(groups) < 2:
        return composition, None
    named = named_base(kb, composition, groups)
    drives = MapDrives(kb, groups)  # the map is read only if two plans cost alike and match alike
    stated = stated_costs(config, kb.advertisements()) if config.objective is Objective.COST else None
    found, chosen = choose_base(
        lambda without: _compose(kb, config, task, avoid | without), composition, groups, named, drives, ties, stated
    )
    if chosen is not None:
        message = {"event": "base_chosen", "base": chosen.base, "why": chosen.why, "rule": chosen.rule}
        bus.publish("/cbrs/task_progress", message)
    return found, chosen


def _kept_base(environment: Environment, chosen: BaseChoice) -> frozenset[str]:
    """The other bases' components, read again (a lab may have registered some since the first plan): a
    re-plan works the base the first plan chose. What the run achieved is that base's (where it stands,
    what its platform carries), and the composer's statements are of classes (an object on a
    RobotPlatform), so another base's delivery would be planned on a load it does not carry
    (docs/simulation.md, "A home with no mobile base")."""
    groups = _base_components(environment)
    others = [components for base, components in groups.items() if base != chosen.base]
    return chosen.left_out.union(*others)


def _compose(
    kb: KnowledgeBase,
    config: ComposeConfig,
    task: str,
    avoid: frozenset[str],
    belief: bool = True,
    advertisements: Sequence[Advertisement] | None = None,
) -> CompositionResult:
    """Compose ``task`` afresh from the belief (``belief``; else the map alone), over every advertisement
    (``advertisements``, if just read) but those in ``avoid``."""
    if not avoid:
        return Composer(kb, config, advertisements=advertisements).compose(task, belief=belief)
    found = kb.advertisements() if advertisements is None else advertisements
    kept = [ad for ad in found if ad.iri not in avoid]
    return Composer(kb, config, advertisements=kept).compose(task, belief=belief)


_WHERE = {HOME + "x", HOME + "minX"}  # what places a thing in the map: a position or an extent


def _undecided(
    error: AmbiguousDesignatorError, requirement: Requirement, index: TaxonomyIndex, kb: KnowledgeBase | None = None
) -> AmbiguousDesignatorError:
    """``error`` saying which of ``requirement``'s preconditions are about the ambiguous class and did not
    tell the things apart: a lab wrote one to choose among them (the full flask of two, by its weight), and a
    precondition leaves out only the things the map's stated quantities decide it false of (docs/execution.md,
    "A thing's quantities stated in the map"); where they would have (``kb``'s stated quantities), that the
    environment designated the task's inputs without the task's guarantees. Its example class in the task's
    own namespace. ``error`` itself, but for that namespace, where no precondition is about the class."""
    preconditions = [
        p
        for p in requirement.preconditions
        if p.subject == error.concept or (p.subject in index and index.is_a(error.concept, p.subject))
    ]
    if not preconditions:
        return error.noting(error.note, requirement.iri)
    which = "; ".join(statement_text(p) for p in preconditions)
    statuses = guaranteed_statuses(requirement, error.concept, lambda c, a: a in index and index.is_a(c, a))
    meant = StatedQuantities.read(kb).meeting(error.candidates, statuses) if kb is not None and statuses else []
    if len(meant) == 1:
        return error.noting(
            f"the task's precondition {which} tells them apart by the quantity each states in the map (only "
            f"{shorten(meant[0])} meets it), but the environment designated the task's inputs without the statuses "
            "its preconditions guarantee (kb.semantic_map.designate_each's guarantees, "
            "kb.stated_quantities.guaranteed_statuses)",
            requirement.iri,
        )
    return error.noting(
        f"the task's precondition {which} does not tell them apart: a precondition is what the requester "
        "guarantees of the thing the task names, and of several things of its class it leaves out only those "
        "whose quantity or colour stated in the map decides it false (a status defined by a measured quantity, "
        "of which each states a level: home:massKg for a home:ObjectWeight; or a colour, by the window of its "
        "home:colourName: home:windowColour); here none or each is left",
        requirement.iri,
    )


def _check_grounded(kb: KnowledgeBase, index: TaxonomyIndex, plan: Plan) -> None:
    """Refuse, before anything moves, a task that names a class of thing the world should hold and
    does not (:func:`ungrounded`, the first it finds)."""
    for refusal in ungrounded(kb, index, plan):
        raise refusal


def ungrounded(
    kb: KnowledgeBase, index: TaxonomyIndex, plan: Plan, facts: Sequence[Mapping[str, Term]] | None = None
) -> tuple[UnresolvedDesignatorError | UngroundedGoalError, ...]:
    """Why :func:`run_task` refuses ``plan`` before anything moves for want of things in the world: each
    class of thing the task names that the world should hold and does not (:func:`_missing`), by the
    store alone (the map, and the belief). In a goal: a place the home lacks (a dish rack) named by the
    goal alone was planned towards the object's own place, and the arm carried the cup there. In an
    input, whether a step takes it or not (the environment designates only those the plan uses): a
    suction cup no robot has was ignored, and the pen fetched by a gripper. ``cbrs plan`` notes them all.
    ``facts``: the rows of ``map_facts`` when the caller has read them already."""
    try:
        requirement = kb.description(plan.requirement)
    except NotFoundError:
        requirement = None
    rows = kb.select("map_facts") if facts is None else facts
    placed = {row["thing"].value for row in rows if row["property"].value in _WHERE}
    known: dict[str, bool] = {}  # by class: whether it is missing (a goal names the classes inputs give)

    def missing(concept: str) -> bool:
        if concept not in known:
            known[concept] = _missing(kb, index, placed, concept)
        return known[concept]

    found: list[UnresolvedDesignatorError | UngroundedGoalError] = []
    if isinstance(requirement, Requirement):
        for parameter in requirement.inputs:
            if parameter.type and missing(parameter.type):
                found.append(UnresolvedDesignatorError(parameter.type))
    produced = {kind for step in plan.steps for _, kind in step.outputs if kind}
    for goal in plan.goals:
        statement = goal.statement
        if statement is None:
            continue
        for concept in (statement.subject, statement.object):
            if _produced(index, produced, concept):
                continue  # a step of the plan answers one (a scale's weight): it is made, not found
            if missing(concept):
                rows = kb.select("things_elsewhere", {"class": concept})
                elsewhere = [(row["thing"].value, row["graph"].value) for row in rows]
                found.append(UngroundedGoalError(statement_text(statement), concept, elsewhere))
    return tuple(found)


def _produced(index: TaxonomyIndex, produced: set[str], concept: str) -> bool:
    """Whether a step of the plan outputs a ``concept`` (its class or a subclass): information a step
    brings into being (a scale's weight, a reading) is no thing the world must hold before the run.
    Before, a goal about one (a person told an object's weight) was refused as "nothing in the world is
    one" whenever the map placed some other information entity (the docking poses)."""
    return any(index.is_a(kind, concept) for kind in produced)


def _missing(kb: KnowledgeBase, index: TaxonomyIndex, placed: set[str], concept: str) -> bool:
    """Whether nothing in the world (map or belief) is a ``concept`` although it is a kind of thing the
    map places: one of its topmost classes has things with a position or an extent in the map
    (``placed``). A dish rack is a place, a suction cup a physical object: none being in the world
    means one is missing. A door's status or a notification is of a kind the map places nothing of
    (the world's qualities, a marker's colours, have no position): no thing to find, so it is left to
    the plan. A concept the ontology does not declare counts as missing."""
    if kb.select("designate", {"class": concept}):
        return False
    if concept not in index:
        return True
    tops = [
        ancestor
        for ancestor in index.is_a_ancestors(concept)
        if all(parent == ROOT for parent, link in index.parents(ancestor).items() if link == "is-a")
    ]
    return any(row["thing"].value in placed for top in tops for row in kb.select("designate", {"class": top}))


def _stop_if_cancelled(executor: Executor, cancelled: Callable[[], bool] | None, done: int, during: str = "") -> None:
    """Before the first step, whenever a step's attempt ends, succeeded or failed, and every tick while a
    remote call is out (``during`` says so): stop the run if asked to (a plan whose steps are all done just
    finishes). Asked only after successes, a Stop during a step that failed let the executor start the
    step's next alternative, or the run re-plan, as if unasked."""
    if cancelled is not None and done < len(executor.plan.steps) and cancelled():
        executor.cancel(f"cancelled on request after {done} of {len(executor.plan.steps)} steps{during}")


def _attempts(executor: Executor) -> int:
    """How many attempts of the plan's steps have ended (each success and each failure is one)."""
    return sum(len(report.attempts) for report in executor.reports)


def _settle(environment: Environment) -> None:
    """Let an environment put the world in a state a new plan can start from (the Environment
    protocol's optional ``settle``): a plan that failed with an object in a robot's hand leaves it
    there, and no plan starts by taking an object from a hand."""
    settle = getattr(environment, "settle", None)
    if callable(settle):
        settle()


def _perceive(environment: Environment) -> None:
    """Let an environment that can look at the world do so (the Environment protocol's optional part)."""
    perceive = getattr(environment, "perceive", None)
    if callable(perceive):
        perceive()


def _check_goals(
    environment: Environment, plan: Plan | None, outputs: Mapping[int, Mapping[str, Any]]
) -> tuple[GoalCheck, ...]:
    """The plan's goal effects, as the robots believe them now and, where the environment has a
    referee (``audit``), as they really are."""
    if plan is None:
        return ()
    audit = getattr(environment, "audit", None)
    at_the_end = getattr(environment, "at_the_end", None)  # optional: how the environment reads "a gripper" now
    with at_the_end() if callable(at_the_end) else contextlib.nullcontext():
        return tuple(_checked(environment, plan, outputs, audit))


def _checked(
    environment: Environment, plan: Plan, outputs: Mapping[int, Mapping[str, Any]], audit: Any
) -> Iterator[GoalCheck]:
    for goal in plan.goals:
        if goal.statement is None:
            continue
        step = plan.step(goal.source.step) if goal.source.step is not None else None
        made = outputs.get(step.index, {}) if step is not None else {}
        believed = environment.verify(step, goal.statement, made)
        holds = audit(goal.statement) if callable(audit) else None
        if goal.role == "deletion":  # the task wants it to stop being true
            believed, holds = (None if v is None else not v for v in (believed, holds))
        holds = holds if holds is None else bool(holds)
        yield GoalCheck(goal.statement, believed, holds, goal.role == "deletion")


def _supplying(kb: KnowledgeBase, composition: CompositionResult) -> dict[str, Requirement]:
    """The requirements that supply the plan's inputs: those the composition was made from (its attempts:
    the task's, each sub-action's), which name the inputs as the plan's bindings do; one it did not attempt
    is read alone. Reading them again sent one request each to a remote store (three for a task of three
    sub-actions), and reading every requirement took longer than a step (0.1 s a plan in the home)."""
    plan = composition.plan
    assert plan is not None
    named = {
        binding.source.requirement
        for step in plan.steps
        for binding in step.bindings
        if binding.source.step is None and binding.source.requirement
    }
    composed: dict[str, Requirement] = {}
    for attempt in composition.attempts:  # the task's own first: a goal's part has only that goal's inputs
        composed.setdefault(attempt.requirement.iri, attempt.requirement)
    found: dict[str, Requirement] = {}
    for iri in sorted(named):
        if iri in composed:
            found[iri] = composed[iri]
            continue
        try:
            description = kb.description(iri)
        except NotFoundError:
            continue  # recorded by another store's plan, say: nothing here supplies it
        if isinstance(description, Requirement):
            found[iri] = description
    return found
