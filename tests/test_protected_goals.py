"""A statement that holds when a plan starts and that a later step deletes is achieved again
(docs/composition.md, "A statement a later step undoes").

The scratch home of the report: a caregiver stands 0.9 m from the base's start, and the run's first
observation believes the base near her (``home:isNear``, as ``sim`` observes it). Fetching her pen, the
plan drove to the table, whose delete effect is that the base is no longer near a person, and then
delivered without driving back to her: delivery failed at run time and only the re-plan succeeded.
Plan only, no physics: each plan is checked by progression over its steps' add and delete effects.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import replace

import pytest

from cbrs.actions.composer import ComposeConfig, Composer, PlanStatus
from cbrs.actions.graph import SRE
from cbrs.actions.plan import Plan
from cbrs.actions.progression import progress
from cbrs.kb import KnowledgeBase, Requirement, Statement
from cbrs.kb.namespaces import GraphName, expand

HOME = expand("home:")
SVC = expand("svc:")
NEAR_PERSON = Statement(HOME + "MobileRobot", HOME + "isNear", HOME + "Person")

SCRATCH = """PREFIX home: <https://w3id.org/cbrs/home#> PREFIX world: <https://w3id.org/cbrs/world#>
PREFIX svc: <https://w3id.org/cbrs/service#> PREFIX graph: <https://w3id.org/cbrs/graph/>
PREFIX owl: <http://www.w3.org/2002/07/owl#> PREFIX rdfs: <http://www.w3.org/2000/01/rdf-schema#>
INSERT DATA {
  GRAPH graph:map { world:Caregiver a home:Caregiver , owl:NamedIndividual ; rdfs:label "the caregiver"@en ;
      home:colourName "blue" ; home:rgba "0.10 0.20 0.85 1" ; home:x 3.5 ; home:y 2.2 ; home:yaw 0.0 . }
  GRAPH graph:world { svc:P3DX01 home:isNear world:Caregiver . }
}"""
"""The caregiver 0.86 m from the base's start (3.0, 1.5), and the belief of the run's first observation."""


@pytest.fixture(scope="module")
def kb() -> Iterator[KnowledgeBase]:
    kb = KnowledgeBase.open(":memory:")
    kb.update(SCRATCH)
    yield kb
    kb.close()


@pytest.fixture(scope="module")
def composer(kb: KnowledgeBase) -> Composer:
    return Composer(kb)


@pytest.fixture(scope="module")
def caregivers_pen(composer: Composer) -> Requirement:
    """FetchMyPen for the caregiver: her class for the person, the pen with her for the goal."""
    fetch = composer.task("FetchMyPen").requirement
    inputs = tuple(replace(p, type=HOME + "Caregiver") if p.name == "person" else p for p in fetch.inputs)
    goal = Statement(HOME + "Pen", HOME + "isWith", HOME + "Caregiver")
    return replace(fetch, iri="urn:test:FetchTheCaregiversPen", inputs=inputs, effects=(goal,))


def _initial(kb: KnowledgeBase, requirement: Requirement) -> list[Statement]:
    """What holds when a run's plan starts: the task's preconditions, the map and the belief."""
    rows = [row for graph in (GraphName.MAP, GraphName.WORLD) for row in kb.select("world_state", {"graph": graph.iri})]
    world = [Statement(r["subjectType"].value, r["relation"].value, r["objectType"].value) for r in rows]
    return [*requirement.preconditions, *world]


def _plan(composer: Composer, requirement: Requirement) -> Plan:
    result = composer.compose(requirement, belief=True)
    assert result.status is PlanStatus.PLANNED and result.plan is not None, [u.text() for u in result.unsatisfied]
    return result.plan


def _index(plan: Plan, name: str) -> int:
    return next(s.index for s in plan.steps if s.component == SVC + name)


def test_the_drive_to_her_is_planned_after_the_drive_to_the_table(
    kb: KnowledgeBase, composer: Composer, caregivers_pen: Requirement
) -> None:
    plan = _plan(composer, caregivers_pen)
    assert progress(plan, _initial(kb, caregivers_pen), composer.matcher) == []
    to_table, to_her = _index(plan, "NavigateToPlace_P3DX01"), _index(plan, "NavigateToPerson_P3DX01")
    deliver = plan.step(_index(plan, "DeliverObject_P3DX01"))
    near = next(b for b in deliver.preconditions if b.statement == NEAR_PERSON)
    assert to_table < to_her < deliver.index and near.source.step == to_her
    # the base is localised and the caregiver tracked for that drive after the drive to the table
    feeders = {plan.step(b.source.step).component for b in plan.step(to_her).bindings if b.source.step}
    assert SVC + "LocateMobileRobot_CeilingCamera01" in feeders
    located = next(
        b.source.step
        for b in plan.step(to_her).preconditions
        if b.source.step and plan.step(b.source.step).component.endswith("LocateMobileRobot_CeilingCamera01")
    )
    assert located > to_table


def test_fetch_my_pen_for_the_resident_holds_by_progression_too(kb: KnowledgeBase, composer: Composer) -> None:
    requirement = composer.task("FetchMyPen").requirement
    plan = _plan(composer, requirement)
    assert progress(plan, _initial(kb, requirement), composer.matcher) == []


def test_without_protection_the_plan_skips_her_and_progression_names_the_deleter(
    kb: KnowledgeBase, composer: Composer, caregivers_pen: Requirement
) -> None:
    unprotected = Composer(
        kb,
        ComposeConfig(protect=False),
        index=composer.index,
        actions=composer.actions,
        advertisements=composer.advertisements,
    )
    plan = _plan(unprotected, caregivers_pen)
    assert all(s.component != SVC + "NavigateToPerson_P3DX01" for s in plan.steps)
    [undone] = progress(plan, _initial(kb, caregivers_pen), unprotected.matcher)
    assert undone.statement == NEAR_PERSON
    assert undone.consumer == _index(plan, "DeliverObject_P3DX01")
    assert undone.deleter == _index(plan, "NavigateToPlace_P3DX01")
    assert "deleted by step" in undone.text(plan) and "NavigateToPlace_P3DX01" in undone.text(plan)


def test_with_no_way_back_to_her_the_plan_is_refused_naming_the_statement(
    kb: KnowledgeBase, composer: Composer, caregivers_pen: Requirement
) -> None:
    ads = [ad for ad in composer.advertisements if ad.iri != SVC + "NavigateToPerson_P3DX01"]
    config = ComposeConfig(matched=False)
    result = Composer(kb, config, index=composer.index, actions=composer.actions, advertisements=ads).compose(
        caregivers_pen, belief=True
    )
    assert result.status is PlanStatus.UNSOLVABLE
    undone = result.unsatisfied[0]
    assert undone.deleted_by == (SVC + "NavigateToPlace_P3DX01",)
    assert undone.consumer == SVC + "DeliverObject_P3DX01"
    assert undone.text().startswith(
        "precondition (home:MobileRobot, home:isNear, home:Person) of svc:DeliverObject_P3DX01"
    )
    assert "is deleted by svc:NavigateToPlace_P3DX01 before it is needed" in undone.text()


def test_a_plan_nothing_undoes_is_the_same_with_and_without_protection(bundled_kb: KnowledgeBase) -> None:
    protected = Composer(bundled_kb)
    unprotected = Composer(
        bundled_kb,
        ComposeConfig(protect=False),
        index=protected.index,
        actions=protected.actions,
        advertisements=protected.advertisements,
    )
    for task in ("FetchMyPen", "RobotArmServeACup"):
        assert protected.compose(task).to_dict() == unprotected.compose(task).to_dict(), task


def test_goals_that_undo_each_other_are_refused_after_the_bound(bundled_kb: KnowledgeBase) -> None:
    """Near the person and near the pen's place at once: each drive deletes the other's goal, so each
    achieved again undoes the other, until ``max_reachieved``; before, the plan was accepted and its run
    failed one goal."""
    composer = Composer(bundled_kb, ComposeConfig(matched=False, max_reachieved=3))
    fetch = composer.task("FetchMyPen").requirement
    near_place = Statement(HOME + "MobileRobot", HOME + "isNear", HOME + "ObjectPlace")
    both = replace(fetch, iri="urn:test:NearBoth", for_task=None, effects=(NEAR_PERSON, near_place))
    result = composer.compose(both)
    assert result.status is PlanStatus.UNSOLVABLE
    [undone] = result.unsatisfied
    drives = {(SVC + "NavigateToPerson_P3DX01",), (SVC + "NavigateToPlace_P3DX01",)}
    assert undone.cycle and undone.deleted_by in drives and undone.consumer == SRE
    assert undone.text().startswith("effect (home:MobileRobot, home:isNear, home:")
    assert "each step that achieves it again undoes in turn another statement" in undone.text()
    assert "ComposeConfig.max_reachieved" in undone.remedy()
