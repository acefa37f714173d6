"""A thing's quantities stated in the map decide a task's preconditions on its measured states
(kb.stated_quantities; docs/execution.md, "A thing's quantities stated in the map"): ``home:massKg`` is the
level of ``home:ObjectWeight`` in kilograms (home.ttl), so the eleventh round's two flasks (docs/examples/
lab11_two_flasks.ttl, lab11:Full an object weight of 0.4 kg and more) are told apart by the weight each
states, and a precondition on the one a task names is decided by it where no sensor reads it. A lab's own
property works alike (a volume in litres, compared with a bound in millilitres); a sensor's reading of a
place still comes first. No simulator: the store and the sensing module alone."""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from typing import Any, cast

import pytest

from cbrs.actions.belief import Observation
from cbrs.actions.components import Component, Container, Registry, Status
from cbrs.actions.composer import Composer
from cbrs.actions.precondition_sensing import PreconditionSensing
from cbrs.actions.task_preconditions import TaskPreconditionError, check_preconditions
from cbrs.kb import KnowledgeBase, Requirement, Statement
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.semantic_map import AmbiguousDesignatorError, designate, designate_each
from cbrs.kb.stated_quantities import StatedQuantities, guaranteed_statuses
from cbrs.tasks import preconditions_line
from tests.helpers_examples import EXAMPLES

HOME, SVC = PREFIXES["home"], PREFIXES["svc"]
LAB11, LAB = "https://example.org/lab11#", "https://example.org/lab#"
FLASK, FULL = LAB11 + "Flask", LAB11 + "Full"

# A lab's own quantity of things: the volume of liquid in a flask, stated in litres, and "brimming" at 400 mL
# and more (another unit of the same kind: the store converts).
VOLUME = f"""
@prefix home: <{HOME}> . @prefix lab: <{LAB}> . @prefix lab11: <{LAB11}> .
@prefix owl: <http://www.w3.org/2002/07/owl#> . @prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> .
@prefix qudt: <http://qudt.org/schema/qudt/> . @prefix quantitykind: <http://qudt.org/vocab/quantitykind/> .
lab:LiquidVolume a owl:Class ; rdfs:subClassOf home:Measurement .
lab:volumeL a owl:AnnotationProperty ; home:levelOf lab:LiquidVolume ; home:levelUnit lab:Litre .
lab:Litre home:readingKey "litres" ; qudt:hasQuantityKind quantitykind:Volume ; qudt:conversionMultiplier 0.001 ;
    qudt:symbol "L" .
lab:Millilitre home:readingKey "millilitres" ; qudt:hasQuantityKind quantitykind:Volume ;
    qudt:conversionMultiplier 0.000001 ; qudt:symbol "mL" .
lab:Brimming a owl:Class ; rdfs:subClassOf home:Status ; home:holdsWhen lab:BrimmingCondition .
lab:BrimmingCondition a home:MeasuredCondition , owl:NamedIndividual ;
    home:measuredQuantity lab:LiquidVolume ; home:atLeast 400 ; qudt:hasUnit lab:Millilitre .
lab:Empty a owl:Class ; rdfs:subClassOf home:Status ; home:holdsWhen lab:EmptyCondition .
lab:EmptyCondition a home:MeasuredCondition , owl:NamedIndividual ;
    home:measuredQuantity home:ObjectWeight ; home:below 0.1 ; qudt:hasUnit <http://qudt.org/vocab/unit/KiloGM> .
lab:YellowFlask a owl:Class ; rdfs:subClassOf lab11:Flask .
lab11:Flask1 lab:volumeL 0.45 .
lab11:Flask2 lab:volumeL 0.05 .
"""


@pytest.fixture(scope="module")
def kb(tmp_path_factory: pytest.TempPathFactory) -> KnowledgeBase:
    store = KnowledgeBase.open(":memory:")
    for graph in ("ontology", "map"):
        store.load([EXAMPLES / "lab11_two_flasks.ttl"], graph=graph)
    volume = tmp_path_factory.mktemp("h10") / "volume.ttl"
    volume.write_text(VOLUME, encoding="utf-8")
    store.load([volume], graph="map")
    store.load([EXAMPLES / "lab9_dark.ttl"], graph="ontology")
    store.load([EXAMPLES / "lab11_fetch_the_full_flask.ttl"], graph="requirements")
    return store


@pytest.fixture(scope="module")
def index(kb: KnowledgeBase) -> Any:
    return Composer(kb).index


