"""The check before a run asks whether the camera a recognition step looks with sees the object whole
(new-user trial 2): reading glasses moved to x 8.27 on a wider shelf failed "partly out of view" at
Kinect01's recognition, after the base had driven to the table. The camera's pose, field of view and
range are the map's, so the check projects the object's outline through the camera's model
(``sim.sight``) and refuses the run with ``OutOfViewError`` before anything moves."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pybullet as p
import pytest

from cbrs.actions.composer import Composer
from cbrs.actions.runner import run_task
from cbrs.kb import KnowledgeBase
from cbrs.kb.semantic_map import SemanticMap
from cbrs.sim import sight
from cbrs.sim.components import SimEnvironment
from cbrs.sim.errors import NotVisibleError
from cbrs.sim.perception import recognise_object
from cbrs.sim.world import HomeWorld, open_world

EXAMPLES = Path(__file__).parent.parent / "docs" / "examples"
LAB = "https://example.org/lab#"


def _store(glasses_x: float | None = None) -> KnowledgeBase:
    kb = KnowledgeBase.open(":memory:")
    for graph in ("ontology", "map"):
        kb.load([EXAMPLES / "glasses_on_the_shelf.ttl"], graph=graph)
    if glasses_x is not None:  # one request: a map read in between would have the glasses off the shelf
        moved = f"<{LAB}Glasses1> home:x {glasses_x} . <{LAB}TableShelf1> home:maxX 8.4"
        kb.update(
            f"DELETE WHERE {{ GRAPH graph:map {{ <{LAB}Glasses1> home:x ?x . <{LAB}TableShelf1> home:maxX ?m }} }};"
            f"INSERT DATA {{ GRAPH graph:map {{ {moved} }} }}"
        )
    return kb


@pytest.fixture(scope="module")
def world() -> Iterator[HomeWorld]:
    with open_world(seed=0, semantic_map=SemanticMap.read(_store())) as built:
        yield built


@pytest.mark.parametrize(
    ("x", "y"), [(8.10, 3.15), (8.16, 3.15), (8.18, 3.15), (8.12, 3.00), (8.24, 3.00)], ids=lambda v: f"{v:.2f}"
)
def test_the_check_sees_what_the_kinects_image_shows_whole(world: HomeWorld, x: float, y: float) -> None:
    """The model's verdict is the recogniser's on the rendered image, the glasses put there (no step)."""
    glasses = world.map.objects[LAB + "Glasses1"]
    centre = (x, y, 0.85 + glasses.size[2] / 2)
    p.resetBasePositionAndOrientation(world.body("Glasses1"), centre, (0, 0, 0, 1), physicsClientId=world.client)
    camera = world.cameras["Kinect01"]
    why = sight.unseen(camera, sight.object_outline(glasses, centre))
    try:
        recognise_object(camera.capture(), glasses.colour)
        seen = True
    except NotVisibleError:  # cut by the border, or not in the image at all
        seen = False
    assert seen == (why == ""), why


def test_glasses_the_kinect_cannot_see_whole_are_refused_before_the_base_drives() -> None:
    kb = _store(glasses_x=8.27)
    kb.load([EXAMPLES / "fetch_my_glasses.ttl"], graph="requirements")
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        started, base = world.time, world.base_pose()
        with pytest.raises(sight.OutOfViewError) as refused:
            run_task(kb, "FetchMyGlasses", SimEnvironment(world, kb), composer=Composer(kb))
        assert world.time == started and world.base_pose() == base  # nothing moved
    error = refused.value
    assert error.thing == LAB + "Glasses1" and [camera for camera, _ in error.cameras] == ["Kinect01"]
    assert "border of its 192 x 144 image" in error.cameras[0][1]
    assert "the Glasses1 at (8.27" in str(error) and "move it in the map (home:x, home:y)" in str(error)
