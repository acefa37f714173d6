"""Plan execution with fault tolerance (paper section 5).

The executor runs a plan step by step, tick by tick: it resolves each step's inputs from the plan's
bindings (an earlier step's outputs or the task's given values), starts the step's component in the
container, ticks it, and checks with a verifier the statements the rest of the plan relies on from
that step (later steps' preconditions and the requirement's effects). A *violation* (an exception, a
failed status, a timeout, or an effect not reached) switches the step to its next-best alternative
component and carries on; when a step has no alternative left, the run fails and the report says
which step and which need could not be met.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from enum import Enum
from typing import Any, Protocol, runtime_checkable

from cbrs.actions.components import Component, Container, LifecycleState, Status
from cbrs.actions.events import Priority
from cbrs.actions.graph import statement_text
from cbrs.actions.plan import Plan, PlanStep
from cbrs.kb import Statement
from cbrs.reasoner.names import local_name


class RunStatus(Enum):
    RUNNING = "running"
    SUCCEEDED = "succeeded"
    FAILED = "failed"
    CANCELLED = "cancelled"  # stopped on request between steps, or during a remote call (run_task's ``cancelled``)


class Verifier(Protocol):
    def __call__(self, step: PlanStep, statement: Statement, outputs: Mapping[str, Any]) -> bool | None:
        """Whether ``statement`` holds now (None: it cannot be checked)."""


class StepStart(Protocol):
    def __call__(self, step: PlanStep, known: Mapping[int, Mapping[str, Any]]) -> None:
        """``step`` is about to start; ``known`` holds, by step index, the inputs of every step of the plan
        known now (the task's values, outputs already produced): what an environment may look ahead at."""


class StepDone(Protocol):
    def __call__(self, step: PlanStep, component: str) -> None:
        """``component`` did ``step`` and its effects were checked: what an environment that keeps beliefs
        no sense can check (a door a remote motor opened) updates them from (the component's effects
        added, its delete effects removed)."""


@runtime_checkable
class Uncounted(Protocol):
    """A component that wants to know when the executor did not count an invocation it ended as succeeded
    (an effect not reached, the environment's bookkeeping failed): a remote actuator then treats what it
    may have done as unknown (``actions.remote.RemoteComponent``; docs/execution.md, "The belief after a failed
    step")."""

    def uncounted(self, reason: str) -> None: ...


@dataclass
class Attempt:
    component: str
    outcome: str  # "succeeded", "failed", or "cancelled" (a remote call a Stop abandoned)
    reason: str = ""
    ticks: int = 0
    seconds: float = 0.0  # on the executor's clock (simulated seconds in the simulation)

    def to_dict(self) -> dict[str, Any]:
        return {
            "component": self.component,
            "outcome": self.outcome,
            "reason": self.reason,
            "ticks": self.ticks,
            "seconds": round(self.seconds, 3),
        }


@dataclass
class StepReport:
    index: int
    planned: str  # the component the plan chose
    attempts: list[Attempt] = field(default_factory=list)
    effects: list[tuple[Statement, bool | None]] = field(default_factory=list)
    outcome: str = "pending"

    @property
    def component(self) -> str:
        """The component that did the step (the last one tried)."""
        return self.attempts[-1].component if self.attempts else self.planned

    @property
    def failed_over(self) -> bool:
        """Whether another component than the planned one did (or last tried) the step."""
        return self.component != self.planned

    def to_dict(self) -> dict[str, Any]:
        return {
            "index": self.index,
            "planned": self.planned,
            "component": self.component,
            "outcome": self.outcome,
            "seconds": round(sum(a.seconds for a in self.attempts), 3),
            "failover": self.failed_over,
            "attempts": [a.to_dict() for a in self.attempts],
            "effects": [{"statement": statement_text(s), "verified": ok} for s, ok in self.effects],
        }


@dataclass(frozen=True)
class Unmet:
    """Why a run failed, in the plan's terms: the requirement left unmet, the step that could not be
    done, what the rest of the plan needed from it, and every component tried for it."""

    requirement: str  # the task's requirement
    step: int
    sub_action: str | None  # the part of a decomposed task the step belongs to
    provides: tuple[str, ...]  # outputs and effects the rest of the plan or the requirement relied on
    needed_by: tuple[str, ...]  # "step N" for later steps, "the requirement" for its outputs and effects
    tried: tuple[Attempt, ...]

    def text(self) -> str:
        what = ", ".join(self.provides) or "its completion"
        part = f" of {local_name(self.sub_action)}" if self.sub_action else ""
        tried = "; ".join(f"{local_name(a.component)}: {a.reason}" for a in self.tried) or "none"
        return (
            f"requirement {local_name(self.requirement)} not met: no component could provide {what}"
            f" for {', '.join(self.needed_by) or 'the plan'} (step {self.step}{part}; tried {tried});"
            f" {self.remedy()}"
        )

    def remedy(self) -> str:
        """What would let a new run get past this step."""
        broken = ", ".join(dict.fromkeys(local_name(a.component) for a in self.tried)) or "its component"
        return f"repair {broken} or register another component that provides {', '.join(self.provides) or 'it'}"

    def to_dict(self) -> dict[str, Any]:
        return {
            "requirement": self.requirement,
            "step": self.step,
            "sub_action": self.sub_action,
            "provides": list(self.provides),
            "needed_by": list(self.needed_by),
            "tried": [a.to_dict() for a in self.tried],
            "text": self.text(),
        }


@dataclass
class ExecutionReport:
    task: str
    status: RunStatus
    steps: list[StepReport]
    reason: str = ""
    ticks: int = 0
    seconds: float = 0.0
    unmet: Unmet | None = None
    # What each step that succeeded gave, by step index: the values a task asking for outputs wants
    # (``RunResult.answers``); left out of ``to_dict``, where a map's cells would swell every report.
    outputs: Mapping[int, Mapping[str, Any]] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        return {
            "task": self.task,
            "status": self.status.value,
            "reason": self.reason,
            "unmet": None if self.unmet is None else self.unmet.to_dict(),
            "ticks": self.ticks,
            "seconds": round(self.seconds, 3),
            "steps": [s.to_dict() for s in self.steps],
        }


class Executor:
    """Runs one plan in a container; ``tick()`` advances it, ``run()`` ticks until it ends."""

    def __init__(
        self,
        plan: Plan,
        container: Container,
        given: Mapping[str, Any],
        verifier: Verifier | None = None,
        clock: Callable[[], float] | None = None,
        step_timeout: int = 10_000,
        on_start: StepStart | None = None,
        on_done: StepDone | None = None,
    ) -> None:
        self.plan = plan
        self.on_start = on_start
        self.on_done = on_done
        self.container = container
        self.given = dict(given)
        self.verifier = verifier
        self.clock = clock or (lambda: 0.0)
        self.step_timeout = step_timeout
        self.results: dict[int, dict[str, Any]] = {}
        # What the rest of the plan relies on from each step: its consumers' preconditions and the
        # requirement's effects, as they were requested (the advertised effect may be more general).
        self.needed: dict[int, list[Statement]] = {}
        for binding in [b for s in plan.steps for b in s.preconditions] + list(plan.goals):
            if binding.statement is not None and binding.source.step is not None and binding.role != "deletion":
                wanted = self.needed.setdefault(binding.source.step, [])
                if binding.statement not in wanted:
                    wanted.append(binding.statement)
        self.reports = [StepReport(s.index, s.component) for s in plan.steps]
        self.status = RunStatus.RUNNING
        self.reason = ""
        self.unmet: Unmet | None = None
        self.ticks = 0
        self._position = 0  # index into plan.steps
        self._active: str | None = None
        self._tried: list[str] = []
        self._started_tick = 0
        self._started_at = 0.0
        self._began = self.clock()

    # -- driving -----------------------------------------------------------------------------------

    def run(self, max_ticks: int = 1_000_000) -> ExecutionReport:
        while self.status is RunStatus.RUNNING and self.ticks < max_ticks:
            self.tick()
        if self.status is RunStatus.RUNNING:
            self._finish(RunStatus.FAILED, f"stopped after {max_ticks} ticks")
        return self.report()

    def tick(self) -> RunStatus:
        if self.status is not RunStatus.RUNNING:
            return self.status
        self.ticks += 1
        if self._position >= len(self.plan.steps):
            self._finish(RunStatus.SUCCEEDED)
            return self.status
        step = self.plan.steps[self._position]
        if self._active is None:
            self._start(step)
        else:
            self._advance(step)
        self.container.bus.dispatch()
        return self.status

    def cancel(self, reason: str) -> None:
        """Stop the run on request: the step under way is aborted (its attempt recorded as cancelled) and
        nothing more starts."""
        if self.status is not RunStatus.RUNNING:
            return
        if self._active is not None:
            iri = self._active
            self.container.abort(iri, reason)
            report = self.reports[self._position]
            report.attempts.append(self._attempt(iri, "cancelled", self.container.reason(iri)))
            report.outcome = "cancelled"
            self._active = None
        self._finish(RunStatus.CANCELLED, reason)

    def waiting(self) -> bool:
        """Whether the step under way only waits on another process's answer (``Component.waiting``): a
        Stop may end it now."""
        return self._active is not None and self.container.component(self._active).waiting()

    def report(self) -> ExecutionReport:
        return ExecutionReport(
            self.plan.task,
            self.status,
            self.reports,
            self.reason,
            self.ticks,
            self.clock() - self._began,
            self.unmet,
            {index: dict(given) for index, given in self.results.items()},
        )

    # -- one step ----------------------------------------------------------------------------------

    def _candidates(self, step: PlanStep) -> list[str]:
        """The step's components not yet tried for it and not broken by an earlier violation."""
        return [
            c for c in step.candidates if c not in self._tried and self.container.state(c) is not LifecycleState.ERROR
        ]

    def _start(self, step: PlanStep) -> None:
        candidates = self._candidates(step)
        if not candidates:
            report = self.reports[self._position]
            report.outcome = "failed"
            self.unmet = self._unmet(step, report)
            where = f"step {step.index} ({local_name(step.component)})"
            self._finish(RunStatus.FAILED, f"{where} failed with no alternative left; {self.unmet.text()}")
            return
        iri = candidates[0]
        self._tried.append(iri)
        self._active = iri
        self._started_tick = self.ticks
        self._started_at = self.clock()
        self._publish("step_started", step, iri)
        try:
            if self.on_start is not None:
                self.on_start(step, {other.index: self.inputs_for(other) for other in self.plan.steps})
            self.container.start(iri, self._inputs(step))
        except Exception as error:  # a component may raise anything: it is a violation, not a crash
            self._violation(step, iri, f"{type(error).__name__}: {error}")

    def _advance(self, step: PlanStep) -> None:
        iri = self._active
        assert iri is not None
        try:
            status = self.container.tick(iri)
        except Exception as error:
            self._violation(step, iri, f"{type(error).__name__}: {error}")
            return
        if status is Status.RUNNING:
            if self.ticks - self._started_tick >= self.step_timeout:
                self._violation(step, iri, f"timeout after {self.step_timeout} ticks")
            return
        component = self.container.component(iri)
        if status is Status.FAILED:
            self._violation(step, iri, component.reason or "failed")
            return
        checks = [(need, self._verify(step, need, component.outputs)) for need in self.needed.get(step.index, [])]
        missed = [statement_text(effect) for effect, ok in checks if ok is False]
        if missed:
            self.reports[self._position].effects = checks
            self._uncounted(component, step, iri, "effect not reached: " + ", ".join(missed))
            return
        if self.on_done is not None:
            try:
                self.on_done(step, iri)
            except Exception as error:  # the environment's bookkeeping failed: the step did not count
                self._uncounted(component, step, iri, f"{type(error).__name__}: {error}")
                return
        report = self.reports[self._position]
        report.attempts.append(self._attempt(iri, "succeeded"))
        report.effects = checks
        report.outcome = "succeeded"
        self.results[step.index] = dict(component.outputs)
        self._publish("step_succeeded", step, iri)
        self._active = None
        self._tried = []
        self._position += 1

    def _unmet(self, step: PlanStep, report: StepReport) -> Unmet:
        """What the plan loses with ``step``: the outputs and effects later steps and the goals take from it."""
        provides: list[str] = []
        needed_by: list[str] = []
        for later in self.plan.steps:
            used = [b for b in later.bindings if b.source.step == step.index]
            if used:
                needed_by.append(f"step {later.index}")
                provides += [b.source.name for b in used]
        goals = [g for g in self.plan.goals if g.source.step == step.index]
        if goals:
            needed_by.append("the requirement")
            provides += [statement_text(g.statement) if g.statement is not None else g.source.name for g in goals]
        provides += [statement_text(s) for s in self.needed.get(step.index, [])]
        attempted = {a.component for a in report.attempts}
        broken = [  # out of order since an earlier step or plan: not tried again, but named
            Attempt(c, "failed", f"out of order since it failed earlier ({self.container.reason(c)})")
            for c in step.candidates
            if c not in attempted and self.container.state(c) is LifecycleState.ERROR
        ]
        return Unmet(
            self.plan.requirement,
            step.index,
            step.part_of,
            tuple(dict.fromkeys(provides)),
            tuple(needed_by),
            (*report.attempts, *broken),
        )

    def _verify(self, step: PlanStep, statement: Statement, outputs: Mapping[str, Any]) -> bool | None:
        if self.verifier is None:
            return None
        found = self.verifier(step, statement, outputs)
        return None if found is None else bool(found)

    def _uncounted(self, component: Component, step: PlanStep, iri: str, reason: str) -> None:
        """A violation after ``component`` ended as succeeded: it is told first, if it asks to be."""
        if isinstance(component, Uncounted):
            try:
                component.uncounted(reason)
            except Exception as error:  # its bookkeeping must not hide the step's own failure
                reason = f"{reason} ({type(error).__name__} telling it: {error})"
        self._violation(step, iri, reason)

    def _violation(self, step: PlanStep, iri: str, reason: str) -> None:
        """Record the failed attempt; the next tick starts the next alternative (or fails the run)."""
        self.container.abort(iri, reason)
        report = self.reports[self._position]
        report.attempts.append(self._attempt(iri, "failed", reason))
        left = self._candidates(step)
        self._publish("step_failed", step, iri, reason=reason, failover=left[0] if left else None)
        self._active = None

    def _attempt(self, iri: str, outcome: str, reason: str = "") -> Attempt:
        return Attempt(iri, outcome, reason, self.ticks - self._started_tick, self.clock() - self._started_at)

    def inputs_for(self, step: PlanStep) -> dict[str, Any]:
        """The values ``step`` is (or would be) invoked with; those not produced yet are left out."""
        values: dict[str, Any] = {}
        for binding in step.inputs:
            source = binding.source
            if source.step is None and source.name in self.given:
                values[binding.name] = self.given[source.name]
            elif source.step is not None and source.name in self.results.get(source.step, {}):
                values[binding.name] = self.results[source.step][source.name]
        return values

    def _inputs(self, step: PlanStep) -> dict[str, Any]:
        values = self.inputs_for(step)
        for binding in step.inputs:
            if binding.name not in values:
                source = binding.source
                if source.step is None:
                    raise KeyError(f"the task gives no value for {source.name!r}")
                raise KeyError(f"step {source.step} gave no {source.name!r}")
        return values

    def _finish(self, status: RunStatus, reason: str = "") -> None:
        self.status = status
        self.reason = reason
        self.container.bus.publish(
            "/cbrs/task",
            {"task": self.plan.task, "status": status.value, "reason": reason},
            Priority.HIGH if status is RunStatus.FAILED else Priority.NORMAL,
        )
        self.container.bus.dispatch()

    def _publish(self, kind: str, step: PlanStep, iri: str, **extra: Any) -> None:
        message = {"event": kind, "task": self.plan.task, "step": step.index, "component": iri, **extra}
        self.container.bus.publish("/cbrs/task_progress", message)
