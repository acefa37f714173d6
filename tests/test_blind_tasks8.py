"""The eighth round of tasks written from the docs alone (docs/examples/lab8_*, docs/tasks.md "An eighth
round"): an apple and a fruit bowl described only in Turtle, two things to two places of the lab's own,
"how humid is the bedroom?" answered by a hygrometer in another process, "which cups are in the kitchen?"
from the world knowledge, and a newcomer's mistakes with each. Nothing is simulated here: the tasks are
composed, the mistakes refused at the load or in the no-plan answer, the hygrometer's answers read by
the remote component's own check (bench/example_tasks.py runs the trials, docs/tasks.md gives their
simulated seconds)."""

from __future__ import annotations

import importlib.util
from collections.abc import Iterator, Mapping
from concurrent.futures import Future
from pathlib import Path
from types import ModuleType
from typing import Any

import pyoxigraph as ox
import pytest

from cbrs.actions.answers import StoreClasses, UnitInTextError, check_quantities
from cbrs.actions.components import Status
from cbrs.actions.composer import Composer
from cbrs.actions.remote import RemoteComponent
from cbrs.kb import KnowledgeBase
from cbrs.kb.errors import UndeclaredSuperclassError
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.semantic_map import MapError
from cbrs.sim.components import implementations
from tests.helpers_examples import EXAMPLES

HOME, SVC, WORLD, LAB8 = PREFIXES["home"], PREFIXES["svc"], PREFIXES["world"], "https://example.org/lab8#"
HYGROMETER = LAB8 + "MeasureHumidity_Hygrometer01"


def _sizes(kb: KnowledgeBase) -> dict[str, int]:
    rows = kb.query("SELECT ?g (COUNT(*) AS ?n) WHERE { GRAPH ?g { ?s ?p ?o } } GROUP BY ?g")
    assert isinstance(rows, ox.QuerySolutions)
    return {str(row["g"].value): int(row["n"].value) for row in rows}


@pytest.fixture(scope="module")
def lab_kb() -> Iterator[KnowledgeBase]:
    """The round's files in one store: the apple and the bowl, the two places, the tasks, the hygrometer."""
    kb = KnowledgeBase.open(":memory:")
    for name in ("lab8_fruit_bowl.ttl", "lab8_two_places.ttl"):
        kb.load([EXAMPLES / name], graph="ontology")
        kb.load([EXAMPLES / name], graph="map")
    for name in ("lab8_put_apple_in_bowl.ttl", "lab8_pen_and_cup_away.ttl", "lab8_mistake_pen_and_cup_is_on.ttl"):
        kb.load([EXAMPLES / name], graph="requirements")
    kb.load([EXAMPLES / "lab8_bedroom_humidity.ttl"], graph="requirements")
    kb.registry.register((EXAMPLES / "lab8_bedroom_hygrometer.ttl").read_text(encoding="utf-8"))
    yield kb
    kb.close()


# -- the apple and the fruit bowl ------------------------------------------------------------------


def test_a_superclass_the_home_ontology_lacks_is_refused_at_the_load(tmp_path: Path) -> None:
    """lab8:Apple rdfs:subClassOf home:Fruit was loaded, and the task then had no plan, saying only that no
    component provides its goal: the apple hung from nothing the components know."""
    kb = KnowledgeBase.open(":memory:")
    before = _sizes(kb)
    with pytest.raises(UndeclaredSuperclassError, match=r"home:Fruit is declared nowhere") as refused:
        kb.load([EXAMPLES / "lab8_mistake_apple.ttl"], graph="ontology")
    assert refused.value.subclass == LAB8 + "Apple" and refused.value.superclass == HOME + "Fruit"
    apple = (EXAMPLES / "lab8_mistake_apple.ttl").read_text(encoding="utf-8").splitlines()
    line = next(n for n, text in enumerate(apple, start=1) if text.startswith("lab8:Apple "))
    assert refused.value.line == line and f"lab8_mistake_apple.ttl:{line}: " in str(refused.value)
    slip = tmp_path / "bowll.ttl"
    slip.write_text(
        (EXAMPLES / "lab8_fruit_bowl.ttl").read_text(encoding="utf-8").replace("home:Bowl ,", "home:Bowll ,"),
        encoding="utf-8",
    )
    with pytest.raises(UndeclaredSuperclassError, match=r"did you mean home:Bowl\?"):
        kb.load([slip], graph="map")
    assert _sizes(kb) == before


