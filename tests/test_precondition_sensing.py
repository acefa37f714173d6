"""A task's precondition on a status the store defines by a measured quantity is decided by a sensor of the
store before the first step (actions.precondition_sensing, kb.measured_states; docs/execution.md, "A task's
preconditions"): the ninth round's ``(home:LivingRoom, home:hasStatus, lab9:Dark)``, lab9:Dark a
home:Illuminance below 50 lx. With stand-in sensor components in a real container (no simulator), the
simulated board's reading from the store, and one run of FetchMyBookIfDark refused in a lit home."""

from __future__ import annotations

from collections.abc import Mapping
from concurrent.futures import Future
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import pytest

from cbrs.actions.belief import Observation
from cbrs.actions.components import Component, Container, LifecycleState, Registry, Status
from cbrs.actions.composer import Composer
from cbrs.actions.faults import FixedFaults
from cbrs.actions.precondition_sensing import PreconditionSensing, Sensed, SensingConfig
from cbrs.actions.task_preconditions import TaskPreconditionError, check_preconditions
from cbrs.kb import KnowledgeBase, Requirement, Statement
from cbrs.kb.measured_states import MeasuredConditionError, UnitError, Units, read_conditions
from cbrs.kb.namespaces import PREFIXES, shorten
from cbrs.sim.room_quantities import measure
from cbrs.tasks import preconditions_line
from tests.helpers_examples import EXAMPLES

HOME, SVC, UNIT = PREFIXES["home"], PREFIXES["svc"], PREFIXES["unit"]
LAB9 = "https://example.org/lab9#"
BOARD = SVC + "MeasureIlluminance_SensorBoard01"
DARK = Statement(HOME + "LivingRoom", HOME + "hasStatus", LAB9 + "Dark")
D = shorten(LAB9 + "Dark")  # as the library writes it (cbrs run writes lab9:Dark, the prefix of the loaded file)
LIGHT_UPDATE = """PREFIX home: <https://w3id.org/cbrs/home#> PREFIX world: <https://w3id.org/cbrs/world#>
DELETE {{ GRAPH graph:map {{ world:LivingRoom home:lightLevel ?old }} }}
INSERT {{ GRAPH graph:map {{ world:LivingRoom home:lightLevel {lux} }} }}
WHERE {{ OPTIONAL {{ GRAPH graph:map {{ world:LivingRoom home:lightLevel ?old }} }} }}"""


class Sensor(Component):
    """A stand-in light sensor: answers ``answer`` (a value's JSON), fails with ``reason``, or never ends."""

    def __init__(self, iri: str, answer: Any = None, reason: str = "", hang: bool = False) -> None:
        super().__init__(iri)
        self.answer, self.failing, self.hang, self.calls = answer, reason, hang, 0

    def begin(self, inputs: Mapping[str, Any]) -> None:
        self.calls += 1

    def update(self) -> Status:
        if self.hang:
            return Status.RUNNING
        if self.failing:
            self.reason = self.failing
            return Status.FAILED
        self.outputs = {"illuminance": self.answer}
        return Status.SUCCEEDED


@pytest.fixture(scope="module")
def kb() -> KnowledgeBase:
    store = KnowledgeBase.open(":memory:")
    store.load([EXAMPLES / "lab9_dark.ttl"], graph="ontology")
    return store


@pytest.fixture(scope="module")
def index(kb: KnowledgeBase) -> Any:
    return Composer(kb).index


def _sensing(
    kb: KnowledgeBase, index: Any, sensor: Sensor, timeout: float = 5.0, failing: tuple[str, ...] = ()
) -> tuple[PreconditionSensing, Container]:
    registry = Registry()
    registry.add(BOARD, lambda iri: sensor)
    container = Container(registry, faults=FixedFaults.of(failing))
    return PreconditionSensing(kb, container, registry, index, timeout), container


def _check(kb: KnowledgeBase, index: Any, sensor: Sensor, *statements: Statement, timeout: float = 5.0) -> Any:
    sense, _ = _sensing(kb, index, sensor, timeout)
    requirement = Requirement(LAB9 + "FetchMyBookIfDark", (), preconditions=statements)
    return check_preconditions(object(), requirement, Observation({}, frozenset(), {}), index.is_a, sense)


def _lux(value: float) -> dict[str, Any]:
    return {"@type": HOME + "Illuminance", "lux": value}


