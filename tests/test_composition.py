"""Composition: the catalogue of small problems with known answers (tests/data/composition)."""

from __future__ import annotations

import tomllib
from dataclasses import replace
from pathlib import Path
from typing import Any

import pytest

from cbrs.actions.composer import ComposeConfig, Composer, Objective, PlanStatus
from cbrs.actions.graph import SRI, SRO, ServiceResourceGraph
from cbrs.actions.search import bidirectional_search
from cbrs.kb import KnowledgeBase, Store
from cbrs.kb.resources import ontology_dir

DATA = Path(__file__).parent / "data" / "composition"
EX = "http://example.org/comp#"
PROBLEMS: list[dict[str, Any]] = tomllib.loads((DATA / "manifest.toml").read_text())["problem"]


def problem_kb(file: str) -> KnowledgeBase:
    kb = KnowledgeBase(Store.open(":memory:"))
    kb.load([ontology_dir() / "core.ttl"], graph="ontology")
    kb.load([DATA / "ontology.ttl"], graph="ontology")
    kb.load([DATA / file])
    return kb


@pytest.mark.parametrize("problem", [pytest.param(p, id=p["id"]) for p in PROBLEMS])
def test_catalogue_problem(problem: dict[str, Any]) -> None:
    kb = problem_kb(problem["file"])
    config = ComposeConfig(objective=Objective(problem.get("objective", "similarity")))
    result = Composer(kb, config).compose(EX + "Req")
    if "unsolvable" in problem:
        assert result.status is PlanStatus.UNSOLVABLE
        assert result.plan is None
        report = "\n".join(u.text() for u in result.unsatisfied)
        for text in problem["unsolvable"]:
            assert text in report
        return
    assert result.status is PlanStatus.PLANNED, [u.text() for u in result.unsatisfied]
    assert result.plan is not None
    assert [c.removeprefix(EX) for c in result.plan.components()] == problem["steps"]
    for component, expected in problem.get("alternatives", {}).items():
        step = next(s for s in result.plan.steps if s.component == EX + component)
        assert [a.removeprefix(EX) for a in step.alternatives] == expected


def test_every_binding_points_back_to_an_earlier_step_or_the_requirement() -> None:
    for problem in PROBLEMS:
        if "steps" not in problem:
            continue
        plan = Composer(problem_kb(problem["file"])).compose(EX + "Req").plan
        assert plan is not None
        for step in plan.steps:
            for binding in step.bindings:
                assert binding.source.step is None or binding.source.step < step.index
        assert all(g.source.step is None or g.source.step <= len(plan.steps) for g in plan.goals)


def test_shared_static_data_is_invoked_once() -> None:
    plan = Composer(problem_kb("shared.ttl")).compose(EX + "Req").plan
    assert plan is not None
    s3 = plan.step(3)
    sources = {b.name: b.source.step for b in s3.inputs}
    assert sources == {"b": 1, "c": 2}
    assert plan.step(2).inputs[0].source.step == 1


def test_graph_has_virtual_nodes_and_accepted_edges_only() -> None:
    kb = problem_kb("similarity_tie.ttl")
    composer = Composer(kb)
    graph: ServiceResourceGraph = composer.graph(composer.task(EX + "Req").requirement)
    into_sro = [e for e in graph.edges() if e.target == SRO]
    assert {e.source for e in into_sro} == {EX + "SExact", EX + "SGeneral"}
    degrees = {e.source: e.degree.value for e in into_sro}
    assert degrees == {EX + "SExact": "Exact", EX + "SGeneral": "HasSubClass"}
    exact = next(e for e in into_sro if e.source == EX + "SExact")
    general = next(e for e in into_sro if e.source == EX + "SGeneral")
    assert exact.similarity > general.similarity
    from_requirement = [e for e in graph.edges() if e.target == EX + "SExact" and e.source == SRI]
    assert [e.degree.value for e in from_requirement] == ["Exact"]


def test_search_levels_and_meeting() -> None:
    kb = problem_kb("chain.ttl")
    composer = Composer(kb)
    graph = composer.graph(composer.task(EX + "Req").requirement)
    trace = bidirectional_search(graph)
    assert trace.levels[SRI] == 0
    assert trace.levels[EX + "S1"] == 1
    assert trace.levels[EX + "S2"] == 2
    assert trace.levels[SRO] == 3
    assert {EX + "S1", EX + "S2"} <= trace.meeting
    assert any(e.source == EX + "S2" and e.target == SRO for e in trace.backward)
    assert any(e.source == SRI and e.target == EX + "S1" for e in trace.forward)


def test_unreachable_cycle_is_never_enabled() -> None:
    kb = problem_kb("cycle.ttl")
    composer = Composer(kb)
    trace = bidirectional_search(composer.graph(composer.task(EX + "Req").requirement))
    assert EX + "S1" not in trace.levels and EX + "S2" not in trace.levels


