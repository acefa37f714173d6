"""Homes of nobody and of several people (docs/tasks.md "What the home must contain").

Before, the simulated home took exactly one person: a lab's home with nobody modelled (tasks that only
move things) or with two residents was refused whatever task ran. The bundled home's ``world.ttl`` is
used with its person taken out, or with a caregiver beside them. One simulation run (a pen brought to
the caregiver of two people, about 40 s simulated); the rest checks maps, builds worlds or refuses a
task before anything moves.
"""

from __future__ import annotations

import json
from collections.abc import Iterator
from pathlib import Path

import pybullet as p
import pytest
from click.testing import CliRunner

from cbrs.actions.composer import Composer
from cbrs.actions.runner import RunResult, run_task
from cbrs.app import App
from cbrs.cli import cli
from cbrs.cli_home import home
from cbrs.kb import KnowledgeBase
from cbrs.kb.home_check import check_home
from cbrs.kb.person_choice import AmbiguousPersonError, LookAlikePeopleError, NoPersonError, look_alikes, person_for
from cbrs.kb.semantic_map import Person, Pose, SemanticMap, UnresolvedDesignatorError
from cbrs.sim import sight
from cbrs.sim.components import SimEnvironment
from cbrs.sim.world import HomeWorld, Perturbation, Spread, open_world

WORLD_FILE = Path(__file__).resolve().parents[1] / "ontologies" / "world.ttl"
HOME = "https://w3id.org/cbrs/home#"
WORLD = "https://w3id.org/cbrs/world#"
RESIDENT = """world:Person a home:Person , owl:NamedIndividual ; rdfs:label "the person in the living room"@en ;
    home:colourName "yellow" ; home:rgba "0.95 0.85 0.10 1" ;
    home:isLocated world:LivingRoom ; home:x 2.0 ; home:y 3.6 ; home:yaw 0.0 .
"""


def _caregiver(colour: str = "blue", rgba: str = "0.10 0.20 0.85 1", x: float = 4.6, y: float = 3.9) -> str:
    """A second person, in the living room under CeilingCamera01 and 2 m from the base's start."""
    return f"""world:Caregiver a home:Caregiver , owl:NamedIndividual ; rdfs:label "the caregiver"@en ;
    home:colourName "{colour}" ; home:rgba "{rgba}" ; home:x {x} ; home:y {y} ; home:yaw 0.0 .
"""


CAREGIVERS_PEN = """@prefix cbrs: <https://w3id.org/cbrs/core#> . @prefix home: <https://w3id.org/cbrs/home#> .
@prefix req: <https://w3id.org/cbrs/requirement#> . @prefix svc: <https://w3id.org/cbrs/service#> .
@prefix act: <https://w3id.org/cbrs/action#> .
req:FetchTheCaregiversPen a cbrs:Requirement ; cbrs:requestedBy svc:P3DX01 ; cbrs:deviceName "P3DX01" ;
    cbrs:serviceName "FetchTheCaregiversPen" ; cbrs:forTask act:FetchMyPen ;
    cbrs:hasOWLSModel [ a cbrs:OWLSModel ;
        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "pen" ; cbrs:parameterType home:Pen ] ;
        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "person" ; cbrs:parameterType home:Caregiver ] ;
        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "colourOfMarker" ;
            cbrs:parameterType home:ColourOfMarker ] ;
        cbrs:hasPrecondition [ a cbrs:Precondition ; cbrs:conditionSubject home:MobileRobot ;
            cbrs:conditionPredicate home:hasMarker ; cbrs:conditionObject home:ColourMarker ] ;
        cbrs:hasEffect [ a cbrs:Effect ; cbrs:conditionSubject home:Pen ; cbrs:conditionPredicate home:isWith ;
            cbrs:conditionObject home:Caregiver ] ] .
"""
"""FetchMyPen for the caregiver: its person input is of their class, which designates them alone."""


def _home(tmp_path: Path, *people: str) -> Path:
    """The bundled home with ``people`` in place of its one person."""
    text = WORLD_FILE.read_text(encoding="utf-8")
    assert RESIDENT in text
    written = tmp_path / "home.ttl"
    written.write_text(text.replace(RESIDENT, "\n".join(people)), encoding="utf-8")
    return written


def _store(tmp_path: Path, *people: str) -> KnowledgeBase:
    kb = KnowledgeBase.open(":memory:")
    kb.load([_home(tmp_path, *people)], graph="map", replace=True)
    (tmp_path / "task.ttl").write_text(CAREGIVERS_PEN, encoding="utf-8")
    kb.load([tmp_path / "task.ttl"], graph="requirements")
    return kb


