"""A remote answer that designates (``@id``) a thing the store's map knows is checked against that thing's
classes, not only the ``@type`` the component wrote (actions/answers.py, docs/execution.md "An answer
that points at the wrong thing"): the kitchen scale answering the pen as its weight fails its step with
the reason, and nothing of the answer is kept."""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from concurrent.futures import Future
from pathlib import Path
from typing import Any

import pytest

from cbrs.actions.answers import StoreClasses, WrongThingError, check_designation
from cbrs.actions.components import Status
from cbrs.actions.remote import RemoteComponent
from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import PREFIXES
from cbrs.sim.components import implementations

HOME, WORLD = PREFIXES["home"], PREFIXES["world"]
EXAMPLES = Path(__file__).resolve().parents[1] / "docs" / "examples"
SCALE = "https://example.org/lab#WeighObject_KitchenScale01"


class Answering:
    """A transport whose every call is answered at once with ``answer``."""

    def __init__(self, answer: Any) -> None:
        self.answer = answer

    def call(self, service: str, args: Mapping[str, Any], timeout: float) -> Future[dict[str, Any]]:
        future: Future[dict[str, Any]] = Future()
        future.set_result(self.answer)
        return future


@pytest.fixture(scope="module")
def kb() -> Iterator[KnowledgeBase]:
    store = KnowledgeBase.open(":memory:")
    store.load([EXAMPLES / "lab_kitchen_scale.ttl"], graph="ontology")
    store.load([EXAMPLES / "lab_kitchen_scale.ttl"], graph="map")
    store.registry.register((EXAMPLES / "lab_weigh_object.ttl").read_text(encoding="utf-8"))
    yield store
    store.close()


def _scale_answering(kb: KnowledgeBase, weight: Any) -> tuple[RemoteComponent, Status]:
    component = implementations(kb, transport=Answering({"weight": weight}))(SCALE)
    assert isinstance(component, RemoteComponent)
    component.begin({})
    status = component.update()
    return component, status


def test_the_pen_answered_as_a_weight_fails_the_scale_s_step_and_changes_nothing(kb: KnowledgeBase) -> None:
    before = kb.store.dump()
    scale, status = _scale_answering(kb, {"@id": WORLD + "Pen", "@type": "home:ObjectWeight"})
    assert status is Status.FAILED
    assert scale.reason.startswith(
        "/kitchen_scale_01/weigh answered a wrong weight: it designates world:Pen, a home:Pen by the store's map"
        " and no home:ObjectWeight"
    )
    assert scale.outputs == {}
    assert kb.store.dump() == before


@pytest.mark.parametrize(
    "weight",
    [
        pytest.param({"@type": "home:ObjectWeight", "object": WORLD + "Cup", "grams": 150.0}, id="a-weight"),
        pytest.param({"@id": "urn:lab:reading-7", "@type": "home:ObjectWeight"}, id="a-thing-the-map-does-not-know"),
    ],
)
def test_a_weight_or_a_thing_the_map_does_not_know_is_taken(kb: KnowledgeBase, weight: dict[str, Any]) -> None:
    scale, status = _scale_answering(kb, weight)
    assert status is Status.SUCCEEDED, scale.reason
    assert scale.outputs["weight"]["@type"] == HOME + "ObjectWeight"


@pytest.mark.parametrize(
    ("port", "thing", "answered", "refused"),
    [
        pytest.param(HOME + "PhysicalObject", "Cup", HOME + "Cup", False, id="its-own-class"),
        pytest.param(HOME + "PhysicalObject", "Cup", HOME + "PhysicalObject", False, id="a-superclass-of-it"),
        pytest.param(HOME + "PhysicalObject", "Cup", HOME + "Pen", True, id="another-object-s-class"),
        pytest.param(HOME + "Place", "Pen", HOME + "Place", True, id="an-object-as-a-place"),
    ],
)
def test_a_designator_must_be_of_the_class_it_is_answered_as(
    kb: KnowledgeBase, port: str, thing: str, answered: str, refused: bool
) -> None:
    value = {"@id": WORLD + thing, "@type": answered}
    if not refused:
        check_designation(port, value, StoreClasses(kb))
        return
    with pytest.raises(WrongThingError) as error:
        check_designation(port, value, StoreClasses(kb))
    assert (error.value.thing, error.value.answered, error.value.concept) == (WORLD + thing, answered, port)
    assert error.value.classes and answered not in error.value.classes
