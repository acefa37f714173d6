"""Set-down spots of an arm whose partner is busy (sim/place_spots.py): a place where another arm has
spots that hold the whole footprint leaves this arm none, so that the thing goes to that arm (the west
bowl's apple); but an arm holding something else cannot take it, and its spots took away the edge spot
that would have served. The spots now count only the arms that can take the step (``able``,
:func:`able_mounts`), for one thing alone and for several a plan puts on one place (sim/packing.py); a
carry no free arm has a spot for names the busy arm that has one and what it holds, not the objects
(sim/services.py). And SPOT_INSET and SEEN_SHORT are settings (docs/settings.md)."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from cbrs.kb import KnowledgeBase
from cbrs.kb.semantic_map import SemanticMap
from cbrs.settings import setting
from cbrs.sim.components import SimEnvironment
from cbrs.sim.context import SimContext, SkillFailed
from cbrs.sim.grasping import SEEN_SHORT, ObjectModel, seen_centre_z, seen_short
from cbrs.sim.packing import PackingRule, arrange, set_down_spots
from cbrs.sim.perception import recognise_object
from cbrs.sim.place_spots import SPOT_INSET, able_mounts, least_inset, place_spots, reach_of, spot_inset
from cbrs.sim.services import approach, carry, pick_up, put_down
from cbrs.sim.values import GraspPlan, designator, to_json
from cbrs.sim.world import open_world
from tests.helpers_examples import EXAMPLES

LAB8 = "https://example.org/lab8#"
HOME, WORLD = "https://w3id.org/cbrs/home#", "https://w3id.org/cbrs/world#"
DEVICE = "CytonDualArm01"
BOWL_EAST = "home:minX 8.20 ; home:maxX 8.40 ; home:minY 3.05 ; home:maxY 3.25"
# The bowl between the arms, its middle 0.66 m from the left arm's mount, and a right arm the lab says
# reaches 0.70 m: it reaches the bowl's east part, not a spot with the whole apple over the bowl.
BOWL_MIDDLE = "home:minX 7.55 ; home:maxX 7.75 ; home:minY 3.10 ; home:maxY 3.30"
SHORTER_RIGHT_ARM = """
PREFIX home: <https://w3id.org/cbrs/home#>
PREFIX world: <https://w3id.org/cbrs/world#>
DELETE { GRAPH <https://w3id.org/cbrs/graph/map> { world:CytonDualArm01RightArm home:reach ?r } }
INSERT { GRAPH <https://w3id.org/cbrs/graph/map> { world:CytonDualArm01RightArm home:reach 0.70 } }
WHERE { GRAPH <https://w3id.org/cbrs/graph/map> { world:CytonDualArm01RightArm home:reach ?r } }
"""
# A mat at the table's west, which the left arm reaches and the shorter right arm does not; a strip along
# the table's front.
WEST_MAT = """
PREFIX home: <https://w3id.org/cbrs/home#>
PREFIX lab8: <https://example.org/lab8#>
INSERT DATA { GRAPH <https://w3id.org/cbrs/graph/map> { lab8:WestMat a home:ObjectPlace ;
    home:minX 7.30 ; home:maxX 7.50 ; home:minY 3.05 ; home:maxY 3.25 ; home:minZ 0.75 ; home:maxZ 0.78 .
  lab8:Strip a home:ObjectPlace ;
    home:minX 7.20 ; home:maxX 8.20 ; home:minY 3.10 ; home:maxY 3.30 ; home:minZ 0.75 ; home:maxZ 0.78 } }
"""
CIRCLE = PackingRule(footprint="circle")


@pytest.fixture(scope="module")
def lab_kb(tmp_path_factory: pytest.TempPathFactory) -> Iterator[KnowledgeBase]:
    text = (EXAMPLES / "lab8_fruit_bowl.ttl").read_text(encoding="utf-8")
    assert BOWL_EAST in text
    path: Path = tmp_path_factory.mktemp("busy") / "fruit_bowl.ttl"
    path.write_text(text.replace(BOWL_EAST, BOWL_MIDDLE), encoding="utf-8")
    kb = KnowledgeBase.open(":memory:")
    kb.load([path], graph="ontology")
    kb.load([path], graph="map")
    kb.update(SHORTER_RIGHT_ARM)
    kb.update(WEST_MAT)
    yield kb


@pytest.fixture(scope="module")
def busy(lab_kb: KnowledgeBase) -> Iterator[SimContext]:
    """The world at seed 0, the left arm holding the cup and the right the apple (the last test of this
    file carries the apple on)."""
    with open_world(seed=0, semantic_map=SemanticMap.read(lab_kb)) as world:
        environment = SimEnvironment(world, lab_kb)
        environment.perceive()
        context = environment.context
        for iri in (WORLD + "Cup", LAB8 + "Apple1"):
            obj = world.map.objects[iri]
            x, y, _ = world.pose(obj.name).position
            seen = recognise_object(world.camera("Kinect01").capture(), obj.colour, near=(x, y))
            plan = GraspPlan(iri, ObjectModel.of(obj))
            approach(context, {"graspPose": to_json(plan), "objectPosition": to_json(seen)}, DEVICE)
            pick_up(context, {}, DEVICE)
        assert world.arm("left").held == world.body("Cup") and world.arm("right").held == world.body("Apple1")
        yield context


def test_an_arm_that_cannot_take_the_step_leaves_the_other_its_edge_spots(lab_kb: KnowledgeBase) -> None:
    smap = SemanticMap.read(lab_kb)
    bowl, apple = smap.things[LAB8 + "FruitBowl1"], smap.objects[LAB8 + "Apple1"]
    left = reach_of(smap.arms[WORLD + "CytonDualArm01LeftArm"])
    right = reach_of(smap.arms[WORLD + "CytonDualArm01RightArm"])
    assert right[2] == pytest.approx(0.70)
    whole = place_spots(smap, bowl, apple.size, [left], [])[1]
    assert whole and place_spots(smap, bowl, apple.size, [right], [])[1] == []  # the left arm's to take
    assert place_spots(smap, bowl, apple.size, [right], [], [left, right])[1] == []
    edge = place_spots(smap, bowl, apple.size, [right], [], [right])[1]  # the left arm holds something
    assert edge and not set(edge) & set(whole)
    box, inset = bowl.box, SPOT_INSET - 1e-9
    for x, y in edge:
        assert box.min_x + inset <= x <= box.max_x - inset and box.min_y + inset <= y <= box.max_y - inset


def test_a_packing_of_several_things_counts_only_the_arms_that_can_take_the_step(lab_kb: KnowledgeBase) -> None:
    """The apple and a small thing after it onto a metre-long strip along the table's front, by an arm at the
    right arm's mount reaching 0.63 m, which reaches only its front edge: with every arm of the map counted,
    the left arm's spots (the whole apple over the strip) take away its own, and the packing (sim/packing.py:
    set_down_spots, arrange) has none; counting only the arms that can take the step (the left holding
    something), its edge spots, and the two things packed along them."""
    smap = SemanticMap.read(lab_kb)
    strip, apple = smap.things[LAB8 + "Strip"], smap.objects[LAB8 + "Apple1"].size
    small = (0.03, 0.03, 0.03)
    right = smap.arms[WORLD + "CytonDualArm01RightArm"].mount
    short = (right[0], right[1], 0.63)
    assert set_down_spots(smap, strip, apple, [short], [], [small], CIRCLE)[1] == []
    assert arrange(smap, strip, [apple, small], [short], [], CIRCLE) is None
    edge = place_spots(smap, strip, apple, [short], [], [short])[1]
    _, spots = set_down_spots(smap, strip, apple, [short], [], [small], CIRCLE, able=[short], later_able=[[short]])
    assert edge and sorted(spots) == sorted(edge)
    packed = arrange(smap, strip, [apple, small], [short], [], CIRCLE, able=[[short], [short]])
    assert packed is not None and packed[0] in edge


def test_no_spot_for_a_free_arm_names_the_busy_arm_that_has_one(busy: SimContext) -> None:
    """The apple, held by the right arm, to the mat at the table's west, which only the left arm reaches:
    before, "... the left arm reaches it, but the objects on it leave no spot free", nothing being on it."""
    with pytest.raises(SkillFailed) as refused:
        carry(busy, {"targetPlace": designator(LAB8 + "WestMat", HOME + "ObjectPlace")}, DEVICE)
    said = str(refused.value)
    assert said.startswith("no spot of WestMat is clear for the Apple1 (around (7.40, 3.15)): ")
    assert said.endswith(": the left arm, which reaches it, holds the Cup")
    assert busy.world.arm("right").held == busy.world.body("Apple1")  # nothing moved


def test_with_the_left_arm_holding_the_cup_the_right_sets_the_apple_down_in_the_bowl(busy: SimContext) -> None:
    """The carry used to fail: "no spot of FruitBowl1 is clear for the Apple1 ... the left arm reaches it",
    the left arm, which has the bowl's middle, holding the cup and so unable to take the apple."""
    context, world = busy, busy.world
    right = reach_of(world.map.arms[WORLD + "CytonDualArm01RightArm"])
    assert able_mounts(world, "Apple1") == able_mounts(world, "Pen", "Apple1") == [right]
    assert len(able_mounts(world, "Pen", "Apple1", "Cup")) == 2
    carry(context, {"targetPlace": designator(LAB8 + "FruitBowl1", HOME + "ObjectPlace")}, DEVICE)
    put_down(context, {}, DEVICE)
    x, y, _ = world.pose("Apple1").position
    assert world.arm("left").held == world.body("Cup")
    bowl = world.map.things[LAB8 + "FruitBowl1"].box
    assert bowl.min_x < x < bowl.max_x and bowl.min_y < y < bowl.max_y


def test_spot_inset_and_seen_short_are_settings(monkeypatch: pytest.MonkeyPatch) -> None:
    assert setting("spot_inset").default() == SPOT_INSET == spot_inset()
    assert setting("seen_short").default() == SEEN_SHORT == seen_short()
    assert least_inset(0.06) == SPOT_INSET
    monkeypatch.setenv("CBRS_SPOT_INSET", "0.01")
    assert least_inset(0.06) == 0.01 and least_inset(0.012) == 0.006  # a place narrower than twice it: its middle
    monkeypatch.setenv("CBRS_SEEN_SHORT", "0.03")
    assert seen_centre_z(0.80, 0.045, 0.07) == 0.80  # 2.5 cm short is within 3 cm
    monkeypatch.setenv("CBRS_SEEN_SHORT", "0.02")
    assert seen_centre_z(0.80, 0.045, 0.07) == pytest.approx(0.80 + 0.0225 - 0.035)
    monkeypatch.setenv("CBRS_SPOT_INSET", "5")  # millimetres meant
    with pytest.raises(ValueError, match=r"CBRS_SPOT_INSET='5': 5 must be a length in metres from 0 to 0.05"):
        least_inset(0.06)
    monkeypatch.setenv("CBRS_SEEN_SHORT", "nan")
    with pytest.raises(ValueError, match=r"CBRS_SEEN_SHORT"):
        seen_short()
