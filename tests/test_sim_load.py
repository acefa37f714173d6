"""The simulation's load cell (sim/load.py, ``/sim/load``): what rests on a place and the weight it bears,
read from pybullet's contacts and the bodies' masses, never from the map. One world, of the bundled home
with the lab's scale plate on the kitchen table (docs/examples/lab_kitchen_scale.ttl)."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.semantic_map import SemanticMap
from cbrs.rosbridge import ServiceError
from cbrs.sim.errors import UnknownPlaceError
from cbrs.sim.load import measure_load
from cbrs.sim.world import HomeWorld, open_world
from cbrs.sim_sensors import LOAD_FIELDS, SimSensors, load_to_json
from tests.test_rosapi_typedefs import cbrs_types, mismatches

WORLD = PREFIXES["world"]
PLATE = "https://example.org/lab#KitchenScale01Plate"
EXAMPLES = Path(__file__).resolve().parents[1] / "docs" / "examples"


@pytest.fixture(scope="module")
def world() -> Iterator[HomeWorld]:
    kb = KnowledgeBase.open(":memory:")
    kb.load([EXAMPLES / "lab_kitchen_scale.ttl"], graph="ontology")
    kb.load([EXAMPLES / "lab_kitchen_scale.ttl"], graph="map")
    semantic_map = SemanticMap.read(kb)
    kb.close()
    with open_world(seed=0, semantic_map=semantic_map) as opened:
        yield opened


def _mass(world: HomeWorld, name: str) -> float:
    """The body's mass as pybullet has it (its base and its links)."""
    import pybullet as p

    body = world.body(name)
    links = range(-1, p.getNumJoints(body, physicsClientId=world.client))
    return sum(p.getDynamicsInfo(body, link, physicsClientId=world.client)[0] for link in links)


def test_the_table_bears_what_stands_on_it_and_the_empty_plate_nothing(world: HomeWorld) -> None:
    table = measure_load(world, "KitchenTable")
    assert [(r.iri, r.mass_kg) for r in table.resting] == [(WORLD + n, _mass(world, n)) for n in ("Cup", "Pen")]
    assert table.load_kg == pytest.approx(_mass(world, "Cup") + _mass(world, "Pen"), rel=0.01)
    assert measure_load(world, WORLD + "KitchenTable").resting == table.resting  # by IRI or local name
    plate = measure_load(world, PLATE)
    assert (plate.place, plate.load_kg, plate.resting) == (PLATE, 0.0, ())


def test_the_plate_weighs_the_cup_put_on_it(world: HomeWorld) -> None:
    box = world.map.things[PLATE].box
    world.place("Cup", (box.min_x + box.max_x) / 2, (box.min_y + box.max_y) / 2)
    world.step(0.5)
    plate = measure_load(world, "KitchenScale01Plate")
    assert [r.iri for r in plate.resting] == [WORLD + "Cup"]
    assert plate.load_kg == pytest.approx(_mass(world, "Cup"), rel=0.01)
    assert plate.time == world.time
    answered = load_to_json(plate)
    assert mismatches(cbrs_types().response("cbrs/MeasureLoad"), answered) == []
    assert answered["resting"] == [WORLD + "Cup"] and answered["masses_kg"] == [_mass(world, "Cup")]


def test_an_unknown_place_is_refused_naming_it(world: HomeWorld) -> None:
    with pytest.raises(UnknownPlaceError, match="'Attic'") as refused:
        measure_load(world, "Attic")
    assert refused.value.place == "Attic"


def test_the_service_reads_its_definition_s_fields_and_answers_from_the_world_watched(world: HomeWorld) -> None:
    assert tuple(cbrs_types().request("cbrs/MeasureLoad")[0]["fieldnames"]) == LOAD_FIELDS
    sensors = SimSensors()
    asks: list[tuple[dict[str, Any], str]] = [
        ({"place": "Attic"}, "'Attic'"),
        ({"place": ""}, "needs a place"),
        ({"place": "KitchenTable", "scale": 2}, "reads place, not scale"),
    ]
    with sensors.watching(world):
        assert sensors.load({"place": "KitchenTable"})["place"] == WORLD + "KitchenTable"
        for args, said in asks:
            with pytest.raises(ServiceError, match=said):
                sensors.load(args)
    with pytest.raises(ServiceError, match="no simulated home is running"):
        sensors.load({"place": "KitchenTable"})