def test_the_same_superclass_is_refused_in_a_sparql_update() -> None:
    """/update and cbrs update run kb.update: the class the load refuses was written by an INSERT DATA."""
    kb = KnowledgeBase.open(":memory:")
    before = _sizes(kb)
    graph = "INSERT DATA { GRAPH <https://w3id.org/cbrs/graph/ontology> { <https://example.org/lab8#Apple> "
    fruit, physical = graph + "rdfs:subClassOf home:Fruit } }", graph + "rdfs:subClassOf home:PhysicalObject } }"
    with pytest.raises(UndeclaredSuperclassError, match=r"^the update: .*home:Fruit is declared nowhere.*written$"):
        kb.update(fruit)
    assert _sizes(kb) == before
    kb.update(physical)
    assert _sizes(kb) != before


def test_sizes_written_in_centimetres_are_refused_naming_the_metres(tmp_path: Path) -> None:
    """home:sizeX 7 for a 7 cm apple: refused before as the cup being inside it "by 307.8 cm"."""
    kb = KnowledgeBase.open(":memory:")
    before = _sizes(kb)
    fixed = tmp_path / "apple_in_cm.ttl"
    text = (EXAMPLES / "lab8_mistake_apple.ttl").read_text(encoding="utf-8")
    fixed.write_text(text.replace("home:Fruit", "home:PhysicalObject"), encoding="utf-8")
    with pytest.raises(MapError, match=r"is 7 x 7 m .* wider than the top of its support KitchenTable") as refused:
        kb.load([fixed], graph="map")
    assert "sizes are in metres: 7 cm is 0.07" in str(refused.value)
    assert "overlap" not in str(refused.value)
    assert _sizes(kb) == before


def test_the_arm_takes_the_goals_subject_not_the_deeper_destination(lab_kb: KnowledgeBase) -> None:
    """The apple straight under home:PhysicalObject, the bowl four classes deeper: the bowl was the more
    about the arm's steps, and the plan had the arm pick up the bowl (the apple given to no step)."""
    result = Composer(lab_kb).compose("PutAppleInBowl")
    assert result.plan is not None and result.unused_inputs == ()
    taken = {
        step.component.rsplit("#", 1)[-1]: binding.source.name
        for step in result.plan.steps
        for binding in step.bindings
        if binding.source.step is None
    }
    assert taken["QueryManipulationProperty_HomeServer01"] == "apple"
    assert taken["InferObjectProperty_HomeServer01"] == "apple"
    assert taken["CarryObject_CytonDualArm01"] == "bowl"


# -- two things to two places ----------------------------------------------------------------------


def test_two_things_to_two_places_plan_one_carry_each(lab_kb: KnowledgeBase) -> None:
    plan = Composer(lab_kb).compose("PenAndCupAway").plan
    assert plan is not None
    carries = [
        (binding.source.name, step.component)
        for step in plan.steps
        for binding in step.bindings
        if step.component.endswith("CarryObject_CytonDualArm01") and binding.source.step is None
    ]
    assert sorted(name for name, _ in carries) == ["cupboard", "shelf"]


def test_a_property_the_ontology_lacks_is_named_in_the_no_plan_answer(lab_kb: KnowledgeBase) -> None:
    """home:isOn: the answer listed what components provide, but never said home:isOn is nothing."""
    result = Composer(lab_kb).compose("PenAndCupAwayIsOn")
    assert result.plan is None and result.unsatisfied
    for unmet in result.unsatisfied:
        assert "home:isOn is no property of the ontology" in unmet.text()
        assert "rdfs:subPropertyOf home:isLocatedOn" in unmet.text()
        assert "no class" not in unmet.text() and "did you mean home:isNear" not in unmet.text()


# -- the bedroom's humidity from a component in another process ------------------------------------


class Answering:
    """A transport whose every call is answered at once with ``answer`` (the bridge's part)."""

    def __init__(self, answer: Any) -> None:
        self.answer = answer

    def call(self, service: str, args: Mapping[str, Any], timeout: float) -> Future[dict[str, Any]]:
        future: Future[dict[str, Any]] = Future()
        future.set_result(self.answer)
        return future


