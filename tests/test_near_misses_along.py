"""Near misses are looked for at every need along the chain a "no plan" answer follows down, not only at
the deepest (docs/composition.md, "Near misses"; docs/tasks.md, "A sixth round": the lab's fridge sensor,
whose output the requirement's own output nearly is, went unnamed because the answer followed the bundled
sensor board down to its missing home:Door). The lab's sensor is registered as the lab wrote it, giving a
home:DeviceStatus: its complementary word names home:Device, which is no sibling of home:Door, so it does
not set the two statuses apart (actions.near_misses.about_other_things)."""

from __future__ import annotations

from dataclasses import replace

import pytest

from cbrs.actions.composer import ComposeConfig, Composer
from cbrs.kb import KnowledgeBase
from tests.helpers_examples import EXAMPLES

LAB6 = "https://example.org/lab6#"
SENSOR = LAB6 + "CheckFridgeDoor_FridgeDoorSensor01"


@pytest.fixture(scope="module")
def kb() -> KnowledgeBase:
    kb = KnowledgeBase.open(":memory:")
    for graph in ("ontology", "map"):
        kb.load([EXAMPLES / "lab6_fridge.ttl"], graph=graph)
    kb.load([EXAMPLES / "lab6_door_status_informs.ttl"], graph="ontology")
    kb.load([EXAMPLES / "lab6_watch_the_fridge.ttl"], graph="requirements")
    kb.registry.register((EXAMPLES / "lab6_mistake_sensor_output.ttl").read_text())
    kb.registry.register((EXAMPLES / "lab6_caregiver_phone.ttl").read_text())
    return kb


def test_the_sensor_that_nearly_gives_the_requirement_its_output_is_named(kb: KnowledgeBase) -> None:
    result = Composer(kb).compose("WatchTheFridge")
    assert result.plan is None
    (unmet,) = result.unsatisfied
    assert unmet.need == "input door (home:Door)"  # the deepest need: the bundled sensor board's
    assert [(m.component, m.consumer) for m in unmet.near_misses] == [(SENSOR, "SRO")]
    text = unmet.text()
    assert "CheckFridgeDoor_FridgeDoorSensor01 comes close: it gives " in text
    assert "home:DeviceStatus, the requirement asks for home:DoorStatus (siblings, neither a kind of the other)" in text
    assert unmet.to_dict()["near_misses"][0]["consumer"] == "SRO"


def test_the_near_misses_along_the_chain_are_capped(kb: KnowledgeBase) -> None:
    config = ComposeConfig()
    for total, expected in ((0, 0), (1, 1)):
        found = Composer(kb, replace(config, near_misses_total=total)).compose("WatchTheFridge")
        assert len(found.unsatisfied[0].near_misses) == expected
    none = Composer(kb, replace(config, near_misses=0)).compose("WatchTheFridge")
    assert none.unsatisfied[0].near_misses == ()
