"""A new object written in Turtle may share its colour with something else of the home (there are six
colours): the base's green marker, the pen's blue, the person's yellow shirt. Perception must tell
the things apart by where they are, not average them (docs/examples/remote_on_the_table.ttl)."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from cbrs.actions.colour_warnings import perceived_things
from cbrs.actions.composer import Composer
from cbrs.actions.runner import run_task
from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.semantic_map import SemanticMap
from cbrs.sim.components import SimEnvironment
from cbrs.sim.errors import AmbiguousSightingError, CutByBorderError
from cbrs.sim.perception import locate_robot, recognise_object, track_person
from cbrs.sim.world import open_world
from tests.home_layout import HANDOVER_POSE

EXAMPLES = Path(__file__).parent.parent / "docs" / "examples"
HOME, WORLD = PREFIXES["home"], PREFIXES["world"]
RGBA = {
    "green": "0.10 0.70 0.20 1",
    "blue": "0.10 0.20 0.85 1",
    "yellow": "0.95 0.85 0.10 1",
    "cyan": "0.05 0.80 0.80 1",
}


def remote_of(colour: str, task: bool = False) -> KnowledgeBase:
    """A store whose map has the example's remote control on the kitchen table, painted ``colour``."""
    kb = KnowledgeBase.open(":memory:")
    kb.load([EXAMPLES / "remote_on_the_table.ttl"], graph="map")
    if task:
        kb.load([EXAMPLES / "fetch_my_remote.ttl"], graph="requirements")
    remote = f"<{WORLD}Remote1>"
    kb.update(f"DELETE WHERE {{ GRAPH graph:map {{ {remote} home:colourName ?c ; home:rgba ?r }} }}")
    kb.update(
        f"INSERT DATA {{ GRAPH graph:map {{ {remote} home:colourName '{colour}' ; home:rgba '{RGBA[colour]}' }} }}"
    )
    return kb


def test_a_green_object_does_not_hide_the_bases_green_marker() -> None:
    kb = remote_of("green")
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        for pose in (None, HANDOVER_POSE):  # at its start, and parked by the table next to the remote
            if pose is not None:
                world.base.place(pose)
                world.step(0.05)
            truth = world.base_pose()
            for camera in ("CeilingCamera01", "CeilingCamera02"):
                seen = locate_robot(world.camera(camera).capture(), world.marker_model)
                assert math.hypot(seen.x - truth.x, seen.y - truth.y) < 0.05, (camera, pose)


def test_a_yellow_object_does_not_pull_the_person_estimate() -> None:
    kb = remote_of("yellow")
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        x, y, _ = world.pose(world.person_name).position
        seen = track_person(world.camera("CeilingCamera01").capture(), "yellow")
    assert math.hypot(seen.x - x, seen.y - y) < 0.05


def test_two_blue_things_are_told_apart_by_where_they_are_believed() -> None:
    kb = remote_of("blue")
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        frame = world.camera("Kinect01").capture()
        pen = world.pose("Pen").position
        with pytest.raises(AmbiguousSightingError) as ambiguous:
            recognise_object(frame, "blue")  # the pen or the remote? not a point between them
        assert ambiguous.value.colour == "blue" and len(ambiguous.value.positions) == 2
        near_pen = recognise_object(frame, "blue", near=(8.07, 3.30))
        assert math.hypot(near_pen.x - pen[0], near_pen.y - pen[1]) < 0.02


@pytest.mark.parametrize(("colour", "task"), [("blue", "FetchMyRemote"), ("green", "FetchMyPen")])
def test_a_task_runs_beside_an_object_of_a_shared_colour(colour: str, task: str) -> None:
    """The remote in the pen's blue is fetched, not the pen; with a green remote on the table the base
    is still localised and the pen fetched."""
    kb = remote_of(colour, task=True)
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        environment = SimEnvironment(world, kb)
        result = run_task(kb, task, environment, composer=Composer(kb))
    assert result.succeeded, result.report.reason if result.report else result.composition.unsatisfied
    assert not result.replans
    facts = {(r["thing"].value, r["relation"].value, r["other"].value) for r in kb.select("world_facts")}
    fetched, stayed = ("Remote1", "Pen") if task == "FetchMyRemote" else ("Pen", "Remote1")
    assert (WORLD + fetched, HOME + "isWith", WORLD + "Person") in facts
    assert (WORLD + stayed, HOME + "isLocatedOn", WORLD + "KitchenTable") in facts
    # what its colour warnings would be of: what it perceived, not the other thing of the fetched one's colour
    looked = environment.looked_for()
    assert {WORLD + fetched, WORLD + "Person"} <= looked and WORLD + stayed not in looked
    assert perceived_things(kb, result) == {WORLD + fetched, WORLD + "Person", WORLD + "P3DX01MarkerColours"}


def test_an_object_at_the_edge_of_the_kinects_view_is_said_to_be_cut_by_it() -> None:
    kb = remote_of("cyan")
    remote = f"<{WORLD}Remote1>"
    kb.update(  # one request: the remote without a pose in between is a map no task reads, and is refused
        f"DELETE WHERE {{ GRAPH graph:map {{ {remote} home:x ?x ; home:y ?y }} }};"
        f"INSERT DATA {{ GRAPH graph:map {{ {remote} home:x 7.15 ; home:y 3.30 }} }}"  # across the left edge
    )
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world, pytest.raises(CutByBorderError) as cut:
        recognise_object(world.camera("Kinect01").capture(), "cyan")
    assert cut.value.camera == "Kinect01" and 0 < cut.value.on_border < cut.value.pixels
    assert "cut by the border of Kinect01's image" in str(cut.value)
