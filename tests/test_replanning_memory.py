"""Re-planning after a deterministic failure: what the run remembers (actions.replanning).

With stubs (no simulator): a component that fails the same way every time, with the thing its input
names believed where it was, is planned around when another route exists, and otherwise repeated at
most ``ReplanPolicy.max_repeats`` times; a failure after which the thing moved is tried again. In
the simulated home, the pencil taken askew at seed 6 is still fetched by the same plan, after the
re-perception found it moved: tests/test_turtle_tasks_arms.py checks that of its run.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import pytest

from cbrs.actions.belief import Observation
from cbrs.actions.components import Component, Registry, Status
from cbrs.actions.plan import Plan, PlanStep
from cbrs.actions.replanning import Failure, ReplanPolicy, ReplanPolicyError
from cbrs.actions.runner import RunResult, run_task
from cbrs.cli_actions import run_text
from cbrs.kb import KnowledgeBase, Requirement, Statement
from cbrs.kb.namespaces import shorten
from cbrs.kb.resources import ontology_dir

EX = "http://example.org/replan#"
HEAD = f"""@prefix cbrs: <https://w3id.org/cbrs/core#> . @prefix ex: <{EX}> .
@prefix owl: <http://www.w3.org/2002/07/owl#> . @prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> .
ex:A a owl:Class . ex:B a owl:Class . ex:D a owl:Class .
ex:Req a cbrs:Requirement ; cbrs:hasOWLSModel [ a cbrs:OWLSModel ;
    cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "a" ; cbrs:parameterType ex:A ] ;
    cbrs:hasOutput [ a cbrs:Parameter ; cbrs:parameterName "d" ; cbrs:parameterType ex:D ] ] .
"""


def component(name: str, given: str, made: str, seconds: float) -> str:
    return f"""ex:{name} a cbrs:MethodInvocationComponent ; cbrs:serviceName "{name}" ;
    cbrs:hasOWLSModel [ a cbrs:OWLSModel ;
        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "{given.lower()}" ; cbrs:parameterType ex:{given} ] ;
        cbrs:hasOutput [ a cbrs:Parameter ; cbrs:parameterName "{made.lower()}" ; cbrs:parameterType ex:{made} ] ] ;
    cbrs:hasQoSModel [ a cbrs:QoSModel ; cbrs:responseTime {seconds} ] .
