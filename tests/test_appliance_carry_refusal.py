"""A take whose carry would hold the object into an appliance is refused before the run, with advice from
the refusal's own values (sim/arm_choice.py: check_take, asked by run_checks.PlanChecks, and floor_advice;
sim/transit.py: band_advice). The fifth round's trial (docs/tasks.md, lab5_wide_carry_hands.ttl with
green_cup.ttl, RobotArmServeACup): the lab's forearm band, 6 cm below the grasp point, kept over the green
cup, holds the red cup up against the tap's spout; the refusal came at ApproachToObject, after one re-plan,
and ended "set the Cup or its place nearer the arm". No task runs: the worlds are built and asked."""

from __future__ import annotations

import dataclasses
import re
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import NamedTuple

import pytest

from cbrs.actions.composer import Composer
from cbrs.actions.plan import Plan
from cbrs.kb import KnowledgeBase
from cbrs.kb.arm_bands import PANDA_SIDE_ARM, ArmBand
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.semantic_map import SemanticMap
from cbrs.sim import arm_choice, skills
from cbrs.sim.arm_choice import CannotCarryError
from cbrs.sim.arms import COLLISION_MARGIN, ArmSide
from cbrs.sim.components import SimEnvironment
from cbrs.sim.world import HomeWorld, open_world

EXAMPLES = Path(__file__).parent.parent / "docs" / "examples"
WORLD = PREFIXES["world"]
TASK = "RobotArmServeACup"


def _trial() -> KnowledgeBase:
    kb = KnowledgeBase.open(":memory:")
    kb.update((EXAMPLES / "lab5_unhand.ru").read_text(encoding="utf-8"))
    kb.load([EXAMPLES / "lab5_wide_carry_hands.ttl"], graph="map")
    for graph in ("ontology", "map"):
        kb.load([EXAMPLES / "green_cup.ttl"], graph=graph)
    return kb


def _given(kb: KnowledgeBase, world: HomeWorld, plan: Plan) -> None:
    SimEnvironment(world, kb).given(plan, {r.iri: r for r in kb.requirements()})


def _unasked(*_: object) -> None:
    raise AssertionError("the arm choice was asked before the run")


class Refused(NamedTuple):
    kb: KnowledgeBase
    world: HomeWorld
    plan: Plan
    error: CannotCarryError
    moved: bool
    limit: float
    """How low the cup's bottom must stay to pass the spout, from the map: its underside, less the margin
    and the cup's height."""


@pytest.fixture(scope="module")
def refused() -> Iterator[Refused]:
    kb = _trial()
    plan = Composer(kb).compose(TASK).plan
    assert plan is not None
    with open_world(seed=1, semantic_map=SemanticMap.read(kb)) as world:
        joints = {side: world.arm(side).joint_positions() for side in ArmSide}
        when = world.time
        with pytest.raises(CannotCarryError) as caught:
            _given(kb, world, plan)
        moved = world.time != when or {side: world.arm(side).joint_positions() for side in ArmSide} != joints
        spout = next(fixture for fixture in skills.appliances(world) if fixture.name == "Spout01")
        cup = world.map.objects[WORLD + "Cup"]
        yield Refused(kb, world, plan, caught.value, moved, spout.zmin - COLLISION_MARGIN - cup.size[2])


def test_the_take_is_refused_before_the_run_naming_the_spout_and_the_band(refused: Refused) -> None:
    """The plan's checks refuse it (no step runs, no re-plan), in the arm choice's words."""
    error = refused.error
    assert not refused.moved
    assert error.thing == WORLD + "Cup" and error.component.endswith("ApproachToObject_CytonDualArm01")
    assert "taking the Cup to BelowOfTap: refused before anything moved" in error.reason
    assert "would come within 1 cm of the Spout01" in error.reason
    assert "the arm's band 0.175-0.350 m back from the grasp point" in error.reason and "over the Cup2" in error.reason


def test_the_advice_is_the_bands_not_to_set_the_cup_nearer_the_arm(refused: Refused) -> None:
    """It says how low the cup must stay (the spout's underside less the margin and the cup's height), what
    holds it higher (the band over the green cup), the band that would do, and moving the green cup."""
    reason = refused.error.reason
    assert "nearer the arm" not in reason
    found = re.search(r"the Cup's bottom must stay at ([\d.]+) m or lower", reason)
    assert found is not None
    assert refused.limit - 0.0015 < float(found.group(1)) <= refused.limit
    assert "over the Cup2 (its top at " in reason.split("must stay at", 1)[1]
    assert "the WideLeftHand's band (home:sideGraspBand) no lower than " in reason
    assert "no narrower band would do: the Cup2 is behind the way itself" in reason
    assert "with the Cup2 moved off its way (home:x, home:y), or by another approach (home:graspApproach)" in reason


def _banded(refused: Refused, monkeypatch: pytest.MonkeyPatch, bands: Callable[[ArmBand], ArmBand]) -> None:
    for side in ArmSide:
        arm = refused.world.arm(side)
        stated = tuple(bands(band) for band in arm.hand.side_arm)
        monkeypatch.setattr(arm, "hand", dataclasses.replace(arm.hand, side_arm=stated))


def test_the_band_the_advice_names_lets_the_take_pass(refused: Refused, monkeypatch: pytest.MonkeyPatch) -> None:
    """The same hands with the forearm band as the advice says (its underside that high): the map's question
    passes the take, and the arm choice is not asked before the run."""
    found = re.search(r"no lower than ([\d.]+) cm below the grasp point", refused.error.reason)
    assert found is not None
    advised = -float(found.group(1)) / 100.0
    assert advised > -0.06
    _banded(refused, monkeypatch, lambda band: dataclasses.replace(band, underside=max(band.underside, advised)))
    monkeypatch.setattr(arm_choice, "who_takes", _unasked)
    _given(refused.kb, refused.world, refused.plan)


def test_a_carry_that_meets_no_appliance_costs_no_dry_run_before_the_run(
    refused: Refused, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The same hands with the bundled Panda arm's bands: the cup's top passes under the spout by the map,
    and the arm choice is not asked before the run."""
    for side in ArmSide:
        arm = refused.world.arm(side)
        monkeypatch.setattr(arm, "hand", dataclasses.replace(arm.hand, side_arm=PANDA_SIDE_ARM))
    monkeypatch.setattr(arm_choice, "who_takes", _unasked)
    _given(refused.kb, refused.world, refused.plan)
