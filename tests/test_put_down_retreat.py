"""The way back of a put-down (sim/skills.py: _retreat, _clear_way): after letting go the hand backs off
along its approach, then, beside a tall object, rises over its top before folding home; each straight
line is checked for collisions piece by piece, and a put-down whose way back runs into something is
refused before it lets go, by the hold's dry run too. PutWineOnCupboard (a 7 cm variant of the 30 cm
bottle) at seed 0: the right arm set the bottle down on the relay spot beside the torso, its back-off
drove the upper arm into the Kinect and the fingers pushed the bottle over. Checked here on the
kinematics copies only: nothing is stepped."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from cbrs.kb import KnowledgeBase
from cbrs.kb.semantic_map import SemanticMap
from cbrs.sim import skills
from cbrs.sim.arms import ArmSide
from cbrs.sim.geometry import Region
from cbrs.sim.grasping import GraspKind, ObjectModel, compute_grasp_pose
from cbrs.sim.perception import ObjectEstimate
from cbrs.sim.world import HomeWorld, open_world

EXAMPLES = Path(__file__).parent.parent / "docs" / "examples"
WORLD, LAB = "https://w3id.org/cbrs/world#", "https://example.org/lab#"
TABLE_TOP = 0.75


@pytest.fixture(scope="module")
def world(tmp_path_factory: pytest.TempPathFactory) -> Iterator[HomeWorld]:
    """The bundled home at seed 0 with the wine bottle narrowed to 7 cm (the 7.5 cm one is refused by the
    jaws); the tests only plan on its kinematics copies."""
    text = (EXAMPLES / "wine_bottle.ttl").read_text(encoding="utf-8")
    narrowed = text.replace("home:sizeX 0.075 ; home:sizeY 0.075", "home:sizeX 0.07 ; home:sizeY 0.07")
    assert narrowed != text
    wine = tmp_path_factory.mktemp("wine") / "wine7.ttl"
    wine.write_text(narrowed, encoding="utf-8")
    kb = KnowledgeBase.open(":memory:")
    for graph in ("ontology", "map"):
        kb.load([wine, EXAMPLES / "low_cupboard.ttl"], graph=graph)
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as home:
        yield home


def test_a_tall_object_gets_a_rise_over_its_top_and_a_short_one_does_not(world: HomeWorld) -> None:
    spec, hand = world.arm_specs[ArmSide.RIGHT], world.arm(ArmSide.RIGHT).hand
    for iri, name, rises in ((LAB + "WineBottle1", "WineBottle1", True), (WORLD + "Cup", "Cup", False)):
        model = ObjectModel.of(world.map.objects[iri]).by(GraspKind.SIDE)
        x, y, z = world.pose(name).position
        size = world.objects[name].size
        grasp = compute_grasp_pose(model, (x, y, z), None, spec.mount, spec.yaw, (size[0], size[1]), hand)
        place = grasp.position
        legs = skills._retreat(grasp, place)
        assert legs[0] == grasp.backed_off(place)
        top = place[2] - grasp.bottom_offset + model.height
        assert (len(legs) == 2) is rises, (name, legs, top)
        if rises:  # straight up from the backed-off pose to ABOVE_CLEARANCE over the top
            assert legs[1][:2] == legs[0][:2]
            assert legs[1][2] == pytest.approx(top + skills.ABOVE_CLEARANCE)


def test_a_put_down_whose_way_back_runs_into_the_kinect_is_refused_by_the_dry_run(world: HomeWorld) -> None:
    model = ObjectModel.of(world.map.objects[LAB + "WineBottle1"]).by(GraspKind.SIDE)
    x, y, z = world.pose("WineBottle1").position
    seen = ObjectEstimate(x, y, z, None, world.objects["WineBottle1"].size, "green", "Kinect01", 0.0, 100)
    # the relay spot the pass chose at seed 0, beside the torso, under the Kinect
    relay = Region("KitchenTableRelay", 7.71, 7.79, 3.03, 3.11, TABLE_TOP, TABLE_TOP + 0.3)
    refused = skills.can_carry(world, seen, ArmSide.RIGHT, model, relay)
    assert "lowering it onto KitchenTableRelay" in refused
    assert "backing off once it is let go" in refused
    # where it stands, the same hold's way back is clear
    here = Region("TakenFrom", x - 0.02, x + 0.02, y - 0.02, y + 0.02, TABLE_TOP, TABLE_TOP + 0.3)
    assert skills.can_carry(world, seen, ArmSide.RIGHT, model, here) == ""
