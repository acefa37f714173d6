"""A pass's relay spot, and the spot an arm's choice of how to take an object dry-runs its carry to, keep
the carry clearance too (sim/relay.py: relay_spot, CLEAR_TRIES; sim/arm_choice.py: carry_check, taking_to,
_loading_by), as the spot a carry aims at does (tests/test_carry_clearance.py).

The world: the bundled store with the tap's lever moved (a 2 cm square, 0.85-0.90 m up) to the front of
the kitchen table, at (7.66-7.68, 3.10-3.12), past which the left arm carries the bundled cup, which only
it reaches, to be passed to the right arm, which loads the platform. Before, the first relay spot whose
holds' moves the planning would make was taken, (7.80, 3.06) for the cup where the map puts it: the left
arm's carry there comes within 1 cm of the lever; in FetchMyCup (seed 0, the spot (7.78, 3.06) from the
Kinect's estimate) it touched the lever at 17.2 s, and now, set down at (7.78, 3.10), the arms keep 2 cm
from it. Checked here on the kinematics copies only (no task runs)."""

from __future__ import annotations

import logging
import math
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest

from cbrs.actions.composer import Composer
from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.semantic_map import SemanticMap
from cbrs.sim import arm_choice, grounding, relay, skills
from cbrs.sim.arm_choice import Loading
from cbrs.sim.arms import ArmSide
from cbrs.sim.components import SimEnvironment
from cbrs.sim.context import SimContext
from cbrs.sim.geometry import Pose2D
from cbrs.sim.grasping import ObjectModel
from cbrs.sim.perception import ObjectEstimate
from cbrs.sim.values import designator
from cbrs.sim.world import HomeWorld, open_world

WORLD, HOME = PREFIXES["world"], PREFIXES["home"]
TASKS = Path(__file__).parent / "data" / "tasks"
LEFT, RIGHT = ArmSide.LEFT, ArmSide.RIGHT
LEVER = (7.66, 7.68, 3.10, 3.12, 0.85, 0.90)

Scene = tuple[SimContext, ObjectEstimate, ObjectModel, Pose2D, Loading]


def _lever_moved() -> KnowledgeBase:
    """The bundled store with the lever moved, a tray both arms reach, and PutCupOnTray (tests/data/tasks)."""
    kb = KnowledgeBase.open(":memory:")
    kb.update(
        "INSERT DATA { GRAPH graph:map { world:TrayPlace a home:ObjectPlace ; home:minX 7.85 ; home:maxX 8.00 ; "
        "home:minY 3.05 ; home:maxY 3.20 ; home:minZ 0.75 ; home:maxZ 0.75 } }"
    )
    kb.load([TASKS / "put_cup_on_tray.ttl"], graph="requirements")
    x0, x1, y0, y1, z0, z1 = LEVER
    kb.update(
        "DELETE { GRAPH graph:map { world:Tap01 home:minX ?a ; home:maxX ?b ; home:minY ?c ; home:maxY ?d ; "
        "home:minZ ?e ; home:maxZ ?f } } "
        f"INSERT {{ GRAPH graph:map {{ world:Tap01 home:minX {x0} ; home:maxX {x1} ; home:minY {y0} ; "
        f"home:maxY {y1} ; home:minZ {z0} ; home:maxZ {z1} }} }} "
        "WHERE { GRAPH graph:map { world:Tap01 home:minX ?a ; home:maxX ?b ; home:minY ?c ; home:maxY ?d ; "
        "home:minZ ?e ; home:maxZ ?f } }"
    )
    return kb


@pytest.fixture(scope="module")
def scene() -> Iterator[Scene]:
    """The scene, with the put-down's check of its way back left out (``skills._clear_way``; tested in
    tests/test_put_down_retreat.py): with the lever here, that check refuses the one relay spot whose
    holds keep clear (its back-off comes by the lever), and these tests are of the clearance alone."""
    kb = _lever_moved()
    with pytest.MonkeyPatch.context() as alone, open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        alone.setattr(skills, "_clear_way", lambda *_: "")
        context = SimEnvironment(world, kb).context
        x, y, z = world.pose("Cup").position
        seen = ObjectEstimate(x, y, z, None, (0.06, 0.06, 0.10), "red", "Kinect01", world.time, 500)
        cup = ObjectModel.of(world.map.objects[WORLD + "Cup"])
        base = grounding.docking_pose(world.map.things[WORLD + "KitchenTable"])
        with pytest.MonkeyPatch.context() as before:  # the choice as before the clearance was asked
            before.setattr(skills, "plan_carry", _blind(skills.plan_carry))
            old = arm_choice.who_loads(context, seen, cup, base)
        yield context, seen, cup, base, old


