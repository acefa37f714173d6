"""A Stop asked during a step takes effect when that step ends, however it ends (actions.runner), and a task
no runnable component can do names the unavailable live components that would have served as well as the
ones the environment cannot run (actions.unavailable). Stub components, no simulator."""

from __future__ import annotations

from pathlib import Path

from cbrs.actions.components import Registry
from cbrs.actions.composer import Composer
from cbrs.actions.executor import RunStatus
from cbrs.actions.runner import run_task, unrunnable_steps
from cbrs.kb import KnowledgeBase
from tests.test_replanning_memory import AROUND, DIRECT, EX, Home, Worker, component, kb_with

SPARE = component("Spare", "A", "D", 2.0)  # the step's alternative to Direct: same inputs and outputs


def _home(failing: dict[str, int]) -> Home:
    home = Home(failing)
    home.registry.add(EX + "Spare", lambda iri: Worker(iri, home))
    return home


def test_a_stop_asked_while_a_step_fails_tries_no_alternative_and_does_not_re_plan(tmp_path: Path) -> None:
    kb = kb_with(DIRECT + SPARE + AROUND, tmp_path)
    unasked = _home({"Direct": 99})
    failed_over = run_task(kb, EX + "Req", unasked)
    assert failed_over.succeeded and unasked.calls[EX + "Spare"] == 1  # the alternative is there to take
    home = _home({"Direct": 99})
    result = run_task(kb, EX + "Req", home, cancelled=lambda: home.calls[EX + "Direct"] > 0)
    assert result.report is not None and result.report.status is RunStatus.CANCELLED
    assert result.report.reason == "cancelled on request after 0 of 1 steps"
    assert not result.replans and not result.stopped
    assert dict(home.calls) == {EX + "Direct": 1}  # neither Spare nor the route around was started
    assert [a.outcome for a in result.report.steps[0].attempts] == ["failed"]


def test_a_stop_asked_while_the_last_alternative_fails_does_not_re_plan(tmp_path: Path) -> None:
    kb = kb_with(DIRECT + AROUND, tmp_path)
    home = _home({"Direct": 99})
    result = run_task(kb, EX + "Req", home, cancelled=lambda: home.calls[EX + "Direct"] > 0)
    assert result.report is not None and result.report.status is RunStatus.CANCELLED
    assert not result.replans and dict(home.calls) == {EX + "Direct": 1}


LIVE = component("Gauge", "A", "D", 1.0)  # the lab's live component: could do the task, its program stopped


def _stopped_gauge(tmp_path: Path) -> KnowledgeBase:
    kb = kb_with(DIRECT + LIVE, tmp_path)
    kb.liveness.renew(EX + "Gauge", 600.0)
    kb.liveness.expire(EX + "Gauge", "its session closed")
    return kb


def test_no_plan_names_the_unavailable_live_component_beside_the_one_that_cannot_run_here(tmp_path: Path) -> None:
    """As TellMeTheBatteryLevel with the lab's gauge stopped: the bundled MonitorBattery the simulation has
    no skill for was named, and not the gauge (docs/components.md, "Tried by a component developer")."""
    kb = _stopped_gauge(tmp_path)
    home = _home({})
    home.registry = Registry()  # Direct has no implementation here, as a bundled service with no skill
    result = run_task(kb, EX + "Req", home)
    assert result.composition.plan is None and result.report is None and not home.calls
    (unmet,) = result.composition.unsatisfied
    assert [component for component, _ in unmet.unrunnable] == [EX + "Direct", EX + "Gauge"]
    assert dict(unmet.unrunnable)[EX + "Gauge"] == "unavailable: its session closed"
    assert "Gauge was planned for it but cannot run here: unavailable: its session closed" in unmet.text()
    assert "Direct was planned for it but cannot run here" in unmet.text()


def test_a_plan_whose_step_cannot_run_here_says_which_unavailable_component_would_do_it(tmp_path: Path) -> None:
    """What ``cbrs plan`` notes of a step the simulated home cannot run."""
    kb = _stopped_gauge(tmp_path)
    plan = Composer(kb).compose(EX + "Req").plan
    assert plan is not None and [step.component for step in plan.steps] == [EX + "Direct"]
    ((step, why),) = unrunnable_steps(kb, plan, Registry())
    assert step.component == EX + "Direct"
    assert why.endswith(f"; a plan without it would use {EX}Gauge, unavailable: its session closed")
    kb.liveness.renew(EX + "Gauge", 600.0)  # its program back: nothing unavailable to name
    plan = Composer(kb).compose(EX + "Req").plan
    assert plan is not None
    ((_, why),) = unrunnable_steps(kb, plan, Registry())
    assert "would use" not in why
