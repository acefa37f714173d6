"""A round by a lab's integrators and its administrator, from the docs alone (docs/examples/lab12_*,
docs/serving.md "Tried by a lab's integrators"): a desk fan's smart plug written with the websockets
package from components.md's "The protocol", a run log that follows the server's topics, rdflib and curl
against the endpoint, and the administrator's token file, restarts and limits. Nothing is simulated here:
the fan's steps call the program over the bridge, and the plans are composed without a world."""

from __future__ import annotations

import json
from collections.abc import Iterator

import pytest

from cbrs.actions.base_choice import choose_in_map
from cbrs.actions.composer import Composer
from cbrs.kb import KnowledgeBase
from tests.helpers_examples import EXAMPLES

LAB12 = "https://example.org/lab12#"
SWITCH_ON, SWITCH_OFF = LAB12 + "SwitchOnDeskFan_FanPlug01", LAB12 + "SwitchOffDeskFan_FanPlug01"


@pytest.fixture(scope="module")
def fan_kb() -> Iterator[KnowledgeBase]:
    """The desk fan in the ontology and the map, its two tasks, and its plug's two components."""
    kb = KnowledgeBase.open(":memory:")
    for graph in ("ontology", "map"):
        kb.load([EXAMPLES / "lab12_desk_fan.ttl"], graph=graph)
    for task in ("lab12_switch_on_the_fan.ttl", "lab12_switch_off_the_fan.ttl"):
        kb.load([EXAMPLES / task], graph="requirements")
    kb.registry.register((EXAMPLES / "lab12_fan_switch.ttl").read_text("utf-8"))
    yield kb
    kb.close()


def test_a_plan_names_the_labs_component_whose_program_is_down(fan_kb: KnowledgeBase) -> None:
    """The plug's program stopped (its lease lapsed): `cbrs run` said "lab12:SwitchOffDeskFan_FanPlug01 was
    planned for it but cannot run here: unavailable: its lease lapsed", but `cbrs plan`, the plans page and
    the bridge's /cbrs/plan (all through choose_in_map) said only "no component provides ...; register a
    component whose effect is ...", to an integrator who had registered one."""
    for iri in (SWITCH_ON, SWITCH_OFF):
        fan_kb.liveness.renew(iri, 600.0)
    composer = Composer(fan_kb)
    live, _ = choose_in_map(composer, LAB12 + "SwitchOffTheDeskFan", composer.compose(LAB12 + "SwitchOffTheDeskFan"))
    assert live.plan is not None and live.plan.steps[0].component == SWITCH_OFF
    for iri in (SWITCH_ON, SWITCH_OFF):
        fan_kb.liveness.expire(iri, "its lease lapsed")
    composer = Composer(fan_kb)
    task = LAB12 + "SwitchOffTheDeskFan"
    gone, _ = choose_in_map(composer, task, composer.compose(task))
    assert gone.plan is None
    (unmet,) = gone.unsatisfied
    assert unmet.unrunnable == ((SWITCH_OFF, "unavailable: its lease lapsed"),)
    assert "SwitchOffDeskFan_FanPlug01 was planned for it but cannot run here: unavailable: its lease lapsed" in (
        unmet.text()
    )
    assert json.dumps(gone.to_dict()).count("its lease lapsed") >= 1
