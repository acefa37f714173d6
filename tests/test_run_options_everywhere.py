"""The composition options ``cbrs run`` and ``cbrs plan`` take are taken wherever a run or plan starts.

``POST /tasks`` takes ``objective``, ``base_ties`` and ``near_misses`` as ``cbrs run --objective --base-ties
--near-misses`` (a bad value: 400 naming the field and what it takes), and the run's JSON says them; the
bridge's ``/cbrs/plan`` and the task editor's plan preview choose the base of a home of two mobile bases
as ``cbrs plan`` does (``actions.base_choice.choose_in_map``) and say which and why. The bridge's
``/cbrs/run_task`` service and action take the options too (refused in ``POST /tasks``'s words), the tasks
page's form offers them, and under ``--objective cost`` the base is chosen by the plans' summed stated
``cbrs:cost`` when every step states one. No simulation: the runs here stop before a world is built, and
the plans are the store's alone.
"""

from __future__ import annotations

import re
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from html import unescape
from types import SimpleNamespace
from typing import Any, cast

import pytest
from flask.testing import FlaskClient

from cbrs import tasks as tasks_module
from cbrs.actions.base_choice import BaseChoice, BaseTies, base_groups, choose_base, choose_in_map, map_bases
from cbrs.actions.composer import ComposeConfig, Composer, CompositionResult, Objective
from cbrs.actions.runner import _one_base
from cbrs.bridge_services import KnowledgeServices
from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import PREFIXES
from cbrs.rosbridge import GoalStatus, ServiceError
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
        no_plan = SimpleNamespace(plan=None, attempts=())
        return SimpleNamespace(report=None, to_dict=dict, replans=(), composition=no_plan, base=None)

    monkeypatch.setattr(tasks_module, "refusal_in_home", lambda *a, **kw: None)
    monkeypatch.setattr(tasks_module, "run_task", stand_in)
    monkeypatch.setattr("cbrs.sim.world.open_world", no_world)
    monkeypatch.setattr("cbrs.sim.components.SimEnvironment", lambda *a: SimpleNamespace(looked_for=lambda: ()))
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


# -- /cbrs/run_task, service and action -----------------------------------------------------------------


def _bridge(kb: KnowledgeBase, runner: TaskRunner) -> KnowledgeServices:
    return KnowledgeServices(SparqlService(kb), runner)


def _goal(args: dict[str, Any]) -> Any:
    """What run_task_goal uses of a goal handle: its args, feedback and the cancel hook."""
    return SimpleNamespace(args=args, publish_feedback=lambda message: None, on_cancel=lambda callback: None)


def test_the_bridge_run_task_takes_the_options_and_their_unset_values_are_the_defaults(
    bundled_kb: KnowledgeBase, served: tuple[FlaskClient, _Ended]
) -> None:
    _, runner = served
    services = _bridge(bundled_kb, runner)
    given = {"task": "FetchMyPen", "objective": "cost", "base_ties": "iri", "near_misses": 0, "wait": True}
    run = services.handlers()["/cbrs/run_task"][1](given)
    assert (run["objective"], run["base_ties"], run["near_misses"]) == ("cost", "iri", 0)
    # what a ROS client sends for "not given": empty text and -1, read as cbrs run's defaults
    unset = {"task": "FetchMyPen", "objective": "", "base_ties": "", "near_misses": -1, "wait": True}
    run = services.handlers()["/cbrs/run_task"][1](unset)
    defaults = ComposeConfig()
    expected = (defaults.objective.value, BaseTies.NEAREST.value, defaults.near_misses)
    assert (run["objective"], run["base_ties"], run["near_misses"]) == expected
    result = services.run_task_goal(_goal({"task": "FetchMyPen", "objective": "cost", "near_misses": 2}))
    assert result.status is GoalStatus.SUCCEEDED
    assert (result.values["objective"], result.values["base_ties"], result.values["near_misses"]) == (
        "cost",
        "nearest",
        2,
    )


