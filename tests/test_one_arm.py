"""A robot with one arm (docs/simulation.md, "A robot with one arm"): the home check takes one arm or none, and
refuses two of one side by name; the simulation builds only the arms the map has; a task the one arm cannot
do is refused before anything moves, naming the arm and what it does not reach; one it can do runs."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from cbrs.actions.composer import Composer
from cbrs.actions.runner import run_task
from cbrs.kb import KnowledgeBase
from cbrs.kb.home_check import HomeError, check_home
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.semantic_map import SemanticMap
from cbrs.sim.arms import ArmSide
from cbrs.sim.components import SimEnvironment
from cbrs.sim.errors import UnknownEntityError
from cbrs.sim.run_checks import CannotLoadError, OutOfReachError
from cbrs.sim.world import HomeWorld, open_world
from tests.helpers_examples import updated_store

WORLD = PREFIXES["world"]
TASKS = Path(__file__).parent / "data" / "tasks"
RIGHT_ONLY, LEFT_ONLY = "lab6_one_arm.ru", "lab6_one_arm_left.ru"
PENCIL_ON_THE_LEFT = """@prefix home: <https://w3id.org/cbrs/home#> . @prefix world: <https://w3id.org/cbrs/world#> .
world:Pencil1 a home:Pencil ; home:shapeKind "box" ; home:sizeX 0.16 ; home:sizeY 0.012 ; home:sizeZ 0.012 ;
    home:massKg 0.01 ; home:colourName "yellow" ; home:rgba "0.95 0.85 0.10 1" ;
    home:isLocatedOn world:KitchenTable ; home:x 7.36 ; home:y 3.30 ; home:yaw 0.3 .
"""


@pytest.fixture(scope="module")
def left_only(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[KnowledgeBase, HomeWorld]]:
    """The left arm alone, a pencil on the table's west (which only the left arm reaches) and its task."""
    kb = updated_store(LEFT_ONLY)
    pencil = tmp_path_factory.mktemp("one_arm") / "pencil.ttl"
    pencil.write_text(PENCIL_ON_THE_LEFT, encoding="utf-8")
    kb.load([pencil], graph="map")
    kb.load([TASKS / "fetch_my_pencil.ttl"], graph="requirements")
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        yield kb, world


@pytest.mark.parametrize(
    ("updates", "sides"),
    [
        pytest.param((RIGHT_ONLY,), ["right"], id="right-only"),
        pytest.param((LEFT_ONLY,), ["left"], id="left-only"),
        pytest.param((RIGHT_ONLY, LEFT_ONLY), [], id="no-arm"),
    ],
)
def test_the_home_check_takes_one_arm_or_none(updates: tuple[str, ...], sides: list[str]) -> None:
    smap = SemanticMap.read(updated_store(*updates))
    check_home(smap)  # no HomeError
    assert sorted(arm.side for arm in smap.arms.values()) == sides
    assert not any(iri.endswith("Hand") for iri in smap.things)  # the taken arm's gripper went with it


@pytest.mark.parametrize(
    ("side", "expected"),
    [
        pytest.param(
            "right",
            r'CytonDualArm01RightArm .* has home:armSide "right", as CytonDualArm01LeftArm has: the simulated '
            r'robot takes one arm a side; give one of them home:armSide "left"',
            id="two-right",
        ),
        pytest.param("centre", r"CytonDualArm01LeftArm .* has home:armSide 'centre': an arm is on the", id="centre"),
    ],
)
def test_two_arms_of_one_side_or_a_side_of_neither_are_refused_by_name(side: str, expected: str) -> None:
    kb = updated_store()
    kb.update(
        "PREFIX home: <https://w3id.org/cbrs/home#> PREFIX world: <https://w3id.org/cbrs/world#> "
        "DELETE { GRAPH <https://w3id.org/cbrs/graph/map> { world:CytonDualArm01LeftArm home:armSide ?s } } "
        f'INSERT {{ GRAPH <https://w3id.org/cbrs/graph/map> {{ world:CytonDualArm01LeftArm home:armSide "{side}" }} }} '
        "WHERE { GRAPH <https://w3id.org/cbrs/graph/map> { world:CytonDualArm01LeftArm home:armSide ?s } }"
    )
    with pytest.raises(HomeError, match=expected):
        check_home(SemanticMap.read(kb))


def test_the_world_builds_only_the_arms_of_the_map(left_only: tuple[KnowledgeBase, HomeWorld]) -> None:
    _, world = left_only
    assert list(world.arms) == [ArmSide.LEFT] and "RightArm" not in world.bodies
    with pytest.raises(UnknownEntityError, match="'right arm'; known: left arm"):
        world.arm(ArmSide.RIGHT)


def test_a_pass_between_arms_the_one_arm_robot_cannot_make_is_refused_before_anything_moves(
    left_only: tuple[KnowledgeBase, HomeWorld],
) -> None:
    """Only the left arm reaches the pencil, and the platform at the table's docking pose is beyond it: with
    two arms the left passes it to the right (tests/test_turtle_tasks_arms.py); with one, the run is refused."""
    kb, world = left_only
    started, base = world.time, world.base_pose()
    with pytest.raises(CannotLoadError) as refused:
        run_task(kb, "FetchMyPencil", SimEnvironment(world, kb), composer=Composer(kb))
    assert world.time == started and world.base_pose() == base  # nothing moved
    assert refused.value.thing == WORLD + "Pencil1"
    said = str(refused.value)
    assert "no free arm reaches the base's platform at (8.50, 2.20)" in said
    assert "the left arm (CytonDualArm01LeftArm) reaches 0.85 m from (7.57, 2.55), 0.99 m away" in said
    assert "it is the robot's one arm, and there is no other to pass a thing to" in said


def test_an_object_out_of_the_one_arms_reach_is_refused_before_anything_moves(
    left_only: tuple[KnowledgeBase, HomeWorld],
) -> None:
    kb, world = left_only
    started = world.time
    with pytest.raises(OutOfReachError) as refused:
        run_task(kb, "FetchMyPen", SimEnvironment(world, kb), composer=Composer(kb))
    assert world.time == started
    assert [arm for arm, *_ in refused.value.arms] == [WORLD + "CytonDualArm01LeftArm"]


def test_a_robot_with_no_arm_is_refused_an_arm_task_before_anything_moves() -> None:
    kb = updated_store(RIGHT_ONLY, LEFT_ONLY)
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        started = world.time
        with pytest.raises(OutOfReachError, match=r"the Cup .*: CytonDualArm01 has no arm \(home:hasArm\)"):
            run_task(kb, "RobotArmServeACup", SimEnvironment(world, kb), composer=Composer(kb))
        assert world.time == started


def test_the_left_arm_alone_serves_a_cup() -> None:
    """The one simulation run: the left arm takes the cup below the tap, sets it down, and, free again,
    pushes the lever itself (with two arms the other arm pushes it)."""
    kb = updated_store(LEFT_ONLY)
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        result = run_task(kb, "RobotArmServeACup", SimEnvironment(world, kb), composer=Composer(kb))
        assert world.arm(ArmSide.LEFT).held is None
    assert result.succeeded, result.report.reason if result.report else result.composition.unsatisfied
    assert not result.replans
    facts = {(r["thing"].value, r["relation"].value, r["other"].value) for r in kb.select("world_facts")}
    assert (WORLD + "Cup", PREFIXES["home"] + "contains", PREFIXES["home"] + "Water") in facts
