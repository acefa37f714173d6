"""A task's own preconditions are asked of the world before its first step (actions.task_preconditions;
docs/execution.md, "A task's preconditions"): one believed false refuses the run before anything moves,
naming it and what is believed instead; one nothing checks is taken as given and the result says so.
With a stand-in environment (no simulator); the simulated home's ``holds`` decides DeliverFromTheBase's
(docs/tasks.md, "A seventh round")."""

from __future__ import annotations

from collections import Counter
from collections.abc import Mapping
from typing import Any

import pyoxigraph as ox
import pytest

from cbrs.actions.belief import Observation
from cbrs.actions.components import Component, Registry, Status
from cbrs.actions.composer import Composer
from cbrs.actions.graph import statement_text
from cbrs.actions.plan import Plan, PlanStep
from cbrs.actions.runner import run_task
from cbrs.actions.task_preconditions import TaskPreconditionError
from cbrs.kb import KnowledgeBase, Requirement, Statement
from cbrs.kb.resources import ontology_dir
from cbrs.kb.shapes import DescriptionShapeError, may_write_descriptions
from tests.helpers_examples import EXAMPLES

EX = "http://example.org/given#"
TASK = f"""@prefix cbrs: <https://w3id.org/cbrs/core#> . @prefix ex: <{EX}> .
@prefix owl: <http://www.w3.org/2002/07/owl#> .
ex:A a owl:Class . ex:D a owl:Class . ex:Tray a owl:Class . ex:Table a owl:Class . ex:on a owl:ObjectProperty .
ex:Req a cbrs:Requirement ; cbrs:hasOWLSModel [ a cbrs:OWLSModel ;
    cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "a" ; cbrs:parameterType ex:A ] ;
    cbrs:hasPrecondition [ a cbrs:Precondition ; cbrs:conditionSubject ex:A ; cbrs:conditionPredicate ex:on ;
        cbrs:conditionObject ex:Tray ] ;
    cbrs:hasOutput [ a cbrs:Parameter ; cbrs:parameterName "d" ; cbrs:parameterType ex:D ] ] .
ex:Direct a cbrs:MethodInvocationComponent ; cbrs:serviceName "Direct" ;
    cbrs:hasOWLSModel [ a cbrs:OWLSModel ;
        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "a" ; cbrs:parameterType ex:A ] ;
        cbrs:hasPrecondition [ a cbrs:Precondition ; cbrs:conditionSubject ex:A ; cbrs:conditionPredicate ex:on ;
            cbrs:conditionObject ex:Tray ] ;
        cbrs:hasOutput [ a cbrs:Parameter ; cbrs:parameterName "d" ; cbrs:parameterType ex:D ] ] ;
    cbrs:hasQoSModel [ a cbrs:QoSModel ; cbrs:responseTime 1.0 ] .
"""
ON_TRAY = Statement(EX + "A", EX + "on", EX + "Tray")
LAB7 = "https://example.org/lab7#"


class Worker(Component):
    def __init__(self, iri: str, home: Home) -> None:
        super().__init__(iri)
        self.home = home

    def begin(self, inputs: Mapping[str, Any]) -> None:
        self.home.calls[self.iri] += 1

    def update(self) -> Status:
        self.outputs = {"d": "d1"}
        return Status.SUCCEEDED


class Home:
    """A stand-in environment: the block ``a1`` the task gives, perceived on the table ``t1``; ``holds``
    answers ``answer`` of every statement."""

    def __init__(self, answer: bool | None) -> None:
        self.answer = answer
        self.asked: list[Statement] = []
        self.calls: Counter[str] = Counter()
        self.registry = Registry()
        self.registry.add(EX + "Direct", lambda iri: Worker(iri, self))
        self.context = None

    def given(self, plan: Plan, requirements: Mapping[str, Requirement]) -> dict[str, Any]:
        return {"a": {"@id": EX + "a1"}}

    def verify(self, step: PlanStep | None, statement: Statement, outputs: Mapping[str, Any]) -> bool | None:
        return None

    def holds(self, statement: Statement) -> bool | None:
        self.asked.append(statement)
        return self.answer

    def observe(self) -> Observation:
        types = {EX + "a1": EX + "A", EX + "t1": EX + "Table"}
        return Observation(types, frozenset({(EX + "a1", EX + "on", EX + "t1")}), {EX + "a1": (1.0, 2.0, 0.7)})

    def clock(self) -> float:
        return 0.0


class Unasked(Home):
    """An environment that cannot tell (no ``holds``): the task's preconditions are taken as given."""

    holds = None  # type: ignore[assignment]


