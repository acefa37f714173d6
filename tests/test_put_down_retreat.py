"""The way back of a put-down (sim/skills.py: _retreat, _clear_way): after letting go the hand backs off
along its approach, then, beside a tall object, rises over its top before folding home; each straight
line is checked for collisions piece by piece, and a put-down whose way back runs into something is
refused before it lets go, by the hold's dry run too. PutWineOnCupboard (a 7 cm variant of the 30 cm
bottle) at seed 0: the right arm set the bottle down on the relay spot beside the torso, its back-off
drove the upper arm into the Kinect and the fingers pushed the bottle over. Checked here on the
kinematics copies only: nothing is stepped."""

from __future__ import annotations

import math
from collections.abc import Iterator

import pytest

from cbrs.kb import KnowledgeBase
from cbrs.kb.semantic_map import SemanticMap
from cbrs.sim import relay, skills
from cbrs.sim.arms import ArmSide
from cbrs.sim.components import SimEnvironment
from cbrs.sim.errors import MovesRefusedError
from cbrs.sim.geometry import Region
from cbrs.sim.grasping import GraspKind, ObjectModel, compute_grasp_pose
from cbrs.sim.hold_choice import Candidates, refuse_moves
from cbrs.sim.perception import ObjectEstimate
from cbrs.sim.world import HomeWorld, open_world
from tests.helpers_examples import wine7_store

WORLD, LAB = "https://w3id.org/cbrs/world#", "https://example.org/lab#"
TABLE_TOP = 0.75


@pytest.fixture(scope="module")
def store(tmp_path_factory: pytest.TempPathFactory) -> KnowledgeBase:
    """The bundled store with the wine bottle narrowed to 7 cm (the 7.5 cm one is refused by the jaws) and
    the low cupboard."""
    return wine7_store(tmp_path_factory.mktemp("wine"))


@pytest.fixture(scope="module")
def world(store: KnowledgeBase) -> Iterator[HomeWorld]:
    """Its home at seed 0; the tests only plan on its kinematics copies."""
    with open_world(seed=0, semantic_map=SemanticMap.read(store)) as home:
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
    assert "would come within 1 cm of the Kinect01Mast" in refused  # what it would hit, named
    # 6 cm west, the straight back-off leaves the arm's reach instead: nothing is hit, and the refusal says so
    west = Region("KitchenTableRelay", 7.65, 7.73, 3.03, 3.11, TABLE_TOP, TABLE_TOP + 0.3)
    out = skills.can_carry(world, seen, ArmSide.RIGHT, model, west)
    assert "backing off once it is let go: no inverse kinematics at (" in out and " cm into the " in out, out
    # where it stands, the same hold's way back is clear
    here = Region("TakenFrom", x - 0.02, x + 0.02, y - 0.02, y + 0.02, TABLE_TOP, TABLE_TOP + 0.3)
    assert skills.can_carry(world, seen, ArmSide.RIGHT, model, here) == ""


def test_the_pass_looks_farther_after_three_spots_beside_the_torso_are_refused(
    store: KnowledgeBase, world: HomeWorld, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The bottle passed from the right arm to the left (PutWineOnCupboard, for the cupboard west of the
    robot): the three relay spots nearest both mounts, 2 cm apart beside the torso, are refused by the
    right arm's back-off into the Kinect's mast; then spots RELAY_SPREAD from every refused one are asked,
    and one west of them serves. Before, the pass was refused after the three (as it still is with no
    spread tries). The holds' moves are the giver's, from where the bottle stands (its take included)."""
    context = SimEnvironment(world, store).context
    model = ObjectModel.of(world.map.objects[LAB + "WineBottle1"]).by(GraspKind.SIDE)
    x, y, z = world.pose("WineBottle1").position
    seen = ObjectEstimate(x, y, z, None, world.objects["WineBottle1"].size, "green", "Kinect01", 0.0, 100)
    asked: list[tuple[tuple[float, float], str]] = []

    def moves(spot: Region, given: ObjectModel, _: ObjectModel) -> str:
        refused = skills.can_carry(world, seen, ArmSide.RIGHT, given, spot)
        asked.append((spot.center[:2], refused))
        refuse_moves(refused, given, ArmSide.RIGHT, "passing the WineBottle1", spot)
        return ""

    def pass_it() -> Region:
        held = Candidates([model])
        return relay.relay_spot(context, seen, held, held, ArmSide.RIGHT, ArmSide.LEFT, moves)[0]

    spot = pass_it()
    first = [at for at, _ in asked[: relay.RELAY_MOVES_TRIES]]
    assert all("backing off once it is let go" in why for _, why in asked[: relay.RELAY_MOVES_TRIES])
    assert max(math.dist(a, b) for a in first for b in first) < 0.05  # side by side
    for n, (at, _) in enumerate(asked[relay.RELAY_MOVES_TRIES :], relay.RELAY_MOVES_TRIES):
        assert all(math.dist(at, before) >= relay.RELAY_SPREAD for before, _ in asked[:n])
    assert len(asked) <= relay.RELAY_MOVES_TRIES + relay.RELAY_SPREAD_TRIES
    assert asked[-1] == (spot.center[:2], "")
    assert spot.center[0] < min(at[0] for at in first) - relay.RELAY_SPREAD  # west of them, toward the left arm

    asked.clear()
    monkeypatch.setattr(relay, "RELAY_SPREAD_TRIES", 0)
    with pytest.raises(MovesRefusedError, match="backing off once it is let go"):
        pass_it()
    assert [at for at, _ in asked] == first


def test_spots_are_asked_nearest_first_then_spread_from_the_refused() -> None:
    spots = [(7.75 + 0.02 * i, 3.07) for i in range(12)]  # 2 cm apart
    refused: list[tuple[float, float]] = []
    asked = []
    for spot in relay._asked(spots, refused):
        asked.append(spot)
        refused.append(spot)  # every spot asked is refused
    spread = math.ceil(relay.RELAY_SPREAD / 0.02 - 1e-9)  # in grid steps
    tail = list(range(relay.RELAY_MOVES_TRIES - 1 + spread, len(spots), spread))
    assert asked == [spots[i] for i in [*range(relay.RELAY_MOVES_TRIES), *tail]]