def test_a_reading_within_the_bound_holds_and_the_line_says_what_was_read(kb: KnowledgeBase, index: Any) -> None:
    sensor = Sensor(BOARD, _lux(12.0))
    (check,) = _check(kb, index, sensor, DARK)
    assert (check.believed, check.sensed, check.why) == (True, "12 lx by SensorBoard01", "")
    assert sensor.calls == 1
    assert check.to_dict() == {
        "statement": f"(home:LivingRoom, home:hasStatus, {D})",
        "believed": True,
        "sensed": "12 lx by SensorBoard01",
    }
    assert preconditions_line([check.to_dict()]) == "preconditions: 1 sensed holding (12 lx by SensorBoard01)"


@pytest.mark.parametrize("lux", [300.0, 50.0], ids=["lit", "at-the-bound"])
def test_a_reading_outside_the_bound_refuses_naming_reading_sensor_and_bound(
    kb: KnowledgeBase, index: Any, lux: float
) -> None:
    with pytest.raises(TaskPreconditionError) as refused:
        _check(kb, index, Sensor(BOARD, _lux(lux)), DARK)
    error = refused.value
    assert error.statement == DARK and error.sensed is not None and error.http_status == 409
    assert (
        f"does not hold: SensorBoard01 (svc:MeasureIlluminance_SensorBoard01) reads {lux:g} lx in home:LivingRoom,"
        f" and {D} holds below 50 lx" in str(error)
    )


def test_a_reading_in_another_unit_of_the_quantity_is_converted(kb: KnowledgeBase, index: Any) -> None:
    (check,) = _check(kb, index, Sensor(BOARD, {"@type": HOME + "Illuminance", "footcandles": 1.0}), DARK)
    assert check.believed is True and check.sensed == "1 fc (10.7639 lx) by SensorBoard01"
    with pytest.raises(TaskPreconditionError, match=r"reads 5 fc \(53\.8196 lx\)"):
        _check(kb, index, Sensor(BOARD, {"@type": HOME + "Illuminance", "footcandles": 5.0}), DARK)


@pytest.mark.parametrize(
    ("answer", "named"),
    [
        pytest.param({"@type": HOME + "Illuminance", "candela": 3.0}, "'candela'", id="unknown-key"),
        pytest.param({"@type": HOME + "Illuminance", "celsius": 3.0}, "unit:DEG_C is a unit of", id="other-kind"),
    ],
)
def test_a_reading_in_a_unit_the_store_cannot_compare_is_an_error_naming_it(
    kb: KnowledgeBase, index: Any, answer: dict[str, Any], named: str
) -> None:
    with pytest.raises(UnitError, match="cannot be compared with unit:LUX") as refused:
        _check(kb, index, Sensor(BOARD, answer), DARK)
    assert named in str(refused.value)


def test_no_sensor_covering_the_place_leaves_it_taken_as_given_saying_why(kb: KnowledgeBase, index: Any) -> None:
    sensor = Sensor(BOARD, _lux(12.0))
    bedroom = Statement(HOME + "Bedroom", HOME + "hasStatus", LAB9 + "Dark")
    marker = Statement(HOME + "MobileRobot", HOME + "hasMarker", HOME + "ColourMarker")
    checks = _check(kb, index, sensor, bedroom, marker)
    assert [(c.believed, c.why) for c in checks] == [
        (None, "no sensor of home:Illuminance covers home:Bedroom"),
        (None, ""),  # no measured condition: not sensing's to decide
    ]
    assert sensor.calls == 0
    assert preconditions_line(c.to_dict() for c in checks) == (
        f"preconditions: 2 taken as given, no test decides them: (home:Bedroom, home:hasStatus, {D})"
        " (no sensor of home:Illuminance covers home:Bedroom); (home:MobileRobot, home:hasMarker, home:ColourMarker)"
    )


