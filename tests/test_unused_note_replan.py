"""A run's note on the task's inputs no step takes names only those no plan of the run took: a re-plan,
composed from what held, need not take an input an earlier plan used (docs/tasks.md, "A sixth round":
TidyPenAndEraser's re-plan, with the eraser on the shelf already, was said to do without the eraser
because no component takes a thing of its class)."""

from __future__ import annotations

from dataclasses import replace

from cbrs.actions.composer import Composer
from cbrs.cli_actions import _unused_note
from cbrs.kb import KnowledgeBase


def test_an_input_an_earlier_plan_took_is_not_named(bundled_kb: KnowledgeBase) -> None:
    result = Composer(bundled_kb).compose("FetchMyPen")
    plan = result.plan
    assert plan is not None and result.unused_inputs == ()
    steps = tuple(
        replace(step, bindings=tuple(b for b in step.bindings if b.source.name != "pen")) for step in plan.steps
    )
    last = replace(result, plan=replace(plan, steps=steps))  # a re-plan that no longer takes the pen
    assert [name for name, _ in last.unused_inputs] == ["pen"]
    assert "no step takes the task's input pen (home:Pen)" in _unused_note(last)
    assert _unused_note(last, [plan]) == ""  # the plan it replaced took it
    assert "input pen" in _unused_note(last, [last.plan] if last.plan else [])  # no plan of the run took it
