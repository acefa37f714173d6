"""An object with one approach gets the approach choice's dry run too (services.approach, hold_choice.first_clear):
nu16 repro 04's 18 cm bottle, held by its side, cannot be carried to the front spot (the straight line
there leaves the left arm's reach). Before, its one approach skipped the dry run: the arm took the bottle,
the carry failed after moving, and the bottle had to be set down again before a re-plan. Now the approach
fails before anything moves, saying why, and so does the re-plan."""

from __future__ import annotations

from pathlib import Path

import pytest

from cbrs.actions.composer import Composer
from cbrs.actions.runner import run_task
from cbrs.kb import KnowledgeBase
from cbrs.kb.semantic_map import SemanticMap
from cbrs.sim.components import SimEnvironment
from cbrs.sim.world import open_world
from tests.test_nu16_settle import MAP, TASK, tilt


class Watching(SimEnvironment):
    """The environment, noting whether an arm held anything whenever a plan was given up."""

    holding: list[bool]

    def settle(self) -> None:
        self.holding.append(any(arm.held is not None for arm in self.world.arms.values()))
        super().settle()


def test_a_carry_the_dry_run_refuses_fails_at_the_approach_before_anything_moves(tmp_path: Path) -> None:
    kb = KnowledgeBase.open(":memory:")
    for name, text, graph in (("map", MAP, "map"), ("task", TASK, "requirements")):
        (tmp_path / f"{name}.ttl").write_text(text, encoding="utf-8")
        kb.load([tmp_path / f"{name}.ttl"], graph=graph)
    with open_world(0, semantic_map=SemanticMap.read(kb)) as world:
        before = world.pose("Bottle1").position
        env = Watching(world, kb)
        env.holding = []
        result = run_task(kb, "https://example.org/lab#MoveBottle", env, composer=Composer(kb), max_replans=1)
        after = world.pose("Bottle1")
        held = [arm.held for arm in world.arms.values()]
    assert not result.succeeded and result.report is not None
    reports = [replan.report for replan in result.replans] + [result.report]
    assert len(reports) == 2 and env.holding == [False]  # re-planned once, nothing in hand to set down
    for report in reports:
        failed = [step for step in report.to_dict()["steps"] if step["outcome"] == "failed"]
        assert [step["component"].rsplit("#", 1)[-1] for step in failed] == ["ApproachToObject_CytonDualArm01"]
        reason = failed[0]["attempts"][-1]["reason"]
        assert reason.startswith("taking the Bottle1 to FrontSpot1: refused before anything moved")
        assert "the left arm would not get the Bottle1 by its side grasp past carrying it to (7.53, 3.12)" in reason
    assert held == [None, None]
    assert after.position == pytest.approx(before, abs=1e-3) and tilt(after.orientation) < 1.0  # untouched
