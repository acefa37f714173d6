"""The robots act on what they perceive and feel; the simulator's truth only referees the outcome."""

from __future__ import annotations

import math
from typing import Any

import pybullet as p

from cbrs.actions.composer import Composer
from cbrs.actions.events import Event
from cbrs.actions.runner import run_task
from cbrs.kb import KnowledgeBase, Statement
from cbrs.kb.semantic_map import SemanticMap
from cbrs.sim.components import SimEnvironment
from cbrs.sim.perceived import PerceivedWorld
from cbrs.sim.referee import Referee
from cbrs.sim.world import HomeWorld, open_world

CAMERA_SOURCES = ("Kinect01", "CeilingCamera01", "CeilingCamera02")


def test_the_belief_finds_objects_and_people_with_the_cameras_alone() -> None:
    with open_world(seed=2) as world:
        belief = PerceivedWorld(world)
        assert belief.objects == {} and belief.people == {}
        belief.look()
        assert belief.frames >= 2
        for name in ("Cup", "Pen"):
            seen = belief.objects[name]
            assert seen.source == "Kinect01"
            assert math.dist(seen.position, world.pose(name).position) < 0.02
        person = belief.people["Person"]
        assert person.source.startswith("CeilingCamera")
        truth = world.pose("Person").position
        assert math.hypot(person.position[0] - truth[0], person.position[1] - truth[1]) < 0.05


def test_an_object_moved_far_from_where_it_was_believed_is_found_by_its_own_colour() -> None:
    with open_world() as world:
        belief = PerceivedWorld(world)
        belief.look()
        world.place("Cup", 8.3, 4.2)  # 0.9 m away, still on the table and in the Kinect's view
        world.step(0.2)
        belief.look(["Cup"], people=False)
        assert math.hypot(belief.objects["Cup"].position[0] - 8.3, belief.objects["Cup"].position[1] - 4.2) < 0.03


def test_a_run_verifies_on_the_belief_and_consults_the_referee_only_for_the_final_verdict(monkeypatch: Any) -> None:
    kb = KnowledgeBase.open(":memory:")
    calls: list[str] = []
    finished: list[bool] = []
    original = Referee.decide

    def spied(self: Referee, *args: Any, **kwargs: Any) -> bool | None:
        calls.append("after the run" if finished else "during the run")
        return original(self, *args, **kwargs)

    monkeypatch.setattr(Referee, "decide", spied)

    def on_event(event: Event) -> None:
        if event.topic == "/cbrs/task":
            finished.append(True)

    with open_world(seed=1, semantic_map=SemanticMap.read(kb)) as world:
        environment = SimEnvironment(world, kb)
        result = run_task(kb, "RobotArmServeACup", environment, composer=Composer(kb), on_event=on_event)
        sources = {sighting.source for sighting in environment.belief.objects.values()}
    assert result.succeeded, result.report
    assert calls and set(calls) == {"after the run"}
    assert sources <= {*CAMERA_SOURCES, "left hand", "right hand", "left hand, let go", "right hand, let go"}
    located = next(goal for goal in result.goals if goal.statement.predicate.endswith("isLocated"))
    water = next(goal for goal in result.goals if goal.statement.predicate.endswith("contains"))
    assert (located.believed, located.holds) == (True, True)
    assert (water.believed, water.holds) == (True, True)


def _decoy(world: HomeWorld, where: tuple[float, float, float]) -> None:
    """A red cylinder the size of the cup, which is not in the map: what the Kinect cannot tell from the cup."""
    cup = world.objects["Cup"]
    radius, height = cup.size[0] / 2, cup.size[2]
    shape = p.createVisualShape(
        p.GEOM_CYLINDER, radius=radius, length=height, rgbaColor=cup.rgba, physicsClientId=world.client
    )
    p.createMultiBody(0.0, -1, shape, where, physicsClientId=world.client)


def test_a_robot_fooled_by_a_decoy_believes_the_task_done_and_the_referee_says_it_failed() -> None:
    kb = KnowledgeBase.open(":memory:")
    with open_world(semantic_map=SemanticMap.read(kb)) as world:

        def swap(event: Event) -> None:  # when the last step succeeded, swap the cup for a decoy
            if event.message.get("event") == "step_succeeded" and "FillCupFromTap" in event.message.get(
                "component", ""
            ):
                position = world.pose("Cup").position
                world.place("Cup", 9.5, 4.5)  # off the table: it drops to the kitchen floor
                _decoy(world, position)

        result = run_task(kb, "RobotArmServeACup", SimEnvironment(world, kb), composer=Composer(kb), on_event=swap)
    assert result.executed  # by the robots' belief, every step did its job
    assert not result.succeeded
    refuted = [goal.statement.predicate.rsplit("#", 1)[-1] for goal in result.refuted]
    assert "isLocated" in refuted
    located = next(goal for goal in result.goals if goal.statement.predicate.endswith("isLocated"))
    assert located.believed is True and located.holds is False
    assert result.to_dict()["status"] == "failed"


def test_an_effect_no_test_decides_is_believed_from_the_step_and_written_to_the_world_graph() -> None:
    kb = KnowledgeBase.open(":memory:")
    home, world_ns = "https://w3id.org/cbrs/home#", "https://w3id.org/cbrs/world#"
    with open_world(semantic_map=SemanticMap.read(kb)) as world:
        environment = SimEnvironment(world, kb)
        inspected = Statement(home + "Cup", home + "isInspectedBy", home + "Person")  # no computable for it
        assert (world_ns + "Cup", home + "isInspectedBy", world_ns + "Person") not in environment.observe().facts
        assert environment.verify(None, inspected, {}) is None  # type: ignore[arg-type]
        assert (world_ns + "Cup", home + "isInspectedBy", world_ns + "Person") in environment.observe().facts
