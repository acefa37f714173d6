"""A shirt the person tracker can take something else for (docs/tasks.md "People: none, one or several").

The tracker finds a person by the largest patch of their shirt's colour in a ceiling camera's image. A
shirt in a colour of the base's marker (green front, magenta rear in the bundled home) outweighs the
marker's patch while in view, but with the person out of view the tracker reported the marker as them
(a scratch run: 32 pixels of the rear patch where 20 pass), so a task that tracks such a person is
refused before anything moves (``LookAlikeMarkerError``); an object of the shirt's colour that a ceiling
camera sees with the person is said, not refused. Map checks only: no simulation.
"""

from __future__ import annotations

import dataclasses

import pytest

from cbrs.kb import KnowledgeBase
from cbrs.kb.home_check import check_home
from cbrs.kb.person_choice import LookAlikeMarkerError, LookAlikePeopleError, people_check, person_for, shirt_clashes
from cbrs.kb.semantic_map import Pose, SemanticMap

WORLD = "https://w3id.org/cbrs/world#"
SVC = "https://w3id.org/cbrs/service#"
STEP = SVC + "TrackPerson_CeilingCamera01"


def _wearing(smap: SemanticMap, colour: str) -> SemanticMap:
    """The bundled map with its person's shirt in ``colour``."""
    person = dataclasses.replace(smap.people[WORLD + "Person"], colour=colour)
    return dataclasses.replace(smap, people={person.iri: person})


@pytest.fixture(scope="module")
def bundled(bundled_kb: KnowledgeBase) -> SemanticMap:
    return SemanticMap.read(bundled_kb)


@pytest.mark.parametrize(
    ("colour", "patch"),
    [pytest.param("magenta", "rear", id="rear"), pytest.param("Green", "front", id="front-any-case")],
)
def test_a_shirt_in_a_colour_of_the_marker_is_refused_for_a_task_that_tracks_them(
    bundled: SemanticMap, colour: str, patch: str
) -> None:
    smap = _wearing(bundled, colour)
    check_home(smap)  # the map is taken: the tasks that track nobody run
    with pytest.raises(LookAlikeMarkerError) as refused:
        person_for(smap, STEP)
    error = refused.value
    assert error.thing == WORLD + "Person" and error.step == STEP and error.colour == colour
    assert error.other == WORLD + "P3DX01Marker" and error.patch == patch
    assert (
        f"wears a {colour} shirt, the colour of P3DX01Marker's {patch} patch, and TrackPerson_CeilingCamera01"
        in str(error)
    )
    assert "give the person a home:colourName (and home:rgba) the marker does not have" in str(error)


def test_the_bundled_person_and_a_second_in_their_own_colour_pass(bundled: SemanticMap) -> None:
    assert person_for(bundled, STEP) == bundled.people[WORLD + "Person"]
    assert shirt_clashes(bundled) == []
    assert [(c.person.name, c.refusal) for c in people_check(bundled)] == [("Person", None)]


def test_twins_are_refused_before_the_marker_is_looked_at(bundled: SemanticMap) -> None:
    resident = dataclasses.replace(bundled.people[WORLD + "Person"], colour="magenta")
    twin = dataclasses.replace(resident, iri=WORLD + "Twin", start=Pose(1.0, 1.0))
    smap = dataclasses.replace(bundled, people={resident.iri: resident, twin.iri: twin})
    with pytest.raises(LookAlikePeopleError):
        person_for(smap, STEP, [twin.iri])


def test_an_object_of_the_shirt_s_colour_in_a_camera_s_view_with_them_is_said_not_refused(bundled: SemanticMap) -> None:
    smap = _wearing(bundled, "red")  # the red cup on the kitchen table: both ceiling cameras see it and them
    assert person_for(smap, STEP) == smap.people[WORLD + "Person"]
    (clash,) = shirt_clashes(smap)
    assert (clash.kind, clash.other, clash.colour) == ("object", WORLD + "Cup", "red")
    assert clash.cameras == (SVC + "CeilingCamera01", SVC + "CeilingCamera02")
    assert "Person wears red, as Cup is, in the view of CeilingCamera01 and CeilingCamera02" in clash.said
    (checked,) = people_check(smap)
    assert checked.refusal is None and checked.clashes == (clash,)
    cup = dataclasses.replace(smap.objects[WORLD + "Cup"], start=Pose(30.0, 30.0))  # under no camera
    assert shirt_clashes(dataclasses.replace(smap, objects={cup.iri: cup})) == []
