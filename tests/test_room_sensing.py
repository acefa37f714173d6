"""The simulated home's room sensors read light, temperature and humidity from what the store states
(sim.room_quantities), a precondition in one unit is decided by a reading in another, and a sensor that
states no effective area measures where its device is (actions.sensor_places; docs/execution.md, "Where a
sensor measures"). The bundled store with the lab's warm and humid statuses and its bedroom thermometer,
the simulated components invoked through a real container, no simulator built."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from types import SimpleNamespace
from typing import Any, cast

import pytest

from cbrs.actions.components import Container
from cbrs.actions.composer import Composer
from cbrs.actions.precondition_sensing import PreconditionSensing
from cbrs.actions.sensor_places import MapPlaces
from cbrs.kb import KnowledgeBase, Statement
from cbrs.kb.namespaces import PREFIXES
from cbrs.sim.components import implementations
from cbrs.sim.context import SimContext, SkillFailed
from cbrs.sim.room_quantities import measure
from tests.helpers_examples import EXAMPLES

HOME, SVC, WORLD = PREFIXES["home"], PREFIXES["svc"], PREFIXES["world"]
LAB = "https://example.org/lab#"
THERMOMETER = LAB + "MeasureTemperature_Thermometer02"
WARM_BEDROOM = Statement(HOME + "Bedroom", HOME + "hasStatus", LAB + "Warm")
PREFIXES_TEXT = (
    "PREFIX home: <https://w3id.org/cbrs/home#> PREFIX world: <https://w3id.org/cbrs/world#>"
    " PREFIX lab: <https://example.org/lab#> PREFIX unit: <http://qudt.org/vocab/unit/> "
)


@pytest.fixture(scope="module")
def kb() -> KnowledgeBase:
    store = KnowledgeBase.open(":memory:")
    store.load([EXAMPLES / "lab_warm_and_humid.ttl"], graph="ontology")
    store.load([EXAMPLES / "lab_bedroom_thermometer.ttl"], graph="services")
    store.load([EXAMPLES / "lab_bedroom_thermometer_map.ttl"], graph="map")
    return store


@pytest.fixture(scope="module")
def index(kb: KnowledgeBase) -> Any:
    return Composer(kb).index


@contextmanager
def stated(kb: KnowledgeBase, triples: str, graph: str = "graph:map") -> Iterator[None]:
    """``triples`` (Turtle, the prefixes above) in ``graph`` for the block, then taken out again."""
    kb.update(f"{PREFIXES_TEXT} INSERT DATA {{ GRAPH {graph} {{ {triples} }} }}")
    try:
        yield
    finally:
        kb.update(f"{PREFIXES_TEXT} DELETE DATA {{ GRAPH {graph} {{ {triples} }} }}")


def _sensing(kb: KnowledgeBase, index: Any) -> PreconditionSensing:
    """Sensing through the simulated components of the store, as a run's container makes them."""
    registry = implementations(kb)
    context = SimContext(world=cast(Any, None), kb=kb)
    return PreconditionSensing(kb, Container(registry, context), registry, index, 5.0)


def _read(kb: KnowledgeBase, component: str, device: str = "SensorBoard01") -> dict[str, Any]:
    return measure(cast(Any, SimpleNamespace(kb=kb, component=component)), {}, device)


def test_the_simulated_board_reads_temperature_and_humidity_the_store_states(kb: KnowledgeBase) -> None:
    temperature, humidity = SVC + "MeasureTemperature_SensorBoard01", SVC + "MeasureHumidity_SensorBoard01"
    assert _read(kb, temperature) == {"temperature": {"@type": HOME + "Temperature", "celsius": 21.0}}  # home:Room's
    assert _read(kb, humidity) == {"humidity": {"@type": HOME + "Humidity", "percent": 45.0}}
    with stated(kb, "world:LivingRoom home:airTemperature 16.5 ; home:relativeHumidity 71.0 ."):
        assert _read(kb, temperature)["temperature"]["celsius"] == 16.5
        assert _read(kb, humidity)["humidity"]["percent"] == 71.0
    # a lab's own property states a level in its own unit, and the reading gives it in that unit
    own = "lab:fahrenheit home:levelOf home:Temperature ; home:levelUnit unit:DEG_F ."
    with stated(kb, own, "graph:ontology"), stated(kb, "world:LivingRoom lab:fahrenheit 50.0 ."):
        assert _read(kb, temperature) == {"temperature": {"@type": HOME + "Temperature", "fahrenheit": 50.0}}