def _blind(real: Callable[..., skills.DryRun]) -> Callable[..., skills.DryRun]:
    """The dry runs as before the clearance was asked: what the planning refuses, nothing of how near."""

    def plan_carry(*args: Any, **kwargs: Any) -> skills.DryRun:
        return skills.DryRun(real(*args, **kwargs).refused)

    return plan_carry


def test_the_relay_spot_is_one_whose_holds_keep_clear_of_the_lever(scene: Scene) -> None:
    context, seen, cup, base, old = scene
    assert old.giver is not None and old.spot is not None
    was = arm_choice.carry_clear(context, old.giver.arm, old.spot, (seen, old.giver.model))
    loading = arm_choice.who_loads(context, seen, cup, base)
    assert loading.giver is not None and loading.spot is not None
    giver, spot = loading.giver, loading.spot
    refused, brushed = arm_choice.carry_check(context, giver.arm, spot, (seen, giver.model))
    assert (old.giver.arm, old.loader.arm) == (giver.arm, loading.loader.arm) == (LEFT, RIGHT)
    assert "would come within 1 cm of the Tap01" in was
    assert (refused, brushed) == ("", "")
    assert spot.center != old.spot.center
    assert math.dist(spot.center[:2], old.spot.center[:2]) < 0.06  # a near spot, not across the table


def test_when_no_relay_spot_keeps_clear_the_first_that_serves_is_taken_and_logged(
    scene: Scene, monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    """With one spot allowed to come near it (CLEAR_TRIES 1), that spot: as before, the log saying so."""
    context, seen, cup, base, old = scene
    monkeypatch.setattr(relay, "CLEAR_TRIES", 1)
    with caplog.at_level(logging.INFO, logger="cbrs.sim"):
        loading = arm_choice.who_loads(context, seen, cup, base)
    assert loading.spot is not None and old.spot is not None
    assert loading.spot.center == old.spot.center
    said = [r.getMessage() for r in caplog.records if "relay spots asked keep 1 cm clear" in r.getMessage()]
    assert len(said) == 1 and "would come within 1 cm of the Tap01" in said[0]


def test_of_two_arms_that_can_take_it_there_the_one_whose_carry_keeps_clear_takes_it(
    scene: Scene, monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    """The cup seen at (7.80, 3.05), where both arms reach it, the right nearer, to go to a tray both reach
    (PutCupOnTray): the right arm takes it. With a stand-in saying every take and carry of the right arm
    comes within 1 cm of an appliance, the left arm takes it (taking_to, who_takes); with every one of
    both arms' so, the right, as before, and the log says so."""
    context, seen, cup, _, _ = scene
    plan = Composer(context.kb).compose("PutCupOnTray").plan
    assert plan is not None
    ctx = SimEnvironment(context.world, context.kb).context
    ctx.plan, ctx.component = plan, PREFIXES["svc"] + "ApproachToObject_CytonDualArm01"
    ctx.given = {
        "cup": designator(WORLD + "Cup", HOME + "Cup"),
        "place": designator(WORLD + "TrayPlace", HOME + "ObjectPlace"),
    }
    there = ObjectEstimate(7.80, 3.05, seen.z, None, seen.size, "red", "Kinect01", seen.time, 500)
    real = skills.plan_carry

    def near(*sides: ArmSide) -> Callable[..., skills.DryRun]:
        def plan_carry(world: HomeWorld, seen: ObjectEstimate, side: ArmSide, *rest: Any, **kw: Any) -> skills.DryRun:
            planned = real(world, seen, side, *rest, **kw)
            asked = kw.get("clearance") is not None  # as the clearance is asked, of the arms of ``sides``
            stand_in = "the stand-in appliance is within 1 cm" if asked and ArmSide(side) in sides else ""
            return skills.DryRun(planned.refused, planned.brushed or stand_in)

        return plan_carry

    assert arm_choice.reaching(ctx, there.x, there.y) == [RIGHT, LEFT]
    chosen = arm_choice.who_takes(ctx, there, cup)
    monkeypatch.setattr(skills, "plan_carry", near(RIGHT))
    other = arm_choice.who_takes(ctx, there, cup)
    monkeypatch.setattr(skills, "plan_carry", near(LEFT, RIGHT))
    with caplog.at_level(logging.INFO, logger="cbrs.sim"):
        both = arm_choice.who_takes(ctx, there, cup)
    assert (chosen.arm, other.arm, both.arm) == (RIGHT, LEFT, RIGHT)
    assert chosen.purpose == other.purpose == "taking the Cup to TrayPlace"
    said = [r.getMessage() for r in caplog.records if "keeps no spot's clearance" in r.getMessage()]
    assert len(said) == 1 and said[0].startswith("taking the Cup to TrayPlace: the right arm")
    assert "the stand-in appliance is within 1 cm" in said[0]