_YELLOW_IN = (
    "INSERT DATA { GRAPH graph:map { <https://example.org/lab11#Flask2> a <https://example.org/lab#YellowFlask> } }"
)
_YELLOW_OUT = (
    "DELETE DATA { GRAPH graph:map { <https://example.org/lab11#Flask2> a <https://example.org/lab#YellowFlask> } }"
)


@contextmanager
def _yellow(kb: KnowledgeBase) -> Iterator[None]:
    """The yellow flask given a class of its own for the block (a task names it by that class)."""
    kb.update(_YELLOW_IN)
    try:
        yield
    finally:
        kb.update(_YELLOW_OUT)


def _check(kb: KnowledgeBase, index: Any, *statements: Statement, sensing: PreconditionSensing | None = None) -> Any:
    sense = sensing or PreconditionSensing(kb, cast(Container, None), (), index, 1.0, advertisements=())
    requirement = Requirement(LAB11 + "FetchTheFullFlask", (), preconditions=statements)
    return check_preconditions(object(), requirement, Observation({}, frozenset(), {}), index.is_a, sense)


def test_the_weight_each_thing_states_tells_them_apart(kb: KnowledgeBase, index: Any) -> None:
    """FetchTheFullFlask was refused as ambiguous: two flasks, the precondition that it is full not read. The
    magenta flask states 0.55 kg and the yellow 0.15 kg, so of the two only the magenta one can be meant."""
    with pytest.raises(AmbiguousDesignatorError):
        designate(kb, FLASK)
    assert designate(kb, FLASK, guarantees=(FULL,)) == LAB11 + "Flask1"
    requirement = Composer(kb).task("FetchTheFullFlask").requirement
    statuses = guaranteed_statuses(requirement, FLASK, index.is_a)
    assert statuses == (FULL,)  # the task's own precondition, not the robot's marker
    things = designate_each(kb, [(FLASK, requirement.requested_by)], guarantees=[statuses])
    assert things == [LAB11 + "Flask1"]
    assert designate(kb, FLASK, guarantees=(LAB + "Brimming",)) == LAB11 + "Flask1"  # a lab's quantity alike
    with pytest.raises(AmbiguousDesignatorError) as neither:  # false of both: none left out, the run's check says
        designate(kb, FLASK, guarantees=(LAB + "Empty",))
    assert neither.value.candidates == [LAB11 + "Flask1", LAB11 + "Flask2"]


def test_a_precondition_on_a_thing_is_decided_by_the_weight_the_map_states(kb: KnowledgeBase, index: Any) -> None:
    (check,) = _check(kb, index, Statement(FLASK, HOME + "hasStatus", FULL))
    assert check.believed is True
    assert check.sensed.replace(LAB11, "lab11:") == "0.55 kg, the map's home:massKg of lab11:Flask1"
    yellow = Statement(LAB + "YellowFlask", HOME + "hasStatus", FULL)
    with pytest.raises(TaskPreconditionError) as refused, _yellow(kb):
        _check(kb, index, yellow)
    said = str(refused.value).replace(LAB11, "lab11:")
    assert "does not hold: the map states 0.15 kg of lab11:Flask2 (home:massKg)" in said
    assert "holds at least 0.4 kg (its home:holdsWhen)" in said
    assert "correct the map (cbrs update)" in said and "once the reading says" not in said
    assert check.stated and check.to_dict()["stated"] is True
    line = preconditions_line([check.to_dict()])
    assert line.replace(LAB11, "lab11:") == (
        "preconditions: 1 holding by the map (0.55 kg, the map's home:massKg of lab11:Flask1)"
    )


def test_the_thing_the_run_designated_is_the_one_asked_about(kb: KnowledgeBase, index: Any) -> None:
    """Where the run's input names the yellow flask (as a run that designated it gives it), the precondition is
    decided of that flask, not of the one the precondition alone would tell apart."""
    given = {"flask": {"@id": LAB11 + "Flask2", "@type": FLASK}, "person": {"@id": "x", "@type": HOME + "Person"}}
    sensing = PreconditionSensing(kb, cast(Container, None), (), index, 1.0, advertisements=(), given=given)
    with pytest.raises(TaskPreconditionError) as refused:
        _check(kb, index, Statement(FLASK, HOME + "hasStatus", FULL), sensing=sensing)
    assert "the map states 0.15 kg of " in str(refused.value)


