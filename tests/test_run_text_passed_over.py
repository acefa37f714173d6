"""``cbrs run``'s text says which components the plan was composed without and why (a circuit breaker's
open state, an actuator still executing a call given up), as its JSON's ``plan.passed_over`` does."""

from __future__ import annotations

from pathlib import Path

from cbrs.actions.runner import run_task
from cbrs.cli_actions import run_text
from cbrs.kb.namespaces import shorten
from tests.test_replanning_memory import DIRECT, EX, Home, Worker, component, kb_with

# the breaker's reason names the component; the actuator rule's names the service it was calling
HANGS = f"{shorten(EX + 'Direct')} is passed over: its last 1 call(s) to /direct/run timed out (no answer within 10 s)"
BUSY = "/prepare/run is still executing the call sent 3.0 s ago, given up after 10 s without an answer"


class PassingOver(Home):
    """The stub home, whose remote components ``Direct`` and ``Prepare`` are passed over."""

    def __init__(self) -> None:
        super().__init__({})
        self.registry.add(EX + "Other", lambda iri: Worker(iri, self))

    def passed_over(self) -> dict[str, str]:
        return {EX + "Direct": HANGS, EX + "Prepare": BUSY}


def test_the_text_names_each_component_passed_over_with_why(tmp_path: Path) -> None:
    others = component("Prepare", "A", "B", 1.0) + component("Finish", "B", "D", 5.0)
    kb = kb_with(DIRECT + others + component("Other", "A", "D", 9.0), tmp_path)
    result = run_task(kb, EX + "Req", PassingOver())
    assert result.succeeded and [s.planned for s in result.report.steps] == [EX + "Other"]  # type: ignore[union-attr]
    lines = run_text(result, 0.0, 0.0).splitlines()
    assert lines[:3] == ["the plan was composed without:", f"  {HANGS}", f"  {shorten(EX + 'Prepare')}: {BUSY}"]
    assert result.to_dict()["plan"]["passed_over"] == [
        {"component": EX + "Direct", "why": HANGS},
        {"component": EX + "Prepare", "why": BUSY},
    ]


def test_nothing_passed_over_adds_no_line(tmp_path: Path) -> None:
    kb = kb_with(DIRECT, tmp_path)
    result = run_task(kb, EX + "Req", Home({}))
    assert result.succeeded and "composed without" not in run_text(result, 0.0, 0.0)
