"""The component container and the executor, tick by tick, with stub components (no simulator)."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import pytest

from cbrs.actions.components import (
    Component,
    Container,
    LifecycleError,
    LifecycleState,
    NoImplementationError,
    Registry,
    Status,
)
from cbrs.actions.events import Event, EventBus, Priority
from cbrs.actions.executor import Executor, RunStatus
from cbrs.actions.plan import Binding, Plan, PlanStep, Source
from cbrs.kb import Statement

EX = "http://example.org/exec#"
DONE = Statement(EX + "Thing", EX + "is", EX + "Done")


class Stub(Component):
    """Succeeds after ``ticks`` updates with ``out = f(in)``; or fails, raises, or never ends."""

    def __init__(self, iri: str, ticks: int = 2, mode: str = "ok") -> None:
        super().__init__(iri)
        self.ticks, self.mode = ticks, mode
        self.seen: list[Mapping[str, Any]] = []
        self.left = 0
        self.halted = 0

    def begin(self, inputs: Mapping[str, Any]) -> None:
        self.seen.append(dict(inputs))
        self.left = self.ticks
        if self.mode == "raise-on-begin":
            raise RuntimeError("cannot start")

    def update(self) -> Status:
        if self.mode == "hang":
            return Status.RUNNING
        self.left -= 1
        if self.left > 0:
            return Status.RUNNING
        if self.mode == "raise":
            raise RuntimeError("sensor unplugged")
        if self.mode == "fail":
            self.reason = "nothing seen"
            return Status.FAILED
        self.outputs = {"out": f"{self.iri.removeprefix(EX)}({self.seen[-1].get('in', '-')})"}
        return Status.SUCCEEDED

    def halt(self) -> None:
        self.halted += 1


def step(
    index: int, component: str, source: Source, alternatives: tuple[str, ...] = (), effects: tuple[Statement, ...] = ()
) -> PlanStep:
    binding = Binding("input", "in", source, "Exact", 1.0, EX + "T")
    return PlanStep(
        index,
        EX + component,
        None,
        None,
        None,
        None,
        (binding,),
        (("out", EX + "T"),),
        effects,
        1.0,
        None,
        tuple(EX + a for a in alternatives),
    )


def plan(*steps: PlanStep, goals: tuple[Binding, ...] = ()) -> Plan:
    return Plan(EX + "Task", EX + "Req", "direct", steps, goals, 1.0, float(len(steps)))


def chain(second_alternatives: tuple[str, ...] = (), effects: tuple[Statement, ...] = ()) -> Plan:
    """A -> B -> C; ``effects``: what the requirement needs B to have brought about."""
    goals = tuple(Binding("precondition", "done", Source("e", 2), "Exact", 1.0, None, e) for e in effects)
    return plan(
        step(1, "A", Source("given", None, EX + "Req")),
        step(2, "B", Source("out", 1), second_alternatives, effects),
        step(3, "C", Source("out", 2)),
        goals=goals,
    )


def setup(stubs: dict[str, Stub]) -> Container:
    registry = Registry()
    for name, stub in stubs.items():
        registry.add(EX + name, lambda iri, stub=stub: stub)
    return Container(registry)


def test_a_plan_runs_step_by_step_and_passes_data() -> None:
    stubs = {n: Stub(EX + n) for n in "ABC"}
    container = setup(stubs)
    executor = Executor(chain(), container, {"given": "g"})
    assert executor.tick() is RunStatus.RUNNING  # starts A
    assert container.state(EX + "A") is LifecycleState.RUNNING
    assert container.state(EX + "B") is LifecycleState.CREATED
    report = executor.run(max_ticks=100)
    assert report.status is RunStatus.SUCCEEDED
    assert stubs["B"].seen == [{"in": "A(g)"}]
    assert stubs["C"].seen == [{"in": "B(A(g))"}]
    assert executor.results[3] == {"out": "C(B(A(g)))"}
    container.finalise_all()
    assert container.history(EX + "A") == [
        LifecycleState.CREATED,
        LifecycleState.INITIALISED,
        LifecycleState.RUNNING,
        LifecycleState.STOPPED,
        LifecycleState.FINALISED,
    ]


def test_each_start_tells_what_the_plans_steps_are_known_to_take_by_then() -> None:
    """The look-ahead hook (an environment's ``starting``): before each step, every step's inputs known
    then, the task's values first and each output as soon as it is produced."""
    seen: list[tuple[int, dict[int, dict[str, Any]]]] = []

    def starting(started: PlanStep, known: Mapping[int, Mapping[str, Any]]) -> None:
        seen.append((started.index, {index: dict(values) for index, values in known.items()}))

    stubs = {n: Stub(EX + n) for n in "ABC"}
    report = Executor(chain(), setup(stubs), {"given": "g"}, on_start=starting).run(max_ticks=100)
    assert report.status is RunStatus.SUCCEEDED
    assert seen == [
        (1, {1: {"in": "g"}, 2: {}, 3: {}}),
        (2, {1: {"in": "g"}, 2: {"in": "A(g)"}, 3: {}}),
        (3, {1: {"in": "g"}, 2: {"in": "A(g)"}, 3: {"in": "B(A(g))"}}),
    ]


def test_a_look_ahead_that_raises_is_the_steps_violation_not_a_crash() -> None:
    def starting(started: PlanStep, known: Mapping[int, Mapping[str, Any]]) -> None:
        if started.index == 2:
            raise RuntimeError("cannot look ahead")

    stubs = {n: Stub(EX + n) for n in "ABC"}
    report = Executor(chain(), setup(stubs), {"given": "g"}, on_start=starting).run(max_ticks=100)
    assert report.status is RunStatus.FAILED and "cannot look ahead" in report.steps[1].attempts[0].reason
    assert stubs["C"].seen == []


@pytest.mark.parametrize("mode", ["fail", "raise", "raise-on-begin", "hang"])
def test_a_violation_fails_over_to_the_alternative(mode: str) -> None:
    stubs = {"A": Stub(EX + "A"), "B": Stub(EX + "B", mode=mode), "B2": Stub(EX + "B2"), "C": Stub(EX + "C")}
    container = setup(stubs)
    report = Executor(chain(("B2",)), container, {"given": "g"}, step_timeout=20).run(max_ticks=500)
    assert report.status is RunStatus.SUCCEEDED
    second = report.steps[1]
    assert [a.component for a in second.attempts] == [EX + "B", EX + "B2"]
    assert [a.outcome for a in second.attempts] == ["failed", "succeeded"]
    assert second.failed_over and second.component == EX + "B2"
    assert stubs["C"].seen == [{"in": "B2(A(g))"}]
    assert container.state(EX + "B") is LifecycleState.ERROR
    expected = {
        "fail": "nothing seen",
        "raise": "sensor unplugged",
        "raise-on-begin": "cannot start",
        "hang": "timeout",
    }
    assert expected[mode] in second.attempts[0].reason
    if mode == "hang":
        assert stubs["B"].halted == 1


def test_an_effect_not_reached_is_a_violation() -> None:
    stubs = {n: Stub(EX + n) for n in ("A", "B", "B2", "C")}
    checked: list[str] = []

    def verifier(s: PlanStep, effect: Statement, outputs: Mapping[str, Any]) -> bool | None:
        checked.append(outputs["out"])
        return outputs["out"].startswith("B2")

    report = Executor(chain(("B2",), (DONE,)), setup(stubs), {"given": "g"}, verifier).run(max_ticks=100)
    assert report.status is RunStatus.SUCCEEDED
    assert checked == ["B(A(g))", "B2(A(g))"]
    assert "effect not reached" in report.steps[1].attempts[0].reason
    assert report.steps[1].effects == [(DONE, True)]


def test_no_alternative_left_fails_the_run_and_names_the_step() -> None:
    stubs = {"A": Stub(EX + "A"), "B": Stub(EX + "B", mode="fail"), "C": Stub(EX + "C")}
    report = Executor(chain(), setup(stubs), {"given": "g"}).run(max_ticks=100)
    assert report.status is RunStatus.FAILED
    assert report.reason.startswith("step 2 (B) failed with no alternative left; requirement Req not met")
    assert "could provide out for step 3 (step 2; tried B: nothing seen)" in report.reason
    assert report.unmet is not None and report.unmet.needed_by == ("step 3",)
    assert report.steps[1].outcome == "failed" and report.steps[2].outcome == "pending"
    assert stubs["C"].seen == []


def test_injected_fault_and_a_broken_component_stays_out() -> None:
    stubs = {n: Stub(EX + n) for n in ("A", "A2", "B", "C")}
    container = setup(stubs)
    container.inject_fault(EX + "A")
    p = plan(
        step(1, "A", Source("given", None, EX + "Req"), ("A2",)),
        step(2, "B", Source("out", 1)),
        step(3, "A", Source("out", 2), ("A2",)),
    )
    report = Executor(p, container, {"given": "g"}).run(max_ticks=100)
    assert report.status is RunStatus.SUCCEEDED
    assert "injected failure" in report.steps[0].attempts[0].reason
    assert [a.component for a in report.steps[2].attempts] == [EX + "A2"]  # A is broken: not tried again
    assert report.steps[2].failed_over


def test_missing_given_value_is_a_violation_with_its_name() -> None:
    report = Executor(chain(), setup({n: Stub(EX + n) for n in "ABC"}), {}).run(max_ticks=50)
    assert report.status is RunStatus.FAILED
    assert "the task gives no value for 'given'" in report.reason


def test_lifecycle_refuses_illegal_transitions_and_suspends() -> None:
    stub = Stub(EX + "A", ticks=3)
    container = setup({"A": stub})
    container.component(EX + "A")  # created and initialised on first use
    with pytest.raises(LifecycleError) as error:
        container.suspend(EX + "A")  # nothing is running
    assert (error.value.current, error.value.wanted) == (LifecycleState.INITIALISED, LifecycleState.SUSPENDED)
    container.start(EX + "A", {"in": 1})
    container.suspend(EX + "A")
    assert [container.tick(EX + "A") for _ in range(5)] == [Status.RUNNING] * 5
    assert stub.left == 3  # suspended: no progress
    container.resume(EX + "A")
    assert [container.tick(EX + "A") for _ in range(3)] == [Status.RUNNING, Status.RUNNING, Status.SUCCEEDED]
    with pytest.raises(LifecycleError):
        container.suspend(EX + "A")  # stopped components cannot be suspended
    with pytest.raises(NoImplementationError, match="no implementation for component"):
        container.component(EX + "Unknown")


def test_events_high_priority_first_and_progress_in_order() -> None:
    bus = EventBus()
    got: list[tuple[str, Any]] = []
    stop = bus.subscribe("/alarm", lambda e: got.append(("alarm", e.message["what"])))
    bus.subscribe("/news", lambda e: got.append(("news", e.message["n"])))
    bus.publish("/news", {"n": 1})
    bus.publish("/news", {"n": 2})
    bus.publish("/alarm", {"what": "fall-down"}, Priority.HIGH)
    assert bus.dispatch() == 3
    assert got == [("alarm", "fall-down"), ("news", 1), ("news", 2)]
    stop()
    bus.publish("/alarm", {"what": "again"}, Priority.HIGH)
    bus.dispatch()
    assert got[-1] == ("news", 2)

    stubs = {"A": Stub(EX + "A"), "B": Stub(EX + "B", mode="fail"), "B2": Stub(EX + "B2"), "C": Stub(EX + "C")}
    container = setup(stubs)
    events: list[Event] = []
    container.bus.subscribe("/cbrs/task_progress", events.append)
    Executor(chain(("B2",)), container, {"given": "g"}).run(max_ticks=100)
    kinds = [(e.message["event"], e.message["step"]) for e in events]
    assert kinds == [
        ("step_started", 1),
        ("step_succeeded", 1),
        ("step_started", 2),
        ("step_failed", 2),
        ("step_started", 2),
        ("step_succeeded", 2),
        ("step_started", 3),
        ("step_succeeded", 3),
    ]
    assert events[3].message["failover"] == EX + "B2"
