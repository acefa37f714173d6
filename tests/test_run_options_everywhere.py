"""The composition options ``cbrs run`` and ``cbrs plan`` take are taken wherever a run or plan starts.

``POST /tasks`` takes ``objective``, ``base_ties`` and ``near_misses`` as ``cbrs run --objective --base-ties
--near-misses`` (a bad value: 400 naming the field and what it takes), and the run's JSON says them; the
bridge's ``/cbrs/plan`` and the task editor's plan preview choose the base of a home of two mobile bases
as ``cbrs plan`` does (``actions.base_choice.choose_in_map``) and say which and why. No simulation: the
runs here stop before a world is built, and the plans are the store's alone.
"""

from __future__ import annotations

import re
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from html import unescape
from types import SimpleNamespace
from typing import Any

import pytest
from flask.testing import FlaskClient

from cbrs import tasks as tasks_module
from cbrs.actions.base_choice import BaseChoice, BaseTies, choose_in_map
from cbrs.actions.composer import ComposeConfig, Composer, CompositionResult, Objective
from cbrs.bridge_services import KnowledgeServices
from cbrs.kb import KnowledgeBase
from cbrs.sparql_service import EndpointConfig, SparqlService
from cbrs.tasks import TaskRun, TaskRunner
from cbrs.web import create_app
from tests.helpers_examples import EXAMPLES

WAIT = 10.0
TASK = "https://example.org/lab6#FetchMyPenAnyBase"
ANY_BASE = (EXAMPLES / "lab6b_fetch_any_base.ttl").read_text(encoding="utf-8")


class _Ended(TaskRunner):
    """A runner whose runs end at once: no planner, no world."""

    def _run(self, run: TaskRun) -> None:
        run.status = "succeeded"
        run.done.set()


@pytest.fixture(scope="module")
def served(bundled_kb: KnowledgeBase) -> Iterator[tuple[FlaskClient, _Ended]]:
    sparql = SparqlService(bundled_kb)
    runner = _Ended(bundled_kb, sparql.lock, camera=None)
    yield create_app(sparql, tasks=runner).test_client(), runner


@pytest.fixture(scope="module")
def two_bases() -> Iterator[KnowledgeBase]:
    """The bundled home with lab6's second Pioneer, its components and the task no robot requests."""
    kb = KnowledgeBase.open(":memory:")
    kb.update((EXAMPLES / "lab6_two_bases.ru").read_text(encoding="utf-8"))
    kb.registry.register((EXAMPLES / "lab6_second_base_components.ttl").read_text(encoding="utf-8"))
    kb.load([EXAMPLES / "lab6b_fetch_any_base.ttl"], graph="requirements")
    yield kb
    kb.close()


@pytest.fixture(scope="module")
def as_cbrs_plan(two_bases: KnowledgeBase) -> dict[BaseTies, tuple[CompositionResult, BaseChoice | None]]:
    """What ``cbrs plan FetchMyPenAnyBase --base-ties T`` composes and chooses, for each T."""
    composer = Composer(two_bases)
    every = composer.compose(TASK)
    return {ties: choose_in_map(composer, TASK, every, ties) for ties in BaseTies}


@pytest.mark.parametrize("path", ["/tasks", "/tasks.json"])
def test_a_run_posted_takes_the_composition_options_and_says_them(
    served: tuple[FlaskClient, _Ended], path: str
) -> None:
    client, runner = served
    body = {"task": "FetchMyPen", "objective": "cost", "base_ties": "iri", "near_misses": 0}
    answer = client.post(path, json=body, headers={"Accept": "application/json"})
    assert answer.status_code == 202, answer.text[:300]
    started = answer.get_json()["started"]
    assert runner.get(started["id"]).done.wait(WAIT)
    run = client.get(answer.headers["Location"]).get_json()["run"]
    assert (run["objective"], run["base_ties"], run["near_misses"]) == ("cost", "iri", 0)


def test_a_form_post_takes_them_and_their_absence_is_cbrs_runs_defaults(served: tuple[FlaskClient, _Ended]) -> None:
    client, runner = served
    answer = client.post("/tasks", data={"task": "FetchMyPen", "objective": "cost", "near_misses": "5"})
    assert answer.status_code == 202
    run = runner.get(answer.headers["Location"].removeprefix("/tasks/"))
    assert (run.objective, run.base_ties, run.near_misses) == ("cost", "nearest", 5)
    plain = client.post("/tasks.json", json={"task": "FetchMyPen"}).get_json()["started"]
    found = runner.get(plain["id"])
    assert found.done.wait(WAIT)
    defaults = ComposeConfig()
    assert (found.objective, found.near_misses) == (defaults.objective.value, defaults.near_misses)
    assert found.base_ties == BaseTies.NEAREST.value


@pytest.mark.parametrize(
    ("field", "value", "says"),
    [
        pytest.param("objective", "fastest", "one of similarity, cost", id="objective"),
        pytest.param("base_ties", "random", "one of nearest, iri", id="base-ties"),
        pytest.param("near_misses", "some", "'some' is not a whole number", id="near-misses-text"),
        pytest.param("near_misses", -1, "0 or more", id="near-misses-negative"),
    ],
)
def test_a_bad_option_is_refused_naming_the_field_and_what_it_takes(
    served: tuple[FlaskClient, _Ended], field: str, value: object, says: str
) -> None:
    client, runner = served
    before = len(runner.runs())
    answer = client.post("/tasks.json", json={"task": "FetchMyPen", field: value})
    assert answer.status_code == 400, answer.text[:300]
    assert says in answer.get_json()["fields"][field]
    assert len(runner.runs()) == before  # nothing started


