"""The area rule's refusal says why a step was tied to a thing it is not given: the input (name and class)
whose value leads to it, and the cbrs:InformsOfThing mark that unties a class that only informs
(docs/composition.md, "Values that lead to a thing"; docs/tasks.md, "A sixth round": the living-room phone
passed over for the kitchen fridge "does not cover lab6:Fridge1", and nothing said that the door's status
it is given tied it there)."""

from __future__ import annotations

import pytest

from cbrs.actions.composer import ComposeConfig, Composer
from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import PREFIXES
from tests.helpers_examples import EXAMPLES

HOME = PREFIXES["home"]
PHONE = "https://example.org/lab6#AlertByPhone_ResidentPhone01"
# the bundled marks but home:Status, made to lead: a door's status then ties the phone to the fridge
STATUS_LEADS = ComposeConfig(
    area_informs=(HOME + "InformationEntity",), area_leads=(HOME + "SpatialData", HOME + "Feature", HOME + "Status")
)


@pytest.fixture(scope="module")
def kb() -> KnowledgeBase:
    kb = KnowledgeBase.open(":memory:")
    for graph in ("ontology", "map"):
        kb.load([EXAMPLES / "lab6_fridge.ttl"], graph=graph)
    kb.load([EXAMPLES / "lab6_watch_the_fridge.ttl"], graph="requirements")
    kb.registry.register((EXAMPLES / "lab6_fridge_door_sensor.ttl").read_text())
    kb.registry.register((EXAMPLES / "lab6_caregiver_phone.ttl").read_text())
    return kb


def test_the_refusal_names_the_input_that_leads_to_the_thing_and_the_mark(kb: KnowledgeBase) -> None:
    result = Composer(kb, STATUS_LEADS).compose("WatchTheFridge")
    assert result.plan is None
    passed = {component: why for need in result.unsatisfied for component, why in need.out_of_area}
    why = passed[PHONE]
    assert "does not cover " in why and "Fridge1 (the task's fridge)" in why
    assert "which its input doorStatus (home:DoorStatus, a class that leads to its thing) is about" in why
    assert "home:DoorStatus cbrs:areaRole cbrs:InformsOfThing" in why


def test_a_thing_the_step_is_given_itself_is_named_without_an_input(kb: KnowledgeBase) -> None:
    """The phone is given the person directly: a refusal over the person says no more than before."""
    rule = Composer(kb).area_rule(Composer(kb).task("WatchTheFridge").requirement)
    assert rule is not None
    phone = next(ad for ad in Composer(kb).advertisements if ad.iri == PHONE)
    why = rule.why_not(phone, {"fridge"})
    assert why is not None and "which its input" not in why and "InformsOfThing" not in why
    led = rule.why_not(phone, {"fridge"}, {"fridge": ("doorStatus", HOME + "DoorStatus")})
    assert led is not None and led.startswith(why) and "its input doorStatus (home:DoorStatus" in led


def test_the_bundled_status_mark_lets_the_phone_serve_the_fridge(kb: KnowledgeBase) -> None:
    plan = Composer(kb).compose("WatchTheFridge").plan
    assert plan is not None and plan.components()[-1] == PHONE
