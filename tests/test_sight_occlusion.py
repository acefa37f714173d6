"""What stands between a camera and what it looks for, and where the seed may put the person.

The check before a run (``sim.sight``) projected an object's or the person's outline through the camera's
model and ignored the map's solid boxes: the pen behind the shelf of docs/examples/glasses_on_the_shelf.ttl
passed, and Kinect01's image has 5 of its pixels. And it took the person at their map pose, which the
seed moves up to 15 cm each way (``sim.world.Spread``): a person the check accepted could start out of view.
One world (the glasses' home, built, not run)."""

from __future__ import annotations

import dataclasses
import re
from collections.abc import Iterator
from pathlib import Path

import pytest

from cbrs.kb import KnowledgeBase
from cbrs.kb.camera_view import MAX_HIDDEN, Occluder, hidden, sight_blocked
from cbrs.kb.semantic_map import Box, Camera, MapError, Pose, SemanticMap
from cbrs.sim import sight
from cbrs.sim.errors import NotVisibleError
from cbrs.sim.perception import recognise_object
from cbrs.sim.world import HomeWorld, Perturbation, Spread, open_world

EXAMPLES = Path(__file__).parent.parent / "docs" / "examples"
WORLD = "https://w3id.org/cbrs/world#"
LAB = "https://example.org/lab#"

CRATE = Occluder("crate", Box(1.0, 2.0, -0.5, 0.5, 0.0, 1.0))


@pytest.mark.parametrize(
    ("eye", "point", "cut"),
    [
        pytest.param((0.0, 0.0, 0.5), (3.0, 0.0, 0.5), ["crate"], id="through"),
        pytest.param((0.0, 0.0, 2.0), (3.0, 0.0, 1.5), [], id="over"),
        pytest.param((0.0, 0.0, 3.0), (1.5, 0.0, 1.0), [], id="ends-on-its-top"),
        pytest.param((0.0, 0.0, 0.5), (1.5, 0.0, 0.5), ["crate"], id="ends-inside"),
        pytest.param((0.0, 0.5, 0.5), (3.0, 0.5, 0.5), [], id="along-a-face"),
        pytest.param((1.5, 0.0, 0.5), (1.5, 0.0, 0.5), [], id="no-line"),
    ],
)
def test_a_sight_line_is_cut_by_a_box_it_enters(
    eye: tuple[float, ...], point: tuple[float, ...], cut: list[str]
) -> None:
    assert sight_blocked(eye, point, [CRATE]) == cut


def test_a_thing_is_hidden_when_more_than_the_allowed_part_of_its_sight_lines_is_cut() -> None:
    eye = (0.0, 0.0, 0.9)
    points = [(3.0, 0.0, 0.9), (3.0, 0.0, 2.5), (3.0, 0.0, 2.6), (3.0, 0.0, 2.7)]  # the first one behind
    why = hidden(eye, points, [CRATE])
    assert why.startswith("1 of the 4 sight lines to the points outlining it pass through crate (1)")
    assert hidden(eye, points, [CRATE], max_hidden=0.25) == ""
    assert hidden(eye, points[1:], [CRATE]) == ""
    with pytest.raises(ValueError, match="max_hidden is a fraction from 0 up to"):
        hidden(eye, points, [CRATE], max_hidden=1.0)


@pytest.fixture(scope="module")
def glasses_world() -> Iterator[HomeWorld]:
    kb = KnowledgeBase.open(":memory:")
    for graph in ("ontology", "map"):
        kb.load([EXAMPLES / "glasses_on_the_shelf.ttl"], graph=graph)
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        yield world


def test_the_occluders_are_the_maps_solid_boxes(glasses_world: HomeWorld) -> None:
    names = {occluder.iri.rsplit("#", 1)[1] for occluder in sight.occluders(glasses_world.map)}
    assert {"KitchenTable", "TableShelf1", "WaterDispenser01", "CytonDualArm01", "WallSouth"} <= names
    assert not names & {"P3DX01", "Person", "Kinect01", "CeilingCamera01", "Pen", "Kitchen", "BelowTheTap"}


