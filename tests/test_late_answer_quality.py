"""A late answer (actions.late_answers) keeps a quality class as a value by the rule a step in time is
believed by (actions.qualities.OwnQualities, shared with sim.components): only as the subject's own
quality, by a relation of home:hasQualityPart's family. The resident's phone's alert, (Person,
lab6:isAlertedOf, DoorStatus), answered after its call was given up, is neither believed nor kept, as in
time (docs/components.md); the door motor's (Door, hasStatus, Opened) still is. No world is built."""

from __future__ import annotations

import logging
from collections.abc import Iterator
from concurrent.futures import Future
from pathlib import Path
from typing import Any

import pytest

from cbrs.actions.answers import StoreClasses
from cbrs.actions.belief import BeliefState
from cbrs.actions.late_answers import GivenUp, watch
from cbrs.actions.qualities import OwnQualities
from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import PREFIXES
from cbrs.sim.components import SimEnvironment

EXAMPLES = Path(__file__).resolve().parents[1] / "docs" / "examples"
HOME, LAB, LAB6 = PREFIXES["home"], "https://example.org/lab#", "https://example.org/lab6#"
PERSON = {"@id": "https://w3id.org/cbrs/world#Person", "@type": "home:Person"}
DOOR = {"@id": LAB + "BedroomDoor", "@type": "home:Door"}


@pytest.fixture(scope="module")
def kb() -> Iterator[KnowledgeBase]:
    store = KnowledgeBase.open(":memory:")
    store.load([EXAMPLES / "lab_bedroom_door.ttl"], graph="map")
    store.load([EXAMPLES / "lab6_fridge.ttl"], graph="ontology")
    store.registry.register((EXAMPLES / "lab_open_door.ttl").read_text(encoding="utf-8"))
    store.registry.register((EXAMPLES / "lab6_caregiver_phone.ttl").read_text(encoding="utf-8"))
    yield store
    store.close()


def _answer_late(kb: KnowledgeBase, component: str, service: str, inputs: dict[str, Any], answer: Any) -> None:
    """``component``'s call, given up, then answered ``answer`` (settled in this thread)."""
    settle = watch(kb, StoreClasses(kb), GivenUp(component, service, 1.0, inputs), lambda values: values)
    assert settle is not None
    done: Future[dict[str, Any]] = Future()
    done.set_result(answer)
    settle(done)


def _told(caplog: pytest.LogCaptureFixture) -> str:
    (message,) = [r.getMessage() for r in caplog.records if "after its call was given up" in r.getMessage()]
    return message


def test_a_late_alert_about_a_status_is_not_believed(kb: KnowledgeBase, caplog: pytest.LogCaptureFixture) -> None:
    with caplog.at_level(logging.WARNING, logger="cbrs.actions.remote"):
        inputs = {"person": PERSON, "doorStatus": {"@type": "home:Opened"}}
        _answer_late(kb, LAB6 + "AlertByPhone_ResidentPhone01", "/alert", inputs, {"alert": {}})
    assert not [f for f in BeliefState(kb).facts(PERSON["@id"]) if f[1] == LAB6 + "isAlertedOf"]
    message = _told(caplog)
    assert "not believed: (home:Person, " in message
    assert "isAlertedOf, home:DoorStatus) (a quality class no quality of its subject" in message
    assert "now believed" not in message


def test_a_late_door_status_is_still_believed(kb: KnowledgeBase, caplog: pytest.LogCaptureFixture) -> None:
    with caplog.at_level(logging.WARNING, logger="cbrs.actions.remote"):
        answer = {"doorStatus": {"@type": "home:Opened"}}
        _answer_late(kb, LAB + "OpenDoor_BedroomDoorMotor01", "/open", {"door": DOOR}, answer)
    assert (DOOR["@id"], HOME + "hasStatus", HOME + "Opened") in BeliefState(kb).facts(DOOR["@id"])
    assert "home:hasStatus, home:Opened)" in _told(caplog)


def test_the_simulated_environment_asks_the_same_rule(kb: KnowledgeBase) -> None:
    environment = object.__new__(SimEnvironment)  # the rule reads the store alone: no world is built
    environment.kb, environment._superclasses, environment._qualities = kb, None, None
    shared = OwnQualities(kb, StoreClasses(kb).is_a)
    for predicate, value in [
        (HOME + "hasStatus", HOME + "Opened"),
        (LAB6 + "isAlertedOf", HOME + "DoorStatus"),
        (HOME + "hasStatus", HOME + "Cup"),
    ]:
        assert environment._own_quality(predicate, value) == shared(predicate, value)
    assert shared(HOME + "hasStatus", HOME + "Opened") and shared.passing(LAB6 + "isAlertedOf", HOME + "DoorStatus")
    assert isinstance(environment._qualities, OwnQualities)
