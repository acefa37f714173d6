"""A run's ``unused_inputs`` (``RunResult.unused_inputs``: `cbrs run --json`, the server's task runs, and
`cbrs run`'s note) names the inputs no plan of the run took (docs/composition.md): after a re-plan that no
longer takes an input the plan it replaced took, none names it (docs/tasks.md, "A sixth round":
TidyPenAndEraser's re-plan was said to do without the eraser). A composition's own stays its plan's. No
world is run: the results are built from a composed plan."""

from __future__ import annotations

from dataclasses import replace

import pytest

from cbrs.actions.composer import Composer, CompositionResult
from cbrs.actions.executor import ExecutionReport, RunStatus
from cbrs.actions.runner import Replan, RunResult
from cbrs.cli_actions import run_text
from cbrs.kb import KnowledgeBase


@pytest.fixture(scope="module")
def replanned(bundled_kb: KnowledgeBase) -> tuple[CompositionResult, CompositionResult]:
    """FetchMyPen's plan, and a re-plan of it that no longer takes the pen."""
    first = Composer(bundled_kb).compose("FetchMyPen")
    plan = first.plan
    assert plan is not None and first.unused_inputs == ()
    steps = tuple(
        replace(step, bindings=tuple(b for b in step.bindings if b.source.name != "pen")) for step in plan.steps
    )
    return first, replace(first, plan=replace(plan, steps=steps))


def _run(last: CompositionResult, *earlier: CompositionResult) -> RunResult:
    report = ExecutionReport(last.task, RunStatus.SUCCEEDED, [])
    replans = tuple(Replan(e.plan, report, "a step failed") for e in earlier if e.plan is not None)
    return RunResult(composition=last, report=report, replans=replans)


def test_the_json_leaves_out_an_input_an_earlier_plan_took(
    replanned: tuple[CompositionResult, CompositionResult],
) -> None:
    first, last = replanned
    result = _run(last, first)
    assert [u["name"] for u in last.to_dict()["unused_inputs"]] == ["pen"]  # the last plan's own
    assert result.unused_inputs == () and result.to_dict()["plan"]["unused_inputs"] == []
    assert "no step takes" not in run_text(result, 0.0, 0.0)


def test_the_json_and_the_note_name_an_input_no_plan_took(
    replanned: tuple[CompositionResult, CompositionResult],
) -> None:
    _, last = replanned
    for result in (_run(last), _run(last, last)):
        (unused,) = result.to_dict()["plan"]["unused_inputs"]
        assert unused["name"] == "pen" and unused["type"].endswith("#Pen")
        assert "no step takes the task's input pen (home:Pen)" in run_text(result, 0.0, 0.0)
