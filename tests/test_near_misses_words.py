"""Which complementary words set two concepts apart for near misses (actions.near_misses.about_other_things;
docs/composition.md, "Near misses"): those naming classes the ontology declares disjoint or siblings, not
any differing words. A robot's position is still not offered for a person's; a device's status is offered
for a door's (docs/tasks.md, "A sixth round": the lab's sensor went unnamed).

A small taxonomy shaped as the bundled home's is (home.ttl), built in memory, and the bundled one itself.
"""

from __future__ import annotations

import pytest

from cbrs.actions.composer import Composer
from cbrs.actions.graph import Matcher
from cbrs.actions.near_misses import SIBLINGS, about_other_things, near
from cbrs.kb import KnowledgeBase
from cbrs.reasoner.taxonomy import ROOT, Link, TaxonomyIndex

H = "https://example.org/h#"
IS_A = [
    ("Agent", None),
    ("Artifact", None),
    ("Device", "Artifact"),
    ("BuildingElement", "Artifact"),
    ("Door", "BuildingElement"),
    ("Robot", "Agent"),
    ("Robot", "Device"),
    ("Person", "Agent"),
    ("Status", None),
    ("DoorStatus", "Status"),
    ("DeviceStatus", "Status"),
    ("RobotStatus", "Status"),
    ("FridgeStatus", "Status"),  # "Fridge" names no class here
    ("Position", None),
    ("RobotPosition", "Position"),
    ("PersonPosition", "Position"),
]


def _matcher(disjoint: tuple[tuple[str, str], ...] = ()) -> Matcher:
    links = [Link(H + child, H + parent if parent else ROOT, "is-a") for child, parent in IS_A]
    return Matcher(TaxonomyIndex.from_links(links, disjoint=[(H + a, H + b) for a, b in disjoint]))


@pytest.mark.parametrize(
    ("wanted", "offered", "apart"),
    [
        pytest.param("PersonPosition", "RobotPosition", True, id="siblings-robot-person"),
        pytest.param("DoorStatus", "DeviceStatus", False, id="device-door-meet-further-up"),
        pytest.param("DeviceStatus", "RobotStatus", False, id="a-robot-is-a-device"),
        pytest.param("DoorStatus", "FridgeStatus", True, id="a-word-naming-no-class"),
        pytest.param("RobotStatus", "RobotPosition", False, id="the-same-word"),
    ],
)
def test_complementary_words_set_concepts_apart_when_they_name_siblings(wanted: str, offered: str, apart: bool) -> None:
    assert about_other_things(_matcher(), H + wanted, H + offered) is apart


def test_a_declared_disjointness_of_what_the_words_name_sets_them_apart() -> None:
    assert near(_matcher(), H + "DoorStatus", H + "DeviceStatus") == SIBLINGS
    disjoint = _matcher(disjoint=(("Device", "Door"),))
    assert about_other_things(disjoint, H + "DoorStatus", H + "DeviceStatus")
    assert near(disjoint, H + "DoorStatus", H + "DeviceStatus") is None


@pytest.fixture(scope="module")
def bundled(bundled_kb: KnowledgeBase) -> Matcher:
    return Composer(bundled_kb).matcher


def test_in_the_bundled_home_a_device_status_is_near_a_door_status_and_a_robot_position_not_a_persons(
    bundled: Matcher,
) -> None:
    home = "https://w3id.org/cbrs/home#"
    assert near(bundled, home + "DoorStatus", home + "DeviceStatus") == SIBLINGS
    assert near(bundled, home + "PersonPosition", home + "RobotPosition") is None
    assert near(bundled, home + "PersonLocation", home + "RobotLocation") is None