"""


DIRECT = component("Direct", "A", "D", 1.0)  # the best plan: one step
AROUND = component("Prepare", "A", "B", 1.0) + component("Finish", "B", "D", 5.0)  # another route


class Worker(Component):
    """Succeeds, or fails with the same reason, as ``Home.failing`` says for its invocation."""

    def __init__(self, iri: str, home: Home) -> None:
        super().__init__(iri)
        self.home = home

    def begin(self, inputs: Mapping[str, Any]) -> None:
        self.home.calls[self.iri] += 1

    def update(self) -> Status:
        if self.home.calls[self.iri] <= self.home.failing.get(self.iri, 0):
            self.reason = "gripper closed on nothing 0.42 m from the block"
            return Status.FAILED
        self.outputs = {"b": "b1", "d": "d1"}
        return Status.SUCCEEDED


class Home:
    """A stub environment: one block ``a1`` the task gives, which a look may find moved by ``moves`` m."""

    def __init__(self, failing: Mapping[str, int], moves: float = 0.0) -> None:
        self.failing = {EX + name: times for name, times in failing.items()}
        self.calls: Counter[str] = Counter()
        self.moves = moves
        self.where = (1.0, 2.0, 0.7)
        self.registry = Registry()
        for name in ("Direct", "Prepare", "Finish"):
            self.registry.add(EX + name, lambda iri: Worker(iri, self))
        self.context = None

    def given(self, plan: Plan, requirements: Mapping[str, Requirement]) -> dict[str, Any]:
        return {"a": {"@id": EX + "a1"}}

    def verify(self, step: PlanStep | None, statement: Statement, outputs: Mapping[str, Any]) -> bool | None:
        return None

    def perceive(self) -> None:
        x, y, z = self.where
        self.where = (x + self.moves, y, z)

    def observe(self) -> Observation:
        return Observation({EX + "a1": EX + "A"}, frozenset(), {EX + "a1": self.where})

    def clock(self) -> float:
        return 0.0


def kb_with(text: str, tmp_path: Path) -> KnowledgeBase:
    kb = KnowledgeBase.open(":memory:")
    kb.load([ontology_dir() / "core.ttl"], graph="ontology")
    path = tmp_path / "replan.ttl"
    path.write_text(HEAD + text, encoding="utf-8")
    kb.load([path])
    return kb


def run(kb: KnowledgeBase, home: Home, policy: ReplanPolicy | None = None) -> RunResult:
    return run_task(kb, EX + "Req", home, replan_policy=policy)


def planned(result: RunResult) -> list[str]:
    assert result.report is not None
    return [step.planned.removeprefix(EX) for step in result.report.steps]


# The old behaviour is the policy that neither avoids nor bounds within the budget of two re-plans.
OLD = ReplanPolicy(avoid=False, max_repeats=2)


def test_a_failure_nothing_changed_since_is_planned_around(tmp_path: Path) -> None:
    kb = kb_with(DIRECT + AROUND, tmp_path)
    old = Home({"Direct": 99})
    repeated = run(kb, old, OLD)
    assert not repeated.succeeded and len(repeated.replans) == 2 and old.calls[EX + "Direct"] == 3
    new = Home({"Direct": 99})
    result = run(kb, new)
    assert result.succeeded and len(result.replans) == 1
    assert planned(result) == ["Prepare", "Finish"] and new.calls[EX + "Direct"] == 1
    replaced = result.replans[0]
    assert replaced.avoided == (EX + "Direct",)
    assert [(f.component, f.inputs, f.things) for f in replaced.failures] == [
        (EX + "Direct", (("a", EX + "a1"),), frozenset({EX + "a1"}))
    ]
    assert result.to_dict()["replans"][0]["avoided"] == [EX + "Direct"]


def test_with_no_other_route_the_run_stops_naming_the_repeated_failure(tmp_path: Path) -> None:
    kb = kb_with(DIRECT, tmp_path)
    old = Home({"Direct": 99})
    assert len(run(kb, old, OLD).replans) == 2 and old.calls[EX + "Direct"] == 3
    once = Home({"Direct": 99})
    result = run(kb, once)  # the default: one repeat
    assert not result.succeeded and len(result.replans) == 1 and once.calls[EX + "Direct"] == 2
    assert result.stopped.startswith("re-planning stopped: step 1 (Direct with a <- a1): gripper closed on nothing")
    assert "met 2 time(s) with nothing it depends on changed (a1); no plan avoids it" in result.stopped
    assert result.to_dict()["stopped"] == result.stopped
    never = Home({"Direct": 99})
    stopped = run(kb, never, ReplanPolicy(max_repeats=0))
    assert not stopped.replans and never.calls[EX + "Direct"] == 1
    assert "met 1 time(s)" in stopped.stopped and stopped.stopped.endswith("again (repeats allowed: 0)")


def test_a_failure_after_which_its_thing_moved_runs_the_same_plan_again(tmp_path: Path) -> None:
    """As the pencil let go and seen elsewhere: the re-perception moved what the failed step worked on,
    so the best plan is tried again rather than the route around it."""
    kb = kb_with(DIRECT + AROUND, tmp_path)
    home = Home({"Direct": 1}, moves=0.10)
    result = run(kb, home)
    assert result.succeeded and len(result.replans) == 1 and not result.replans[0].avoided
    assert planned(result) == ["Direct"] and home.calls[EX + "Direct"] == 2
    still = Home({"Direct": 1}, moves=0.01)  # within the tolerance: it has not moved
    assert planned(run(kb, still)) == ["Prepare", "Finish"]


def test_a_policy_refuses_impossible_bounds_and_a_failure_kind_ignores_measurements() -> None:
    with pytest.raises(ReplanPolicyError) as refused:
        ReplanPolicy(max_repeats=-1)
    assert refused.value.name == "max_repeats" and refused.value.value == -1
    with pytest.raises(ReplanPolicyError, match="tolerance"):
        ReplanPolicy(tolerance=-0.5)
    with pytest.raises(ReplanPolicyError, match="reconnect_grace"):
        ReplanPolicy(reconnect_grace=float("nan"))
    one = Failure(3, EX + "Direct", (), "taken askew (0.42 rad) at (7.36, 3.30)", frozenset())
    other = Failure(5, EX + "Direct", (), "taken askew (0.40 rad) at (7.35, 3.31)", frozenset())
    assert one.key == other.key and one.kind == "taken askew (# rad) at (#, #)"


class Producer(Worker):
    """Answers with the B it is named after: ``Locate`` a wrong one, ``Locate2`` a right one."""

    def update(self) -> Status:
        self.outputs = {"b": "wrong" if self.iri.endswith("#Locate") else "right", "c": "c1"}
        return Status.SUCCEEDED


class Consumer(Worker):
    """Fails on a wrong B, as an arm fails on a position a camera gave half a metre off."""

    def begin(self, inputs: Mapping[str, Any]) -> None:
        super().begin(inputs)
        self.given = dict(inputs)

    def update(self) -> Status:
        if self.given.get("b") == "wrong":
            self.reason = "no free arm reaches the block at (8.57, 3.30)"
            return Status.FAILED
        self.outputs = {"d": "d1"}
        return Status.SUCCEEDED


def test_when_no_plan_avoids_the_failed_step_the_next_avoids_what_it_was_given(tmp_path: Path) -> None:
    """The consumer is the only way to D, and failed on what the best producer gave it: the re-plan
    composes without that producer, so the other one is tried instead of the same plan again."""
    producers = component("Grasp", "A", "C", 1.0) + component("Locate", "A", "B", 1.0)
    producers += component("Locate2", "A", "B", 3.0)  # a stand-in for Locate; the grasp planner has none
    use = component("Use", "B", "D", 1.0).replace(
        "cbrs:hasOutput",
        'cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "c" ; cbrs:parameterType ex:C ] ;\n'
        "        cbrs:hasOutput",
    )
    kb = kb_with("ex:C a owl:Class .\n" + producers + use, tmp_path)
    home = Home({})
    home.registry = Registry()
    for name in ("Grasp", "Locate", "Locate2"):
        home.registry.add(EX + name, lambda iri: Producer(iri, home))
    home.registry.add(EX + "Use", lambda iri: Consumer(iri, home))
    result = run(kb, home)
    assert result.succeeded, result.stopped or (result.report.reason if result.report else "")
    assert len(result.replans) == 1 and sorted(planned(result)) == ["Grasp", "Locate2", "Use"]
    failure = result.replans[0].failures[0]
    assert failure.component == EX + "Use" and set(failure.producers) == {EX + "Grasp", EX + "Locate"}
    assert result.replans[0].avoided == (EX + "Locate",)
    assert home.calls[EX + "Locate"] == 1 and home.calls[EX + "Use"] == 2
    # said as what it was: Locate gave the failed step its input; it is not said to have failed
    text = run_text(result, 0.0, 0.0)
    assert f"avoids {shorten(EX + 'Locate')} (gave the failed step its inputs)" in text, text
    assert "failed, nothing changed" not in text
