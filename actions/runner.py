"""Plan, then execute: what ``cbrs run`` and the task services do, for any environment.

An ``Environment`` provides the component implementations, the values the task gives (the world's
cup, pen, person), the effect verifier, observations for the belief state, and a clock. The
simulation provides one (``sim.components``); tests provide stubs.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from typing import Any, Protocol

from actions.belief import BeliefState, Observation
from actions.components import Container, Registry
from actions.composer import Composer, CompositionResult, PlanStatus, store_plan
from actions.events import Event, EventBus
from actions.executor import ExecutionReport, Executor, RunStatus
from actions.faults import Combined, FaultPolicy, FixedFaults
from actions.plan import Plan, PlanStep
from kb import KnowledgeBase, Requirement, Statement


class Environment(Protocol):
    registry: Registry
    context: Any

    def given(self, plan: Plan, requirements: Mapping[str, Requirement]) -> dict[str, Any]:
        """Values for the inputs the task's requirement(s) give, by parameter name."""

    def verify(self, step: PlanStep, statement: Statement, outputs: Mapping[str, Any]) -> bool | None:
        """Whether ``statement`` holds now in the environment."""

    def observe(self) -> Observation:
        """The belief state to write to the world graph now."""

    def clock(self) -> float:
        """Seconds on the environment's clock (simulated time)."""


@dataclass(frozen=True)
class RunResult:
    composition: CompositionResult
    report: ExecutionReport | None  # None when there was no plan to run

    @property
    def succeeded(self) -> bool:
        return self.report is not None and self.report.status is RunStatus.SUCCEEDED

    def to_dict(self) -> dict[str, Any]:
        found: dict[str, Any] = {
            "task": self.composition.task,
            "status": self.report.status.value if self.report else PlanStatus.UNSOLVABLE.value,
            "plan": self.composition.to_dict(),
        }
        if self.report is not None:
            found["execution"] = self.report.to_dict()
        return found


def run_task(
    kb: KnowledgeBase,
    task: str,
    environment: Environment,
    faults: Iterable[str] = (),
    composer: Composer | None = None,
    on_event: Callable[[Event], None] | None = None,
    max_ticks: int = 100_000,
    fault_policy: FaultPolicy | None = None,
) -> RunResult:
    """Compose ``task``, store the plan, run it in ``environment`` and keep the world graph current.

    ``faults`` fail whenever invoked; ``fault_policy`` (e.g. ``RandomFaults``) may break others mid-run.
    """
    composer = composer or Composer(kb)
    composition = composer.compose(task)
    if composition.plan is None:
        return RunResult(composition, None)
    plan = composition.plan
    store_plan(kb, plan)
    bus = EventBus()
    if on_event is not None:
        bus.subscribe("*", on_event)
    failing = FixedFaults.of(faults)
    policy = failing if fault_policy is None else Combined((failing, fault_policy))
    container = Container(environment.registry, environment.context, bus, policy)
    requirements = {r.iri: r for r in kb.requirements()}
    belief = BeliefState(kb)
    belief.write(environment.observe())
    executor = Executor(plan, container, environment.given(plan, requirements), environment.verify, environment.clock)
    done = 0
    try:
        while executor.status is RunStatus.RUNNING and executor.ticks < max_ticks:
            executor.tick()
            if len(executor.results) != done:  # a step finished: the world changed
                done = len(executor.results)
                belief.write(environment.observe())
        report = executor.run(max_ticks)  # ends a run that hit max_ticks; otherwise just the report
    finally:
        container.finalise_all()
    belief.write(environment.observe())
    return RunResult(composition, report)