def _program() -> ModuleType:
    spec = importlib.util.spec_from_file_location("lab8_bedroom_hygrometer", EXAMPLES / "lab8_bedroom_hygrometer.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _read(kb: KnowledgeBase, answer: Any) -> RemoteComponent:
    component = implementations(kb, transport=Answering(answer))(HYGROMETER)
    assert isinstance(component, RemoteComponent)
    component.begin({})
    for _ in range(100):
        if component.update() is not Status.RUNNING:
            break
    return component


def test_the_bedroom_humidity_is_planned_onto_the_hygrometer_alone(lab_kb: KnowledgeBase) -> None:
    plan = Composer(lab_kb).compose("BedroomHumidity").plan
    assert plan is not None
    assert [step.component for step in plan.steps] == [HYGROMETER]
    assert plan.steps[0].alternatives == ()  # the living room's sensor board is passed over by the area rule


def test_the_hygrometers_answer_is_taken_and_a_number_with_its_unit_as_text_refused(lab_kb: KnowledgeBase) -> None:
    """--misbehave unit answered "47.5 %": the run believed it and passed the text on."""
    program = _program()
    good = _read(lab_kb, program.reading("no"))
    assert good.outputs["humidity"]["percent"] == 47.5, good.reason
    wrong = _read(lab_kb, program.reading("unit"))
    assert wrong.outputs == {} or "humidity" not in wrong.outputs
    assert wrong.reason.startswith("/lab8_hygrometer_01/read answered a wrong humidity: malformed home:Humidity")
    assert "'percent' is '47.5 %', a number with its unit ('%') written as text" in wrong.reason
    assert '("percent": 47.5)' in wrong.reason


def test_only_measurements_are_read_for_numbers_as_text(lab_kb: KnowledgeBase) -> None:
    classes = StoreClasses(lab_kb)
    for text in ("21.5 °C", "21,5", "0.5m", "1e3 Pa"):
        with pytest.raises(UnitInTextError):
            check_quantities(HOME + "RoomTemperature", {"@type": "home:RoomTemperature", "value": text}, classes)
    for text in ("2026-11-28T10:00:00Z", "12:30", "steady", "5 x 3"):  # a date, a time, words
        check_quantities(HOME + "Humidity", {"@type": "home:Humidity", "note": text}, classes)
    check_quantities(HOME + "DoorStatus", {"@type": "home:Opened", "note": "47 %"}, classes)  # no measurement


# -- which cups are in the kitchen? ----------------------------------------------------------------


def test_which_things_are_in_a_room_from_the_world_knowledge(lab_kb: KnowledgeBase) -> None:
    """The map says what a thing stands on, not its room: ?cup home:isLocated world:Kitchen found none."""

    def things(concept: str, room: str) -> set[str]:
        rows = lab_kb.select("things_in_room", {"class": ox.NamedNode(concept), "room": ox.NamedNode(room)})
        return {row["thing"].value for row in rows}

    assert things(HOME + "Cup", WORLD + "Kitchen") == {WORLD + "Cup"}
    assert things(HOME + "Cup", HOME + "Kitchen") == {WORLD + "Cup"}  # the room's class names it too
    assert things(HOME + "Cup", WORLD + "Bedroom") == set()
    assert {WORLD + "Cup", WORLD + "Pen", LAB8 + "Apple1"} <= things(HOME + "PhysicalObject", WORLD + "Kitchen")


def test_a_question_about_the_world_written_as_a_task_is_sent_to_the_store() -> None:
    """The cups as the output of a task: no plan, and the answer said only to register a component."""
    kb = KnowledgeBase.open(":memory:")
    kb.load([EXAMPLES / "lab8_mistake_which_cups.ttl"], graph="requirements")
    result = Composer(kb).compose("WhichCupsInTheKitchen")
    assert result.plan is None and len(result.unsatisfied) == 1
    text = result.unsatisfied[0].text()
    assert "no component provides output cups (home:Cup) of the requirement" in text
    assert "cbrs query --name things_in_room --bind class=home:Cup" in text
    kb.load([EXAMPLES / "lab8_bedroom_humidity.ttl"], graph="requirements")  # no hygrometer: no plan
    humidity = Composer(kb).compose("BedroomHumidity")  # an output that is no thing: no word of the store
    assert humidity.plan is None and humidity.unsatisfied
    assert all("things_in_room" not in u.text() for u in humidity.unsatisfied)
