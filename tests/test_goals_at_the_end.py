"""The task's goals checked after the last step read "a gripper" as any arm, a step's effect as the arm at work.

EraserCupPen (docs/execution.md) keeps the cup in the left hand while the right sets the pen down; the
goal (home:Cup, home:isGraspedBy, home:Gripper), checked at the end since 78b8ac1, was decided for the arm
of the last step, the right, and the run failed with the cup in hand. No simulation step here: the
referee's and the robots' answers are recorded with the side each is asked about.
"""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from cbrs.actions import runner
from cbrs.actions.plan import Binding, Plan, Source
from cbrs.kb import KnowledgeBase
from cbrs.kb.model import Statement
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.semantic_map import SemanticMap
from cbrs.sim.arms import ArmSide
from cbrs.sim.components import SimEnvironment
from cbrs.sim.world import HomeWorld, open_world

HOME = PREFIXES["home"]
CUP_HELD = Statement(HOME + "Cup", HOME + "isGraspedBy", HOME + "Gripper")


@pytest.fixture(scope="module")
def home() -> Iterator[tuple[KnowledgeBase, HomeWorld]]:
    kb = KnowledgeBase.open(":memory:")
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        yield kb, world


def _asked(environment: SimEnvironment, monkeypatch: pytest.MonkeyPatch) -> list[tuple[str, ArmSide | None]]:
    asked: list[tuple[str, ArmSide | None]] = []

    def referee(name: str, side: ArmSide | None) -> bool:
        asked.append(("referee", side))
        return side is None  # the cup is in the other hand than the arm at work

    def belief(name: str, side: ArmSide | None) -> bool:
        asked.append(("belief", side))
        return side is None

    monkeypatch.setattr(environment.referee, "grasped", referee)
    monkeypatch.setattr(environment.belief, "grasped", belief)
    return asked


def test_a_goal_about_a_gripper_is_any_arms_at_the_end_and_the_arm_at_works_before(
    home: tuple[KnowledgeBase, HomeWorld], monkeypatch: pytest.MonkeyPatch
) -> None:
    kb, world = home
    environment = SimEnvironment(world, kb)
    environment.context.arm = ArmSide.RIGHT  # the last step's, the pen's put-down
    asked = _asked(environment, monkeypatch)
    assert environment.audit(CUP_HELD) is False  # during the run: the arm at work's
    with environment.at_the_end():
        assert environment.audit(CUP_HELD) is True
        assert environment.verify(None, CUP_HELD, {}) is True
    assert environment.audit(CUP_HELD) is False  # and the arm at work's again after
    assert asked == [("referee", ArmSide.RIGHT), ("referee", None), ("belief", None), ("referee", ArmSide.RIGHT)]


def test_the_runner_checks_the_goals_at_the_end(
    home: tuple[KnowledgeBase, HomeWorld], monkeypatch: pytest.MonkeyPatch
) -> None:
    kb, world = home
    environment = SimEnvironment(world, kb)
    environment.context.arm = ArmSide.RIGHT
    _asked(environment, monkeypatch)
    goal = Binding("effect", "cupHeld", Source("requirement"), "Exact", 1.0, statement=CUP_HELD)
    plan = Plan("task", "requirement", "direct", (), (goal,), 1.0, 0.0)
    (check,) = runner._check_goals(environment, plan, {})
    assert (check.believed, check.holds) == (True, True)
