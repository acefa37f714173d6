"""A Stop asked during a step takes effect when that step ends, however it ends (actions.runner), and a task
no runnable component can do names the unavailable live components that would have served as well as the
ones the environment cannot run (actions.unavailable). Stub components, no simulator."""

from __future__ import annotations

from pathlib import Path

from cbrs.actions.executor import RunStatus
from cbrs.actions.runner import run_task
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