def test_the_pen_behind_the_shelf_is_hidden_as_the_kinects_image_shows(glasses_world: HomeWorld) -> None:
    world = glasses_world
    camera, blockers = world.cameras["Kinect01"], sight.occluders(world.map)
    frame = camera.capture()
    pen = world.map.objects[WORLD + "Pen"]
    where = world.pose("Pen").position
    outline = sight.object_outline(pen, where)
    assert sight.unseen(camera, outline) == ""  # in frame: what the check said before
    why = sight.unseen(camera, outline, blockers)
    assert "sight lines to the points outlining it pass through TableShelf1" in why
    with pytest.raises(NotVisibleError):
        recognise_object(frame, pen.colour)
    refused = str(sight.OutOfViewError(LAB + "RecognisePen_Kinect01", pen.iri, where, [("Kinect01", why)]))
    assert "RecognisePen_Kinect01 would look for the Pen at (8.06, 3.30, 0.76) with Kinect01" in refused
    assert re.search(r"Kinect01: \d of the 8 sight lines .* pass through TableShelf1 \(\d\)", refused)
    assert "or what hides it out of the way" in refused
    glasses = world.map.objects[LAB + "Glasses1"]  # on the shelf: in plain view, and found
    assert sight.unseen(camera, sight.object_outline(glasses, world.pose("Glasses1").position), blockers) == ""
    recognise_object(frame, glasses.colour)


def test_a_person_the_check_accepts_is_in_view_at_every_seed(glasses_world: HomeWorld) -> None:
    """CeilingCamera01's image ends at x 0.43 at the shirt's top: a person at x 0.72 is in view at their
    map pose, but the seed may move them 15 cm west, where the image's border cuts their shirt."""
    camera = glasses_world.cameras["CeilingCamera01"]
    person = next(iter(glasses_world.map.people.values()))
    near_the_edge = dataclasses.replace(person, start=Pose(0.72, 3.6))
    assert sight.unseen(camera, sight.person_outline(near_the_edge, spread=0.0)) == ""  # the check before
    assert "fall on or past the border" in sight.unseen(camera, sight.person_outline(near_the_edge))

    def cut_at(where: Pose, seed: int) -> bool:
        dx, dy = Perturbation.from_seed(seed).person
        moved = dataclasses.replace(person, start=Pose(where.x + dx, where.y + dy))
        return bool(sight.unseen(camera, sight.person_outline(moved, spread=0.0)))

    assert any(cut_at(near_the_edge.start, seed) for seed in range(20))  # what a run met
    inside = Pose(0.72 + Spread().person, 3.6)  # as far in as the spread reaches
    assert sight.unseen(camera, sight.person_outline(dataclasses.replace(person, start=inside))) == ""
    assert not any(cut_at(inside, seed) for seed in range(200))


def test_a_camera_of_the_map_may_allow_part_of_a_thing_hidden(glasses_world: HomeWorld) -> None:
    """``home:occlusionTolerance`` is the camera's own fraction: read from the map, handed to the simulated
    camera and used by ``sight.unseen``; a value that is no fraction is refused naming the camera."""
    assert Camera("c", (0.0, 0.0, 1.0), 45.0).occlusion_tolerance == MAX_HIDDEN
    camera, blockers = glasses_world.cameras["Kinect01"], sight.occluders(glasses_world.map)
    pen = glasses_world.map.objects[WORLD + "Pen"]
    outline = sight.object_outline(pen, glasses_world.pose("Pen").position)
    why = sight.unseen(camera, outline, blockers)
    cut, lines = (int(n) for n in re.findall(r"(\d+) of the (\d+) sight lines", why)[0])
    assert 0 < cut < lines  # where it settled, part of the pen shows over the shelf's edge
    strict = camera.spec
    try:
        camera.spec = dataclasses.replace(strict, max_hidden=cut / lines)
        assert sight.unseen(camera, outline, blockers) == ""
        assert sight.unseen(camera, outline, blockers, max_hidden=0.0) == why  # one call's own fraction
        camera.spec = dataclasses.replace(strict, max_hidden=(cut - 1) / lines)
        assert sight.unseen(camera, outline, blockers).startswith(f"{cut} of the {lines} sight lines")
    finally:
        camera.spec = strict

    kb = KnowledgeBase.open(":memory:")
    kinect = "https://w3id.org/cbrs/service#Kinect01"
    told = (
        "PREFIX home: <https://w3id.org/cbrs/home#> "
        "INSERT DATA { GRAPH <https://w3id.org/cbrs/graph/map> { <%s> home:occlusionTolerance %s } }"
    )
    kb.update(told % (kinect, "0.5"))
    assert SemanticMap.read(kb).cameras[kinect].occlusion_tolerance == 0.5
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        assert world.cameras["Kinect01"].spec.max_hidden == 0.5
    kb.update(told.replace("INSERT", "DELETE") % (kinect, "0.5"))
    with pytest.raises(MapError, match=r"(?s)Kinect01.*home:occlusionTolerance of 1\.0.*nothing was changed"):
        kb.update(told % (kinect, "1.0"))  # an update of the map is checked as a run reads it
    assert SemanticMap.read(kb).cameras[kinect].occlusion_tolerance == MAX_HIDDEN