@pytest.fixture(scope="module")
def kb(tmp_path_factory: pytest.TempPathFactory) -> KnowledgeBase:
    store = KnowledgeBase.open(":memory:")
    store.load([ontology_dir() / "core.ttl"], graph="ontology")
    path = tmp_path_factory.mktemp("given") / "given.ttl"
    path.write_text(TASK, encoding="utf-8")
    store.load([path])
    return store


def test_a_precondition_believed_false_refuses_the_run_before_anything_moves(kb: KnowledgeBase) -> None:
    before = sorted(str(quad) for quad in kb.select("world_facts"))
    home = Home(False)
    with pytest.raises(TaskPreconditionError) as refused:
        run_task(kb, EX + "Req", home)
    error = refused.value
    assert home.asked == [ON_TRAY] and not home.calls  # asked, and no step started
    assert (error.requirement, error.statement) == (EX + "Req", ON_TRAY)
    assert error.instead == ((EX + "a1", EX + "on", EX + "t1"),)  # what the run perceives of the block
    text = str(error)
    assert f"does not hold: the run believes {EX}a1 {EX}on {EX}t1." in text
    assert "lab7_load_then_deliver.ttl" in text and "leave the precondition out" in text
    assert error.http_status == 409
    assert sorted(str(quad) for quad in kb.select("world_facts")) == before  # the store left as it was


@pytest.mark.parametrize(
    ("home", "believed"),
    [
        pytest.param(Home(True), True, id="perceived-holding"),
        pytest.param(Home(None), None, id="no-test-decides-it"),
        pytest.param(Unasked(None), None, id="environment-cannot-tell"),
    ],
)
def test_a_precondition_not_believed_false_runs_and_the_result_says_how_it_stood(
    kb: KnowledgeBase, home: Home, believed: bool | None
) -> None:
    result = run_task(kb, EX + "Req", home)
    assert result.succeeded and home.calls[EX + "Direct"] == 1
    assert [(check.statement, check.believed) for check in result.preconditions] == [(ON_TRAY, believed)]
    assert result.to_dict()["preconditions"] == [{"statement": statement_text(ON_TRAY), "believed": believed}]


# A requirement written by an update that names no graph lands in the default graph, where a task is found
# as in any graph; the update's descriptions are checked there as in graph:requirements (kb/shapes.py,
# CHECKED_GRAPHS; docs/tasks.md, "A seventh round": the GRAPH block left out).
WHERE_IS = (EXAMPLES / "lab7_where_is_my_pen.ru").read_text(encoding="utf-8")
UNGRAPHED = WHERE_IS.replace("INSERT DATA { GRAPH <https://w3id.org/cbrs/graph/requirements> {", "INSERT DATA {")
UNGRAPHED = UNGRAPHED[: UNGRAPHED.rindex("}")]  # the GRAPH block's closing brace


def test_a_description_an_update_writes_into_the_default_graph_is_checked(kb: KnowledgeBase) -> None:
    assert UNGRAPHED != WHERE_IS and "GRAPH" not in UNGRAPHED.rsplit("INSERT DATA", 1)[1]
    misspelt = UNGRAPHED.replace("home:Pen .", "home:Pne .")
    with pytest.raises(DescriptionShapeError, match="did you mean home:Pen"):
        kb.update(misspelt)
    assert not any(True for _ in kb.store.quads(ox.NamedNode(LAB7 + "WhereIsMyPen")))  # nothing written
    kb.update(UNGRAPHED)  # the same, spelt right: stored in the default graph and found as a task
    assert any(True for _ in kb.store.quads(ox.NamedNode(LAB7 + "WhereIsMyPen"), None, None, ox.DefaultGraph()))
    assert Composer(kb).task("WhereIsMyPen").requirement.iri == LAB7 + "WhereIsMyPen"


@pytest.mark.parametrize(
    ("text", "may"),
    [
        pytest.param("INSERT { <urn:a> cbrs:hasInput <urn:b> } WHERE {}", True, id="a-cbrs-term"),
        pytest.param("INSERT { <urn:a> <https://w3id.org/cbrs/core#hasInput> <urn:b> } WHERE {}", True, id="spelt-out"),
        pytest.param("COPY <urn:g> TO DEFAULT", True, id="into-the-default-graph"),
        pytest.param("INSERT { <urn:a> <urn:b> 1 } WHERE {}", False, id="no-description-term"),
    ],
)
def test_an_update_that_might_write_a_description_into_the_default_graph_is_recognised(text: str, may: bool) -> None:
    assert may_write_descriptions(text) is may