@pytest.mark.parametrize(
    ("field", "value"),
    [
        pytest.param("objective", "fastest", id="objective"),
        pytest.param("base_ties", "random", id="base-ties"),
        pytest.param("near_misses", -2, id="near-misses-negative"),
        pytest.param("near_misses", 1.5, id="near-misses-fraction"),
    ],
)
def test_the_bridge_refuses_a_bad_option_as_post_tasks_does(
    bundled_kb: KnowledgeBase, served: tuple[FlaskClient, _Ended], field: str, value: object
) -> None:
    client, runner = served
    services = _bridge(bundled_kb, runner)
    before = len(runner.runs())
    with pytest.raises(ServiceError) as refused:
        services.handlers()["/cbrs/run_task"][1]({"task": "FetchMyPen", field: value})
    with pytest.raises(ServiceError) as goal_refused:
        services.run_task_goal(_goal({"task": "FetchMyPen", field: value}))
    assert str(goal_refused.value) == str(refused.value)
    assert len(runner.runs()) == before  # nothing started
    posted = client.post("/tasks.json", json={"task": "FetchMyPen", field: value})
    assert posted.status_code == 400
    if field != "near_misses":  # the page checks a number's form itself; the words of a choice are the runner's
        assert str(refused.value) == posted.get_json()["fields"][field]
    else:
        assert str(refused.value).startswith(f"near_misses {value!r} is not") and "0 or more" in str(refused.value)


# -- the tasks page's form ------------------------------------------------------------------------------


def test_the_start_form_offers_the_options_with_cbrs_runs_defaults(served: tuple[FlaskClient, _Ended]) -> None:
    client, runner = served
    page = client.get("/tasks").text
    form = page[page.index('id="start"') : page.index("</form>", page.index('id="start"'))]
    for name in ("objective", "base_ties", "near_misses"):
        assert f'<label for="{name}">' in form and f'name="{name}"' in form
    defaults = ComposeConfig()
    selected = dict(
        re.findall(
            r'<select id="(\w+)"[^>]*>\s*(?:<option value="\w+">\w+</option>)*'
            r'<option value="(\w+)" selected>',
            form,
        )
    )
    assert selected["objective"] == defaults.objective.value and selected["base_ties"] == BaseTies.NEAREST.value
    offered = set(re.findall(r'<option value="(\w+)"', form))
    assert {o.value for o in Objective} | {t.value for t in BaseTies} <= offered
    near = re.search(r'<input type="number" id="near_misses" name="near_misses" value="(\d+)"', form)
    assert near is not None and int(near.group(1)) == defaults.near_misses
    # the form as sent unchanged starts the run with them; another choice is kept
    answer = client.post(
        "/tasks", data={"task": "FetchMyPen", "objective": "cost", "base_ties": "iri", "near_misses": "0"}
    )
    assert answer.status_code == 202
    run = runner.get(answer.headers["Location"].removeprefix("/tasks/"))
    assert (run.objective, run.base_ties, run.near_misses) == ("cost", "iri", 0)
    again = client.post("/tasks", data={"task": "FetchMyPen", "objective": "far"})
    assert again.status_code == 400 and "objective &#39;far&#39; is not one of" in again.text


# -- the base chosen under --objective cost -------------------------------------------------------------

SVC = PREFIXES["svc"]
P1, P2 = SVC + "P3DX01", SVC + "P3DX02"
EVERY_COST = """PREFIX cbrs: <https://w3id.org/cbrs/core#>
INSERT { GRAPH ?g { ?q cbrs:cost 1.0 } }
WHERE { GRAPH ?g { ?q a cbrs:QoSModel FILTER NOT EXISTS { ?q cbrs:cost ?c } } }"""


@pytest.fixture(scope="module")
def stated() -> Iterator[KnowledgeBase]:
    """The two-base store where every component states cbrs:cost 1.0 but P3DX02's delivery, 0.1 (its
    response time and P3DX01's alike): by response time the bases tie, by stated cost P3DX02 is cheaper."""
    kb = KnowledgeBase.open(":memory:")
    kb.update((EXAMPLES / "lab6_two_bases.ru").read_text(encoding="utf-8"))
    text = (EXAMPLES / "lab6_second_base_components.ttl").read_text(encoding="utf-8")
    assert text.count("cbrs:responseTime 15.0 ;") == 1  # the delivery's
    kb.registry.register(text.replace("cbrs:responseTime 15.0 ;", "cbrs:responseTime 15.0 ; cbrs:cost 0.1 ;"))
    kb.update(EVERY_COST)
    kb.load([EXAMPLES / "lab6b_fetch_any_base.ttl"], graph="requirements")
    yield kb
    kb.close()


def _chosen(kb: KnowledgeBase, config: ComposeConfig) -> tuple[CompositionResult, BaseChoice]:
    composer = Composer(kb, config)
    found, chosen = choose_in_map(composer, TASK, composer.compose(TASK))
    assert chosen is not None and found.plan is not None
    return found, chosen