def test_a_condition_in_fahrenheit_is_decided_by_a_reading_in_celsius(kb: KnowledgeBase, index: Any) -> None:
    warm = Statement(HOME + "LivingRoom", HOME + "hasStatus", LAB + "Warm")
    found = _sensing(kb, index)(warm)
    assert found is not None and (found.holds, found.how, found.bound) == (
        True,
        "21 °C (69.8 °F) by SensorBoard01",
        "at least 64.4 °F",
    )
    with stated(kb, "world:LivingRoom home:airTemperature 17.5 ."):  # 63.5 °F
        found = _sensing(kb, index)(warm)
    assert found is not None and (found.holds, found.reading) == (False, "17.5 °C (63.5 °F)")
    humid = Statement(HOME + "LivingRoom", HOME + "hasStatus", LAB + "Humid")
    found = _sensing(kb, index)(humid)
    assert found is not None and (found.holds, found.how) == (False, "45 % by SensorBoard01")
    with stated(kb, "world:LivingRoom home:relativeHumidity 60.0 ."):  # at the bound, included
        found = _sensing(kb, index)(humid)
    assert found is not None and found.holds is True


def test_a_sensor_with_no_stated_area_measures_the_room_its_device_is_in(kb: KnowledgeBase, index: Any) -> None:
    sense = _sensing(kb, index)
    temperature = HOME + "Temperature"
    assert [ad.iri for ad, _ in sense.sensors(temperature, HOME + "Bedroom")] == [THERMOMETER]
    assert [ad.iri for ad, _ in sense.sensors(temperature, WORLD + "Bedroom")] == [THERMOMETER]
    assert [ad.iri for ad, _ in sense.sensors(temperature, HOME + "LivingRoom")] == [
        SVC + "MeasureTemperature_SensorBoard01"  # the board, by its area; not the bedroom's thermometer
    ]
    with stated(kb, "world:Bedroom home:airTemperature 15.0 ."):  # the bedroom cold, the living room not
        found = _sensing(kb, index)(WARM_BEDROOM)
        assert _read(kb, THERMOMETER, "Thermometer02")["temperature"]["celsius"] == 15.0
    assert found is not None and (found.holds, found.how) == (False, "15 °C (59 °F) by Thermometer02")


PLACED = "lab:Thermometer02 home:x 0.10 ; home:y 7.00 ; home:z 1.50 ."


@pytest.mark.parametrize(
    ("where", "rooms"),
    [
        pytest.param("lab:Thermometer02 home:isLocated world:KitchenTable .", ("Kitchen",), id="on-a-table"),
        pytest.param("lab:Thermometer02 home:isLocated world:Bedroom .", ("Bedroom",), id="located-in-a-room"),
        pytest.param(
            "lab:Thermometer02 home:minX 5.9 ; home:maxX 6.1 ; home:minY 1.0 ; home:maxY 1.2 .",
            ("Kitchen", "LivingRoom"),
            id="astride-a-wall",
        ),
        pytest.param("", (), id="not-placed"),
    ],
)
def test_where_the_map_puts_a_device_decides_the_rooms_it_measures(
    kb: KnowledgeBase, index: Any, where: str, rooms: tuple[str, ...]
) -> None:
    kb.update(f"{PREFIXES_TEXT} DELETE DATA {{ GRAPH graph:map {{ {PLACED} }} }}")
    try:
        with stated(kb, where) if where else _nothing():
            found = MapPlaces.read(kb).rooms_of(LAB + "Thermometer02")
            assert found == tuple(WORLD + room for room in rooms)
            if not rooms:
                with pytest.raises(SkillFailed, match=r"states no effective area, and the map puts its device"):
                    _read(kb, THERMOMETER, "Thermometer02")
                found_sensed = _sensing(kb, index)(WARM_BEDROOM)
                assert found_sensed is not None and found_sensed.holds is None
                assert found_sensed.how == "no sensor of home:Temperature covers home:Bedroom"
    finally:
        kb.update(f"{PREFIXES_TEXT} INSERT DATA {{ GRAPH graph:map {{ {PLACED} }} }}")


@contextmanager
def _nothing() -> Iterator[None]:
    yield
