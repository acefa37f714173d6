"""A goal that holds when the task starts (actions/composer.py, ``_per_goal``): it wants no step, the
plan's other goals are planned, the world meets it, and a step that undoes it has it achieved again or
the plan refused. Before, a task one of whose goals already held and had no component to provide it (a
cup to stay on the table: nothing makes a cup "on" a table) was refused outright, and the refusal advised
stating the goal as a fact of the map, which it already was.

The store is tests/test_progression_joined.py's: a robot at a shelf when the plan starts, an object to
put away, and a component for it that, in two of the three stores, takes the robot from the shelf.
"""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from cbrs.actions.composer import Composer, PlanStatus
from cbrs.kb import KnowledgeBase
from tests.test_composition import EX
from tests.test_progression_joined import (
    AT_SHELF,
    LEAVES,
    PREFIXES,
    _component,
    _condition,
    _names,
    _parameter,
    _requirement,
    _store,
)

REQUIREMENT = _requirement("Req", {"obj": "Obj"}, [("Obj", "at", "Shelf"), ("Robot", "at", "Shelf")])
"""Put the object away and stay at the shelf: the second goal holds at the start."""


def _services(leaves: bool) -> str:
    model = [_parameter("obj", "Obj"), _condition("Effect", "Obj", "at", "Shelf")] + ([LEAVES] if leaves else [])
    return PREFIXES + _component("PutAway", " ; ".join(model)) + REQUIREMENT


@pytest.fixture(scope="module")
def stores(tmp_path_factory: pytest.TempPathFactory) -> Iterator[dict[str, KnowledgeBase]]:
    made = {
        "stays": _store(tmp_path_factory.mktemp("held"), _services(leaves=False), reachieve=False),
        "leaves, drives back": _store(tmp_path_factory.mktemp("held"), _services(leaves=True), reachieve=True),
        "leaves": _store(tmp_path_factory.mktemp("held"), _services(leaves=True), reachieve=False),
    }
    yield made
    for kb in made.values():
        kb.close()


def test_a_goal_that_holds_needs_no_step_and_the_world_meets_it(stores: dict[str, KnowledgeBase]) -> None:
    result = Composer(stores["stays"]).compose(EX + "Req")
    assert result.status is PlanStatus.PLANNED and result.plan is not None, [u.text() for u in result.unsatisfied]
    assert _names(result.plan) == ["PutAway"]
    held = next(goal for goal in result.plan.goals if goal.statement == AT_SHELF)
    assert held.source.step is None and held.source.name == "world"  # the runner checks it at the end


def test_a_goal_that_holds_and_a_step_undoes_is_achieved_again(stores: dict[str, KnowledgeBase]) -> None:
    result = Composer(stores["leaves, drives back"]).compose(EX + "Req")
    assert result.status is PlanStatus.PLANNED and result.plan is not None, [u.text() for u in result.unsatisfied]
    assert _names(result.plan) == ["PutAway", "GoToShelf"]
    held = next(goal for goal in result.plan.goals if goal.statement == AT_SHELF)
    assert held.source.step == 2  # the drive back, after the step that left


def test_a_goal_that_holds_and_nothing_achieves_again_is_refused_naming_its_undoer(
    stores: dict[str, KnowledgeBase],
) -> None:
    result = Composer(stores["leaves"]).compose(EX + "Req")
    assert result.status is not PlanStatus.PLANNED and result.plan is None
    (reason,) = result.unsatisfied
    assert f"({EX}Robot, {EX}at, {EX}Shelf)" in reason.text(), reason.text()
    assert [c.removeprefix(EX) for c in reason.deleted_by] == ["PutAway"]