def test_deep_fan_in_stays_bounded(bundled_kb: KnowledgeBase) -> None:
    """Ten layers, each needing two results of the layer below: 2**10 invocations if every use got its
    own; past max_steps, uses share invocations, and the plan is still well formed."""
    from cbrs.actions.composer import ComposeConfig
    from cbrs.actions.model import ActionLibrary
    from cbrs.kb import Advertisement, Parameter, Requirement
    from cbrs.reasoner.taxonomy import ROOT, Link, TaxonomyIndex

    types = [f"{EX}T{i}" for i in range(11)]
    index = TaxonomyIndex.from_links([Link(t, ROOT, "is-a") for t in types])
    ads = [
        Advertisement(
            iri=f"{EX}L{i}",
            types=(),
            inputs=(
                Parameter(f"{EX}L{i}in1", "input", types[i - 1], "x"),
                Parameter(f"{EX}L{i}in2", "input", types[i - 1], "y"),
            ),
            outputs=(Parameter(f"{EX}L{i}out", "output", types[i], "out"),),
        )
        for i in range(1, 11)
    ]
    requirement = Requirement(
        iri=EX + "Deep",
        types=(),
        inputs=(Parameter(EX + "given", "input", types[0], "given"),),
        outputs=(Parameter(EX + "wanted", "output", types[10], "wanted"),),
    )
    composer = Composer(
        bundled_kb, ComposeConfig(max_steps=40), index=index, actions=ActionLibrary(), advertisements=ads
    )
    plan = composer.compose(requirement).plan
    assert plan is not None
    assert 10 <= len(plan.steps) <= 2 * 40
    assert plan.steps[-1].component == EX + "L10"
    for step in plan.steps:
        assert len(step.inputs) == 2
        assert all(b.source.step is None or b.source.step < step.index for b in step.bindings)


def test_a_task_names_a_requirement_never_an_advertisement() -> None:
    """A task is read by its own IRI first; an advertisement there is no task, and the error lists the
    requirements there are."""
    from cbrs.actions.errors import UnknownTaskError

    composer = Composer(problem_kb("chain.ttl"))
    assert composer.task(EX + "Req").requirement.iri == EX + "Req"
    with pytest.raises(UnknownTaskError) as error:
        composer.task(EX + "S1")
    assert error.value.known == ("Req",)


def test_a_bare_name_finds_a_task_of_any_namespace_and_says_when_it_is_ambiguous() -> None:
    """ex:Req is no req: or act: name: a bare "Req" found it only through the CLI, and the error listed
    "Req" among the known tasks it had just refused."""
    from cbrs.actions.errors import UnknownTaskError

    kb = problem_kb("chain.ttl")
    assert Composer(kb).task("Req").requirement.iri == EX + "Req"
    kb.update(
        "INSERT DATA { GRAPH <https://w3id.org/cbrs/graph/requirements> {"
        " <http://example.org/other#Req> a <https://w3id.org/cbrs/core#Requirement> } }"
    )
    with pytest.raises(UnknownTaskError, match="names more than one task") as error:
        Composer(kb).task("Req")
    assert error.value.known == ("http://example.org/comp#Req", "http://example.org/other#Req")


def test_a_task_with_nothing_to_plan_towards_says_what_to_state(bundled_kb: KnowledgeBase) -> None:
    """A task that wants nothing (no output, effect or delete effect) has no goal composition plans for:
    the reason says what to state, not to register a component for 'an output or effect'. One that wants
    only something to stop being true is planned for (tests/test_delete_goals.py)."""
    from cbrs.kb import Requirement, Statement

    home = "https://w3id.org/cbrs/home#"
    only_deletes = Requirement(
        iri=EX + "PenOffItsPlace",
        types=(),
        deletes=(Statement(home + "Pen", home + "isLocated", home + "Place"),),
    )
    result = Composer(bundled_kb).compose(replace(only_deletes, deletes=()))
    assert result.status is PlanStatus.UNSOLVABLE
    (reason,) = [u.text() for u in result.unsatisfied]
    assert "cbrs:hasEffect" in reason and "cbrs:hasDeleteEffect" in reason
    assert "register a component" not in reason
    plan = Composer(bundled_kb).compose(only_deletes).plan
    assert plan is not None and [g.role for g in plan.goals] == ["deletion"]


def test_a_plan_names_the_inputs_the_task_gives_that_no_step_takes(bundled_kb: KnowledgeBase) -> None:
    """A destination given as furniture, a class no component takes for a place: the plan went to the
    object's own place and said nothing of the input it left aside (new-user walkthrough)."""
    from dataclasses import replace

    from cbrs.cli_actions import plan_text
    from cbrs.kb.model import Parameter

    home = "https://w3id.org/cbrs/home#"
    fetch = Composer(bundled_kb).task("FetchMyPen").requirement
    assert Composer(bundled_kb).compose(fetch).unused_inputs == ()
    table = Parameter(fetch.iri + "/table", fetch.inputs[0].direction, home + "Table", "table")
    result = Composer(bundled_kb).compose(replace(fetch, inputs=(*fetch.inputs, table)))
    assert result.plan is not None and result.unused_inputs == (("table", home + "Table"),)
    assert result.to_dict()["unused_inputs"] == [{"name": "table", "type": home + "Table"}]
    assert "note: no step takes the task's input table (home:Table)" in plan_text(result)
