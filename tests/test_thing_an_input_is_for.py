"""The thing an input is for (docs/composition.md): an input of a physical class takes only a value of the class
the statements its step is planned for name for it. CallToTheTable alone (docs/tasks.md, "A fifteenth round":
the bell's sub-action, with no table set before it) gives only the mat, and its bell wants a cup on the mat: the
extraction took the base's colour marker, found by a ceiling camera, for the cup, and planned to put it on the
mat. Composed only; nothing is simulated."""

from __future__ import annotations

from dataclasses import replace

import pytest

from cbrs.actions.composer import ComposeConfig, Composer, PlanStatus
from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import PREFIXES
from tests.helpers_examples import EXAMPLES

HOME, SVC, LAB15 = PREFIXES["home"], PREFIXES["svc"], "https://example.org/lab15#"
MARKER = SVC + "DetectColourMarker_CeilingCamera01"


@pytest.fixture(scope="module")
def kb() -> KnowledgeBase:
    """The place setting in the ontology and the map, the lab's tasks, and the bell's component registered."""
    kb = KnowledgeBase.open(":memory:")
    for graph in ("ontology", "map"):
        kb.load([EXAMPLES / "lab15_place_setting.ttl"], graph=graph)
    kb.load(
        [EXAMPLES / "lab15_set_the_table.ttl", EXAMPLES / "lab15_set_the_table_and_call_me.ttl"], graph="requirements"
    )
    kb.registry.register((EXAMPLES / "lab15_dinner_bell.ttl").read_text("utf-8"))
    return kb


def test_a_cup_the_task_does_not_give_is_named_not_fetched(kb: KnowledgeBase) -> None:
    """No plan, and the reason names the cup the chain is for, the statement it is for, and the marker
    passed over; not the cameras' steps."""
    result = Composer(kb).compose("CallToTheTable")
    assert result.status is PlanStatus.UNSOLVABLE and result.unsatisfied
    for why in result.unsatisfied:
        assert why.things == (HOME + "Cup",)
        assert why.things_for.startswith("(home:Cup, home:isLocated, ") and "PlaceMat" in why.things_for
        assert (MARKER, "marker (home:ColourMarker)") in why.passed_over
        assert why.text().startswith("the task gives no home:Cup and no step gives one for input objectType")
        assert "give a home:Cup as an input of the task" in why.remedy()
        assert why.to_dict()["things"] == [HOME + "Cup"]


def test_without_the_rule_the_marker_stands_in_for_the_cup(kb: KnowledgeBase) -> None:
    """The fault the rule removes, with the rule off (thing_class None): the property query about the
    marker, the marker carried to the mat."""
    result = Composer(kb, ComposeConfig(thing_class=None)).compose("CallToTheTable")
    assert result.plan is not None
    sources = {
        (step.component.rsplit("#", 1)[-1], b.name): b.source
        for step in result.plan.steps
        for b in step.bindings
        if b.role == "input"
    }
    fed = sources[("QueryManipulationProperty_HomeServer01", "objectType")]
    assert fed.step is not None and result.plan.step(fed.step).component == MARKER


def test_given_the_cup_the_bell_is_rung_over_it(kb: KnowledgeBase) -> None:
    """The remedy the answer gives: with a cup among its inputs, the task's cup is picked up and put on the mat,
    and no step of the plan detects the marker."""
    composer = Composer(kb)
    task = composer.task("CallToTheTable")
    (cup,) = [p for p in composer.task("SetTheTableAndCallMe").requirement.inputs if p.type == HOME + "Cup"]
    requirement = replace(task.requirement, inputs=(*task.requirement.inputs, cup))
    result = composer.compose(requirement)
    assert result.plan is not None
    assert MARKER not in {step.component for step in result.plan.steps}
    taken = [
        b.source for step in result.plan.steps for b in step.bindings if b.role == "input" and b.name == "objectType"
    ]
    assert taken and all(source.step is None and source.name == "cup" for source in taken)