@pytest.mark.parametrize(
    ("sensor", "timeout", "failing", "why"),
    [
        pytest.param(
            Sensor(BOARD, reason="lamp sensor unplugged"), 5.0, (), "failed: lamp sensor unplugged", id="fails"
        ),
        pytest.param(Sensor(BOARD, hang=True), 0.05, (), "failed: no reading within 0.05 s", id="hangs"),
        pytest.param(
            Sensor(BOARD, _lux(12.0)),
            5.0,
            (BOARD,),
            f"failed: InjectedFault: injected failure of {BOARD}",
            id="injected-fault",
        ),
    ],
)
def test_a_sensor_that_gives_no_reading_leaves_it_taken_as_given_saying_why(
    kb: KnowledgeBase, index: Any, sensor: Sensor, timeout: float, failing: tuple[str, ...], why: str
) -> None:
    sense, container = _sensing(kb, index, sensor, timeout, failing)
    requirement = Requirement(LAB9 + "FetchMyBookIfDark", (), preconditions=(DARK,))
    (check,) = check_preconditions(object(), requirement, Observation({}, frozenset(), {}), index.is_a, sense)
    assert check.believed is None and check.why == f"SensorBoard01 (svc:MeasureIlluminance_SensorBoard01) {why}"
    assert container.state(BOARD) is LifecycleState.ERROR  # aborted as the executor aborts a step's component


def test_the_store_states_conditions_and_units_and_refuses_one_no_reading_can_decide(kb: KnowledgeBase) -> None:
    condition = read_conditions(kb)[LAB9 + "Dark"]
    assert (condition.quantity, condition.at_least, condition.below, condition.unit) == (
        HOME + "Illuminance",
        None,
        50.0,
        UNIT + "LUX",
    )
    units = Units.read(kb)
    assert units.convert(20.0, UNIT + "DEG_C", UNIT + "DEG_F") == pytest.approx(68.0)
    assert units.convert(47.5, UNIT + "PERCENT", UNIT + "FRACTION") == pytest.approx(0.475)
    broken = KnowledgeBase.open(":memory:")
    broken.update(
        "PREFIX home: <https://w3id.org/cbrs/home#> PREFIX ex: <http://example.org/x#> INSERT DATA { GRAPH"
        " graph:ontology { ex:Bright home:holdsWhen ex:c . ex:c home:measuredQuantity home:Illuminance ;"
        " home:atLeast 500.0 } }"
    )
    with pytest.raises(MeasuredConditionError, match=r"ex:Bright|x#Bright") as refused:
        read_conditions(broken)
    assert "has no qudt:hasUnit" in str(refused.value)
    broken.load([EXAMPLES / "lab9_dark.ttl"], graph="ontology")  # a broken condition stops only its own status
    sense = PreconditionSensing(broken, Container(Registry()), Registry(), Composer(broken).index, 1.0)
    bright = Statement(HOME + "LivingRoom", HOME + "hasStatus", "http://example.org/x#Bright")
    with pytest.raises(MeasuredConditionError, match="has no qudt:hasUnit"):
        sense(bright)
    assert sense(DARK) == Sensed(None, "no sensor of home:Illuminance covers home:LivingRoom", "below 50 lx")


def test_sensing_is_configured_by_its_settings(monkeypatch: pytest.MonkeyPatch) -> None:
    assert SensingConfig.from_settings() == SensingConfig(True, 10.0)
    monkeypatch.setenv("CBRS_PRECONDITION_SENSING", "off")
    monkeypatch.setenv("CBRS_PRECONDITION_SENSING_TIMEOUT", "2.5")
    assert SensingConfig.from_settings() == SensingConfig(False, 2.5)
    with pytest.raises(ValueError, match="above 0"):
        SensingConfig(True, 0.0)


def test_the_simulated_board_reads_the_light_level_the_map_states(kb: KnowledgeBase) -> None:
    context: Any = SimpleNamespace(kb=kb, component=BOARD)
    assert measure(context, {}, "SensorBoard01") == {"illuminance": _lux(300.0)}  # home:Room's, by day
    kb.update(LIGHT_UPDATE.format(lux="12.0"))
    try:
        assert measure(context, {}, "SensorBoard01") == {"illuminance": _lux(12.0)}
    finally:
        kb.update(
            "PREFIX home: <https://w3id.org/cbrs/home#> PREFIX world: <https://w3id.org/cbrs/world#>"
            " DELETE WHERE { GRAPH graph:map { world:LivingRoom home:lightLevel ?old } }"
        )