def test_objective_cost_chooses_the_base_whose_plan_states_the_least_summed_cost(stated: KnowledgeBase) -> None:
    found, chosen = _chosen(stated, ComposeConfig(objective=Objective.COST))
    assert found.plan is not None and (chosen.base, chosen.rule) == (P2, "stated-cost")
    assert "objective cost" in chosen.why and "stated cbrs:cost" in chosen.why and "P3DX01's" in chosen.why
    components = {step.component for step in found.plan.steps}
    assert SVC + "DeliverObject_P3DX02" in components and not components & chosen.left_out
    # the default objective chooses as before: the plans cost alike in seconds, the nearer base
    _, by_similarity = _chosen(stated, ComposeConfig())
    assert by_similarity.rule == "nearest" and by_similarity.base == P1 and "cbrs:cost" not in by_similarity.why


def test_objective_cost_with_a_step_stating_no_cost_ranks_by_response_time_and_says_so(
    two_bases: KnowledgeBase, as_cbrs_plan: dict[BaseTies, tuple[CompositionResult, BaseChoice | None]]
) -> None:
    """lab6's components state no cbrs:cost (the path planners alone do): the base is the default
    objective's, and the why says the stated cost could not rank."""
    _, chosen = _chosen(two_bases, ComposeConfig(objective=Objective.COST))
    _, as_before = as_cbrs_plan[BaseTies.NEAREST]
    assert as_before is not None and (chosen.base, chosen.rule) == (as_before.base, as_before.rule)
    assert (
        chosen.why
        == as_before.why + " (objective cost: not every step of the plans states a cbrs:cost, so response time ranks)"
    )


def _stub(cost: float, components: tuple[str, ...]) -> CompositionResult:
    steps = tuple(SimpleNamespace(component=c, candidates=(c,)) for c in components)
    plan = SimpleNamespace(steps=steps, cost=cost, similarity=0.9)
    attempt = SimpleNamespace(requirement=SimpleNamespace(requested_by=None))
    return cast(CompositionResult, SimpleNamespace(plan=plan, attempts=(attempt,)))


def test_stated_costs_rank_before_response_time_only_when_every_step_of_every_plan_states_one() -> None:
    groups = {P1: frozenset({"nav1"}), P2: frozenset({"nav2"})}
    quick, cheap = _stub(10.0, ("nav1", "arm")), _stub(20.0, ("nav2", "arm"))

    def compose(without: frozenset[str]) -> CompositionResult:
        return quick if "nav2" in without else cheap

    mixed = _stub(5.0, ("nav1", "nav2"))
    every = {"nav1": 3.0, "nav2": 1.0, "arm": 0.5}
    found, chosen = choose_base(compose, mixed, groups, stated=every)
    assert found is cheap and chosen is not None and chosen.rule == "stated-cost"
    assert "1.5 summed over its 2 steps, P3DX01's 3.5" in chosen.why
    for silent in ({"nav1": 3.0, "nav2": 1.0, "arm": None}, {"nav1": 3.0, "arm": 0.5}):
        found, chosen = choose_base(compose, mixed, groups, stated=silent)
        assert found is quick and chosen is not None and chosen.rule == "cost"
        assert chosen.why.endswith("so response time ranks)")
    found, chosen = choose_base(compose, mixed, groups)  # the default objective: no stated costs given
    assert found is quick and chosen is not None and "cbrs:cost" not in chosen.why


def test_a_run_chooses_the_base_by_the_stated_cost_as_cbrs_plan_does(stated: KnowledgeBase) -> None:
    """The runner's base choice (the environment's bases and a bus stood in for) under objective cost."""
    config = ComposeConfig(objective=Objective.COST)
    expected, chosen = _chosen(stated, config)
    groups = base_groups(stated, map_bases(stated))
    environment = SimpleNamespace(base_components=lambda: groups)
    said: list[dict[str, Any]] = []
    bus = SimpleNamespace(publish=lambda topic, message: said.append(message))
    composition = Composer(stated, config).compose(TASK, belief=True)
    found, by_run = _one_base(stated, config, TASK, composition, cast(Any, environment), cast(Any, bus), frozenset())
    assert by_run is not None and (by_run.base, by_run.rule, by_run.why) == (chosen.base, chosen.rule, chosen.why)
    assert found.plan is not None and expected.plan is not None
    assert [s.component for s in found.plan.steps] == [s.component for s in expected.plan.steps]
    assert said and said[0]["rule"] == "stated-cost"