def _person(name: str, colour: str) -> Person:
    return Person(WORLD + name, Pose(1.0, 1.0), colour, (0.5, 0.5, 0.5, 1.0))


# -- the home check and the report -------------------------------------------------------------------


def test_a_home_of_nobody_is_loaded_reported_and_drawn(tmp_path: Path) -> None:
    store, drawing = str(tmp_path / "store"), tmp_path / "home.svg"
    done = CliRunner().invoke(cli, ["--store", store, "load", "--graph", "map", "--replace", str(_home(tmp_path))])
    assert done.exit_code == 0, done.output
    done = CliRunner().invoke(cli, ["--store", store, "home", "--draw", str(drawing)])
    assert done.exit_code == 0, done.output
    assert "2 arms, 0 people, 3 cameras" in done.output
    assert "people: none: a task that tracks, goes to or hands something to a person is refused" in done.output
    assert "check: the simulation can build this home" in done.output
    assert 'class="home-person"' not in drawing.read_text(encoding="utf-8")
    said = json.loads(CliRunner().invoke(cli, ["--store", store, "home", "--json"]).output)
    assert said["verdict"] == "ok" and said["counts"]["people"] == 0 and said["people"].startswith("none")


def test_two_people_are_reported_and_people_in_one_shirt_colour_are_named(tmp_path: Path) -> None:
    kb = KnowledgeBase.open(":memory:")
    kb.load([_home(tmp_path, RESIDENT, _caregiver("yellow", "0.95 0.85 0.10 1"))], graph="map", replace=True)
    smap = SemanticMap.read(kb)
    check_home(smap)  # taken: only a task for one of them is refused
    assert look_alikes(smap) == [("yellow", [WORLD + "Caregiver", WORLD + "Person"])]
    done = CliRunner().invoke(cli, ["--store", ":memory:", "home"])
    assert "people: Person (yellow shirt)\n" in done.output  # the bundled home: one person, nothing to add
    done = CliRunner().invoke(home, ["--draw", str(tmp_path / "two.svg")], obj=App(":memory:", kb))
    assert done.exit_code == 0, done.output
    assert "people: Caregiver (yellow shirt), Person (yellow shirt); a task for one names them" in done.output
    assert "Caregiver and Person wear yellow: the tracker cannot tell them apart" in done.output
    drawn = (tmp_path / "two.svg").read_text(encoding="utf-8")
    assert drawn.count('class="home-person"') == 2
    assert "yellow shirt as Person's (the tracker cannot tell them apart)" in drawn


# -- which person a step means ------------------------------------------------------------------------


def test_the_person_a_step_means_is_the_one_designated_else_the_only_one() -> None:
    step = "https://w3id.org/cbrs/service#TrackPerson_CeilingCamera01"
    resident, caregiver, twin = _person("Person", "yellow"), _person("Caregiver", "blue"), _person("Twin", "Yellow")
    with pytest.raises(NoPersonError, match=r"has no individual in the map, and TrackPerson_CeilingCamera01 needs"):
        person_for(SemanticMap(), step)
    alone = SemanticMap(people={resident.iri: resident})
    assert person_for(alone, step) == resident == person_for(alone, step, [WORLD + "Cup"])
    two = SemanticMap(people={resident.iri: resident, caregiver.iri: caregiver})
    assert person_for(two, step, [WORLD + "Pen", caregiver.iri]) == caregiver
    with pytest.raises(AmbiguousPersonError) as refused:
        person_for(two, step, [WORLD + "Pen"])
    assert refused.value.people == (caregiver.iri, resident.iri) and refused.value.step == step
    assert "the map has 2 people (Caregiver, Person) and the task designates none of them" in str(refused.value)
    with pytest.raises(AmbiguousPersonError):
        person_for(two, step, [resident.iri, caregiver.iri])
    three = SemanticMap(people={p.iri: p for p in (resident, caregiver, twin)})
    assert person_for(three, step, [caregiver.iri]) == caregiver  # the twins do not matter to them
    with pytest.raises(LookAlikePeopleError) as twins:
        person_for(three, step, [resident.iri])
    assert twins.value.thing == resident.iri and twins.value.people == (resident.iri, twin.iri)
    assert "wears a yellow shirt, as Twin does" in str(twins.value)