def test_fetch_my_book_if_dark_in_a_lit_home_is_refused_before_anything_moves(tmp_path: Path) -> None:
    """The one simulated run: the bundled board read through the run's container, the store as it was."""
    from cbrs.actions.runner import run_task
    from cbrs.kb.semantic_map import SemanticMap
    from cbrs.sim import HomeWorld
    from cbrs.sim.components import SimEnvironment

    store = KnowledgeBase.open(":memory:")
    store.load([EXAMPLES / "lab9_book_on_box.ttl", EXAMPLES / "lab9_dark.ttl"], graph="ontology")
    store.load([EXAMPLES / "lab9_book_on_box.ttl"], graph="map")
    store.load([EXAMPLES / "lab9_fetch_my_book_if_dark.ttl"], graph="requirements")
    before = sorted(str(row) for row in store.select("world_facts"))
    with HomeWorld.create(seed=0, semantic_map=SemanticMap.read(store)) as world:
        environment = SimEnvironment(world, store)
        with pytest.raises(TaskPreconditionError, match="reads 300 lx in home:LivingRoom") as refused:
            run_task(store, "FetchMyBookIfDark", environment)
        assert world.time < 1.0  # nothing drove or reached: only the cameras' first look
    assert refused.value.sensed is not None and refused.value.sensed.sensor == BOARD
    assert sorted(str(row) for row in store.select("world_facts")) == before


LAB_SENSOR = """@prefix cbrs: <https://w3id.org/cbrs/core#> . @prefix home: <https://w3id.org/cbrs/home#> .
@prefix labl: <https://example.org/lablight#> . @prefix owl: <http://www.w3.org/2002/07/owl#> .
labl:Light01 a owl:NamedIndividual , home:Device .
labl:MeasureLight_Light01 a cbrs:DynamicPerceptionComponent ; cbrs:device labl:Light01 ;
    cbrs:deviceName "Light01" ; cbrs:serviceName "MeasureLight" ; cbrs:serviceCategory "EnvironmentalSensing" ;
    cbrs:hasOWLSModel [ a cbrs:OWLSModel ;
        cbrs:hasOutput [ a cbrs:Parameter ; cbrs:parameterName "light" ; cbrs:parameterType home:Illuminance ] ] ;
    cbrs:hasSEAModel [ a cbrs:SEAModel ; cbrs:effectiveArea home:Bedroom ] ;
    cbrs:hasPort [ a cbrs:ServicePort ; cbrs:portName "read" ; cbrs:topic "/lab_light/read" ;
        cbrs:messageType "lab_msgs/Light" ] .
"""


class Bridge:
    """A stand-in transport: each call answered with ``answer``, or never."""

    def __init__(self, answer: dict[str, Any] | None) -> None:
        self.answer = answer
        self.calls: list[str] = []

    def call(self, service: str, args: Mapping[str, Any], timeout: float) -> Future[dict[str, Any]]:
        self.calls.append(service)
        future: Future[dict[str, Any]] = Future()
        if self.answer is not None:
            future.set_result(self.answer)
        return future


@pytest.mark.parametrize(
    ("answer", "believed", "said"),
    [
        pytest.param({"light": {"@type": "home:Illuminance", "lux": 8.0}}, True, "8 lx by Light01", id="answers"),
        pytest.param(
            None,
            None,
            "Light01 (MeasureLight_Light01) failed: /lab_light/read did not answer within 0.1 s",
            id="silent",
        ),
    ],
)
def test_a_sensor_in_another_process_is_asked_over_the_bridge_with_its_own_timeout(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, answer: dict[str, Any] | None, believed: bool | None, said: str
) -> None:
    from cbrs.sim.components import implementations

    monkeypatch.setenv("CBRS_REMOTE_CALL_TIMEOUT", "0.1")
    store = KnowledgeBase.open(":memory:")
    store.load([EXAMPLES / "lab9_dark.ttl"], graph="ontology")
    (tmp_path / "light.ttl").write_text(LAB_SENSOR, encoding="utf-8")
    store.load([tmp_path / "light.ttl"], graph="services")
    bridge = Bridge(answer)
    registry = implementations(store, transport=bridge)
    sense = PreconditionSensing(store, Container(registry), registry, Composer(store).index, 5.0)
    bedroom = Statement(HOME + "Bedroom", HOME + "hasStatus", LAB9 + "Dark")
    found = sense(bedroom)
    assert found is not None and bridge.calls == ["/lab_light/read"]
    assert (found.holds, found.how.replace("https://example.org/lablight#", "")) == (believed, said)
