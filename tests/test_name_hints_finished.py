"""A name typed with a prefix nobody declared (``rq:``, ``hom:``) is refused saying so wherever cbrs reads
one, not only where the CLI reads it: a task's name for the library, the tasks and plans pages (the
message itself, which the pages show: a note they leave out), a component kind on the services page, a
value's ``@type`` in a remote answer or a late answer's inputs (it was taken as typed and matched nothing,
or dropped)."""

from __future__ import annotations

import logging
from collections.abc import Iterator
from pathlib import Path

import pytest
from flask.testing import FlaskClient

from cbrs.actions.answers import StoreClasses, UnknownTypeError, check_designation
from cbrs.actions.late_answers import GivenUp, watch
from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import HOME
from cbrs.sparql_service import SparqlService
from cbrs.task_names import TaskNameError, task_iri
from cbrs.web import create_app

EXAMPLES = Path(__file__).resolve().parents[1] / "docs" / "examples"
PREFIX_SAID = "rq: is declared nowhere and is no IRI scheme cbrs reads bare; did you mean req:FetchMyPen?"


@pytest.fixture(scope="module")
def client(bundled_kb: KnowledgeBase) -> FlaskClient:
    return create_app(SparqlService(bundled_kb)).test_client()


def test_a_task_with_a_misspelt_prefix_says_so_to_a_library_caller(bundled_kb: KnowledgeBase) -> None:
    with pytest.raises(TaskNameError) as refused:
        task_iri(bundled_kb, "rq:FetchMyPen")
    error = refused.value
    assert error.prefix_reason == PREFIX_SAID
    assert str(error).startswith(f"no requirement or action named 'rq:FetchMyPen' ({PREFIX_SAID}); did you mean")
    with pytest.raises(TaskNameError) as unknown:  # a declared prefix: nothing to say of it
        task_iri(bundled_kb, "req:FetchMyPenn")
    assert unknown.value.prefix_reason is None and "declared nowhere" not in str(unknown.value)


@pytest.mark.parametrize("path", ["/plans.json", "/tasks.json"])
def test_the_pages_say_what_is_wrong_with_a_tasks_prefix(client: FlaskClient, path: str) -> None:
    answer = client.get(path, query_string={"task": "rq:FetchMyPen"})
    assert answer.status_code == 400
    assert PREFIX_SAID in answer.get_json()["fields"]["task"]


def test_a_kind_with_a_misspelt_prefix_is_refused_naming_the_prefix(client: FlaskClient) -> None:
    answer = client.get("/services.json", query_string={"kind": "cbr:StaticDataComponent"})
    assert answer.status_code == 400
    said = answer.get_json()["fields"]["kind"]
    assert "cbr: is declared nowhere" in said and "did you mean cbrs:StaticDataComponent?" in said


def test_a_kind_of_no_advertisement_is_offered_the_nearest(client: FlaskClient) -> None:
    answer = client.get("/services.json", query_string={"kind": "StaticData"})
    assert answer.status_code == 400
    said = answer.get_json()["fields"]["kind"]
    assert said.startswith("no advertisement is of kind 'StaticData'; did you mean cbrs:StaticDataComponent?")
    assert client.get("/services.json", query_string={"kind": "StaticDataComponent"}).status_code == 200


@pytest.fixture(scope="module")
def door_kb() -> Iterator[KnowledgeBase]:
    kb = KnowledgeBase.open(":memory:")
    kb.load([EXAMPLES / "lab_bedroom_door.ttl"], graph="map")
    kb.registry.register((EXAMPLES / "lab_open_door.ttl").read_text(encoding="utf-8"))
    yield kb
    kb.close()


DOOR = "https://example.org/lab#BedroomDoor"


def test_an_answers_type_with_a_misspelt_prefix_is_refused_as_such(door_kb: KnowledgeBase) -> None:
    """It was taken as typed: the door answered as a 'hom:Door' was refused as the wrong thing."""
    with pytest.raises(UnknownTypeError) as refused:
        check_designation(HOME + "Door", {"@id": DOOR, "@type": "hom:Door"}, StoreClasses(door_kb))
    assert refused.value.written == "hom:Door" and "did you mean home:Door?" in str(refused.value)
    with pytest.raises(UnknownTypeError, match="no IRI and no prefixed name"):
        check_designation(HOME + "Door", {"@id": DOOR, "@type": "Door"}, StoreClasses(door_kb))
    check_designation(HOME + "Door", {"@id": DOOR, "@type": "home:Door"}, StoreClasses(door_kb))  # passes


def test_a_late_answers_input_with_a_misspelt_type_is_named(
    door_kb: KnowledgeBase, caplog: pytest.LogCaptureFixture
) -> None:
    """Its type was dropped without a word; now the call's watch says which type names no class."""
    inputs = {"door": {"@id": DOOR, "@type": "hom:Door"}}
    call = GivenUp("https://example.org/lab#OpenDoor_BedroomDoorMotor01", "/open", 1.0, inputs)
    with caplog.at_level(logging.WARNING, logger="cbrs.actions.remote"):
        assert watch(door_kb, StoreClasses(door_kb), call, lambda values: values) is None
    (said,) = [r.getMessage() for r in caplog.records if "changes no belief" in r.getMessage()]
    assert "the '@type' 'hom:Door' names no class: hom: is declared nowhere" in said
    assert "did you mean home:Door?" in said