def test_the_run_composes_with_them_as_cbrs_run_does(
    bundled_kb: KnowledgeBase, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The runner's composer and run_task get the options (the world, environment and run stood in for)."""
    seen: dict[str, Any] = {}

    @contextmanager
    def no_world(**_: Any) -> Iterator[Any]:
        yield SimpleNamespace(time=0.0)

    def stand_in(kb: KnowledgeBase, task: str, env: Any, faults: Any, composer: Composer, *a: Any, **kw: Any) -> Any:
        seen.update(config=composer.config, base_ties=kw["base_ties"])
        return SimpleNamespace(report=None, to_dict=dict)

    monkeypatch.setattr(tasks_module, "refusal_in_home", lambda *a, **kw: None)
    monkeypatch.setattr(tasks_module, "run_task", stand_in)
    monkeypatch.setattr("cbrs.sim.world.open_world", no_world)
    monkeypatch.setattr("cbrs.sim.components.SimEnvironment", lambda *a: None)
    runner = TaskRunner(bundled_kb, threading.RLock(), camera=None)
    run = runner.run("FetchMyPen", objective="cost", base_ties="iri", near_misses=1, timeout=WAIT)
    assert run.status == "no-plan", run.error
    assert seen["config"].objective is Objective.COST and seen["config"].near_misses == 1
    assert seen["base_ties"] is BaseTies.IRI


@pytest.mark.parametrize("ties", [BaseTies.NEAREST, BaseTies.IRI])
def test_the_bridge_plan_chooses_the_base_as_cbrs_plan_does(
    two_bases: KnowledgeBase, as_cbrs_plan: dict[BaseTies, tuple[CompositionResult, BaseChoice | None]], ties: BaseTies
) -> None:
    sparql = SparqlService(two_bases)
    services = KnowledgeServices(sparql, TaskRunner(two_bases, sparql.lock, camera=None))
    answer = services.plan({"task": "FetchMyPenAnyBase", "base_ties": ties.value})
    expected, chosen = as_cbrs_plan[ties]
    assert chosen is not None and expected.plan is not None
    assert answer["base"] == chosen.to_dict() and answer["base"]["why"] and answer["base"]["left_out"]
    components = [step["component"] for step in answer["steps"]]
    assert components == [step.component for step in expected.plan.steps]
    assert not set(components) & chosen.left_out  # no other base's component in the plan


def test_the_bridge_plan_refuses_a_bad_base_ties_and_a_one_base_home_is_unchanged(bundled_kb: KnowledgeBase) -> None:
    from cbrs.rosbridge import ServiceError

    sparql = SparqlService(bundled_kb, EndpointConfig(read_only=True))  # the shared store: nothing recorded
    services = KnowledgeServices(sparql, TaskRunner(bundled_kb, sparql.lock, camera=None))
    with pytest.raises(ServiceError, match="base_ties 'far' is not one of nearest, iri"):
        services.plan({"task": "FetchMyPen", "base_ties": "far"})
    answer = services.plan({"task": "FetchMyPen"})
    assert answer["status"] == "planned" and "base" not in answer and not answer["recorded"]


def _preview(client: FlaskClient, text: str, as_json: bool) -> Any:
    return client.post("/tasks/new" + (".json" if as_json else ""), data={"turtle": text, "action": "check"})


def test_the_editor_preview_says_the_base_in_a_two_base_home(
    two_bases: KnowledgeBase, as_cbrs_plan: dict[BaseTies, tuple[CompositionResult, BaseChoice | None]]
) -> None:
    """The draft is the stored task under another name: it is planned as that one is (the default ties)."""
    client = create_app(SparqlService(two_bases), tasks=_Ended(two_bases, threading.RLock(), camera=None)).test_client()
    draft = ANY_BASE.replace("lab6:FetchMyPenAnyBase a", "lab6:FetchMyPenDraft a")
    _, chosen = as_cbrs_plan[BaseTies.NEAREST]
    assert chosen is not None
    answer = _preview(client, draft, as_json=True)
    assert answer.status_code == 200, answer.text[:300]
    base = answer.get_json()["base"]
    assert (base["base"], base["rule"]) == (chosen.base, chosen.rule)
    page = unescape(re.sub(r"<[^>]+>", "", _preview(client, draft, as_json=False).text))
    assert "as a run would choose it: " + chosen.why in page


def test_the_editor_preview_of_a_one_base_home_says_no_base(served: tuple[FlaskClient, _Ended]) -> None:
    client, _ = served
    draft = ANY_BASE.replace("lab6:FetchMyPenAnyBase a", "lab6:FetchMyPenDraft a")
    answer = _preview(client, draft, as_json=True)
    assert answer.status_code == 200 and answer.get_json()["base"] is None
    assert "as a run would choose it" not in _preview(client, draft, as_json=False).text