def test_a_lab_s_own_quantity_in_another_unit_is_converted(kb: KnowledgeBase, index: Any) -> None:
    quantities = StatedQuantities.read(kb)
    level = quantities.level(LAB11 + "Flask1", LAB + "LiquidVolume")
    assert level is not None and (level.prop, level.value, level.unit) == (LAB + "volumeL", 0.45, LAB + "Litre")
    (check,) = _check(kb, index, Statement(FLASK, HOME + "hasStatus", LAB + "Brimming"))
    assert check.believed is True
    assert check.sensed.replace(LAB11, "lab11:").replace(LAB, "lab:") == (
        "0.45 L (450 mL), the map's lab:volumeL of lab11:Flask1"
    )
    with pytest.raises(TaskPreconditionError) as refused, _yellow(kb):
        _check(kb, index, Statement(LAB + "YellowFlask", HOME + "hasStatus", LAB + "Brimming"))
    assert "the map states 0.05 L (50 mL) of" in str(refused.value)


def test_a_thing_that_states_no_level_of_the_quantity_is_taken_as_given(kb: KnowledgeBase, index: Any) -> None:
    """The pen states a weight and no volume: no sensor reads a thing, and the map says nothing of it."""
    (check,) = _check(kb, index, Statement(HOME + "Pen", HOME + "hasStatus", LAB + "Brimming"))
    assert check.believed is None
    assert check.why.replace(LAB, "lab:").endswith(
        "home:Pen is no place, and a sensor reads a measured state of the place its effective area covers, not of"
        " a thing; nor does the map state a level of lab:LiquidVolume of it (a property with home:levelOf and"
        " home:levelUnit, as home:massKg is of home:ObjectWeight)"
    )


class _Sensor(Component):
    """A stand-in light sensor reading ``lux``."""

    def __init__(self, iri: str, lux: float) -> None:
        super().__init__(iri)
        self.lux = lux

    def begin(self, inputs: Mapping[str, Any]) -> None:
        pass

    def update(self) -> Status:
        self.outputs = {"illuminance": {"@type": HOME + "Illuminance", "lux": self.lux}}
        return Status.SUCCEEDED


def test_a_sensor_s_reading_comes_before_the_level_a_place_states(kb: KnowledgeBase, index: Any) -> None:
    """The living room states 12 lx of its own: without a sensor that decides it dark; the board reading
    300 lx (a reading is of now) decides it lit. A class's level (home:Room's 300 lx) is no place's own."""
    dark = Statement(HOME + "LivingRoom", HOME + "hasStatus", "https://example.org/lab9#Dark")
    kb.update("INSERT DATA { GRAPH graph:map { world:LivingRoom home:lightLevel 12.0 } }")
    try:
        (check,) = _check(kb, index, dark)
        assert (check.believed, check.sensed) == (True, "12 lx, the map's home:lightLevel of world:LivingRoom")
        board = SVC + "MeasureIlluminance_SensorBoard01"
        registry = Registry()
        registry.add(board, lambda iri: _Sensor(iri, 300.0))
        sensing = PreconditionSensing(kb, Container(registry), registry, index, 5.0)
        with pytest.raises(TaskPreconditionError) as refused:
            _check(kb, index, dark, sensing=sensing)
        assert "SensorBoard01 (svc:MeasureIlluminance_SensorBoard01) reads 300 lx" in str(refused.value)
    finally:
        kb.update("DELETE DATA { GRAPH graph:map { world:LivingRoom home:lightLevel 12.0 } }")
    bedroom = Statement(HOME + "Bedroom", HOME + "hasStatus", "https://example.org/lab9#Dark")
    (check,) = _check(kb, index, bedroom)
    assert check.believed is None and check.why == "no sensor of home:Illuminance covers home:Bedroom"


def test_an_environment_that_designates_without_the_guarantees_is_told_so(kb: KnowledgeBase, index: Any) -> None:
    """A lab's own environment that designates the task's inputs without the statuses the task guarantees (an
    older one) meets the two flasks as ambiguous; the refusal says the stated weights tell them apart."""
    from cbrs.actions.runner import _undecided

    requirement = Composer(kb).task("FetchTheFullFlask").requirement
    with pytest.raises(AmbiguousDesignatorError) as ambiguous:
        designate_each(kb, [(FLASK, requirement.requested_by)])
    said = str(_undecided(ambiguous.value, requirement, index, kb)).replace(LAB11, "lab11:")
    assert "(lab11:Flask, home:hasStatus, lab11:Full) tells them apart by the quantity each states" in said
    assert "(only lab11:Flask1 meets it), but the environment designated the task's inputs without" in said