def test_each_person_is_moved_by_the_seed_and_a_home_of_one_as_before() -> None:
    resident, caregiver, third = WORLD + "Person", WORLD + "Caregiver", WORLD + "Visitor"
    for seed in (0, 3):
        alone = Perturbation.from_seed(seed, people=[resident])
        assert alone.people == {resident: alone.person}  # the draw a home of one person always had
        two = Perturbation.from_seed(seed, people=[resident, caregiver])
        three = Perturbation.from_seed(seed, people=[resident, caregiver, third])
        assert two.base == alone.base and {k: three.people[k] for k in two.people} == two.people
        assert two.people[resident] != two.people[caregiver]
        limit = Spread().person
        assert all(abs(d) <= limit for offset in three.people.values() for d in offset)


# -- runs ----------------------------------------------------------------------------------------------


def test_a_task_for_a_person_in_a_home_of_nobody_is_refused_before_anything_moves(tmp_path: Path) -> None:
    kb = _store(tmp_path)
    with open_world(0, semantic_map=SemanticMap.read(kb)) as world:
        assert world.people == {} and "Person" not in world.bodies
        with pytest.raises(NoPersonError, match="the simulation's default person"):
            world.person  # noqa: B018 - the property refuses: nobody to default to
        started, base = world.time, world.base_pose()
        with pytest.raises(UnresolvedDesignatorError) as refused:
            run_task(kb, "FetchMyPen", SimEnvironment(world, kb), composer=Composer(kb))
        assert world.time == started and world.base_pose() == base
    assert refused.value.concept == HOME + "Person"
    assert "nothing in the world is a Person" in str(refused.value)


def test_people_the_tracker_cannot_tell_apart_are_refused_before_anything_moves(tmp_path: Path) -> None:
    kb = _store(tmp_path, RESIDENT, _caregiver("yellow", "0.95 0.85 0.10 1"))
    with open_world(0, semantic_map=SemanticMap.read(kb)) as world:
        started, base = world.time, world.base_pose()
        with pytest.raises(LookAlikePeopleError) as refused:
            run_task(kb, "FetchTheCaregiversPen", SimEnvironment(world, kb), composer=Composer(kb))
        assert world.time == started and world.base_pose() == base
    assert refused.value.thing == WORLD + "Caregiver" and refused.value.colour == "yellow"
    assert "wears a yellow shirt, as Person does" in str(refused.value)


def test_the_camera_check_looks_for_the_person_the_task_means(tmp_path: Path) -> None:
    """The caregiver by the living room's west wall, past the edge of CeilingCamera01's image: the resident in
    its view is no help."""
    kb = _store(tmp_path, RESIDENT, _caregiver(x=0.3, y=2.0))
    with open_world(0, semantic_map=SemanticMap.read(kb)) as world:
        started = world.time
        with pytest.raises(sight.OutOfViewError) as refused:
            run_task(kb, "FetchTheCaregiversPen", SimEnvironment(world, kb), composer=Composer(kb))
        assert world.time == started
    assert refused.value.thing == WORLD + "Caregiver"
    assert "TrackPerson_CeilingCamera01 would look for the Caregiver at (0.30, 2.00" in str(refused.value)


@pytest.fixture(scope="module")
def caregivers_run(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[HomeWorld, RunResult]]:
    kb = _store(tmp_path_factory.mktemp("two"), RESIDENT, _caregiver())
    with open_world(0, semantic_map=SemanticMap.read(kb)) as world:
        resident = world.pose("Person").position
        result = run_task(kb, "FetchTheCaregiversPen", SimEnvironment(world, kb), composer=Composer(kb))
        assert world.pose("Person").position == resident  # nobody but the base moved near them
        yield world, result
    kb.close()


def test_the_pen_is_brought_to_the_person_the_task_names_of_two(caregivers_run: tuple[HomeWorld, RunResult]) -> None:
    world, result = caregivers_run
    assert result.succeeded and all(check.holds for check in result.goals) and result.report is not None
    assert world.holders == {"Pen": "Caregiver"}
    x, y, _ = world.pose("Caregiver").position
    assert world.base_pose().distance_to(x, y) <= 1.0
    (track,) = [step for step in result.report.steps if "TrackPerson" in step.component]
    seen = result.report.outputs[track.index]["personPosition"]  # the blue shirt, not the yellow one
    assert abs(seen["x"] - x) < 0.3 and abs(seen["y"] - y) < 0.3


def test_each_person_is_built_in_their_shirt_colour(caregivers_run: tuple[HomeWorld, RunResult]) -> None:
    world, _ = caregivers_run
    for name, colour in (("Person", (0.95, 0.85, 0.10)), ("Caregiver", (0.10, 0.20, 0.85))):
        shapes = p.getVisualShapeData(world.body(name), physicsClientId=world.client)
        assert any(tuple(round(c, 2) for c in shape[7][:3]) == colour for shape in shapes), name
