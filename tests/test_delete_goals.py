"""A requirement's delete effects are goals like its effects (docs/composition.md, "Delete effects a task
wants"): composition plans a step whose delete effect meets each (the step already planned when one does),
the goals list them, the executor does not verify them as a step's effects, and the check after the run
asks that the statement no longer holds. A delete effect no component's meets is a "no plan" naming it
(docs/tasks.md, "A sixth round": ClearPenOffTheTable's delete effect had been dropped without a word)."""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import pytest

from cbrs.actions.composer import Composer
from cbrs.actions.plan import Plan, PlanStep
from cbrs.actions.runner import _check_goals
from cbrs.cli_actions import plan_text
from cbrs.kb import KnowledgeBase, Statement
from cbrs.kb.namespaces import PREFIXES
from tests.helpers_examples import EXAMPLES

HOME, SVC = PREFIXES["home"], PREFIXES["svc"]
PICK_UP = (
    SVC + "PickUpObject_CytonDualArm01"
)  # deletes (PhysicalObject, isLocated, Place), (.., isLocatedOn, Furniture)
# the pen off the table's top (world:KitchenTableTop, a home:TableTop: a region, so a place the pick-up deletes)
OFF_THE_TOP = Statement(HOME + "Pen", HOME + "isLocatedOn", HOME + "TableTop")


@pytest.fixture(scope="module")
def composer() -> Composer:
    kb = KnowledgeBase.open(":memory:")
    for graph in ("ontology", "map"):
        kb.load([EXAMPLES / "lab6_tidy_shelf.ttl"], graph=graph)
    kb.load([EXAMPLES / "lab6_pen_off_the_table.ttl", EXAMPLES / "lab6_mistake_delete_only.ttl"], graph="requirements")
    return Composer(kb)


def test_a_delete_effect_beside_an_effect_is_met_by_the_pick_up_already_planned(composer: Composer) -> None:
    task = composer.task("ClearPenOffTheTable")
    alone = composer.compose(replace(task.requirement, deletes=())).plan
    result = composer.compose(replace(task.requirement, deletes=(OFF_THE_TOP,)))
    both = result.plan
    assert alone is not None and both is not None
    assert both.components() == alone.components()  # no second pick-up: the carry's own deletes it
    deletion = [g for g in both.goals if g.role == "deletion"]
    assert [(g.statement, both.step(g.source.step or 0).component) for g in deletion] == [(OFF_THE_TOP, PICK_UP)]
    assert "not (home:Pen, home:isLocatedOn, home:TableTop) <- #6" in plan_text(result)


def test_a_delete_effect_alone_is_planned_for(composer: Composer) -> None:
    task = composer.task("PenNotOnTheTable")
    plan = composer.attempt(replace(task.requirement, deletes=(OFF_THE_TOP,)), task).plan
    assert plan is not None and plan.components()[-1] == PICK_UP
    assert [g.role for g in plan.goals] == ["deletion"]


def test_the_pen_off_the_table_is_met_by_the_pick_up(composer: Composer) -> None:
    """The lab's (Pen, isLocatedOn, Table), as the map says the pen stands (on world:KitchenTable): the pick-up
    deletes where the object stood, a place or a piece of furniture (ontologies/services.ttl)."""
    for task in ("ClearPenOffTheTable", "PenNotOnTheTable"):
        plan = composer.compose(task).plan
        assert plan is not None, task
        deletion = [g for g in plan.goals if g.role == "deletion"]
        assert [plan.step(g.source.step or 0).component for g in deletion] == [PICK_UP], task


def test_a_delete_effect_no_component_deletes_is_a_no_plan_naming_it(composer: Composer) -> None:
    """Nothing deletes where a person is: the answer names the delete effect and what components do delete
    about its subject's kind."""
    task = composer.task("PenNotOnTheTable")
    away = Statement(HOME + "Person", HOME + "isLocated", HOME + "Room")
    result = composer.attempt(replace(task.requirement, deletes=(away,)), task)
    assert result.plan is None
    text = " ".join(u.text() for u in result.unsatisfied)
    assert "no component deletes (home:Person, home:isLocated, home:Room)" in text, text
    assert "delete effects alone are no goal" not in text


class _World:
    """An environment whose robots believe ``believed`` of every statement and whose referee says ``holds``."""

    def __init__(self, believed: bool | None, holds: bool | None) -> None:
        self.believed, self.holds = believed, holds

    def verify(self, step: PlanStep | None, statement: Statement, outputs: Any) -> bool | None:
        return self.believed

    def audit(self, statement: Statement) -> bool | None:
        return self.holds


def test_the_check_after_the_run_asks_that_a_deleted_statement_no_longer_holds(composer: Composer) -> None:
    task = composer.task("ClearPenOffTheTable")
    plan = composer.compose(replace(task.requirement, deletes=(OFF_THE_TOP,))).plan
    assert isinstance(plan, Plan)
    checks = {c.deleted: c for c in _check_goals(_World(True, True), plan, {})}  # type: ignore[arg-type]
    assert (checks[False].believed, checks[False].holds) == (True, True)
    assert (checks[True].believed, checks[True].holds) == (False, False)  # the pen is still on a table top
    assert checks[True].to_dict()["statement"] == "not (home:Pen, home:isLocatedOn, home:TableTop)"
    gone = {c.deleted: c for c in _check_goals(_World(False, None), plan, {})}  # type: ignore[arg-type]
    assert (gone[True].believed, gone[True].holds) == (True, None)
