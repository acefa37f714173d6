"""``cbrs run`` refuses a task no plan can come of before it builds the simulated home
(``actions.runner.refusal_before_world``), with the answer a run that built it and perceived gives; and
goes on to build it whenever something perceived might still make a plan. Every refusal here is made
with ``open_world`` replaced by one that fails the test: no world is built, which is the point. The
one world built (to compare the answers) runs no step."""

from __future__ import annotations

import json
from collections.abc import Callable, Iterator, Mapping, Sequence
from pathlib import Path
from typing import Any

import pytest
from click.testing import CliRunner

from cbrs.actions.composer import Composer
from cbrs.actions.runner import refusal_before_world, run_task
from cbrs.cli import cli
from cbrs.kb import Advertisement, KnowledgeBase
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.semantic_map import SemanticMap
from cbrs.sim.components import SimEnvironment, implementations
from cbrs.sim.run_checks import map_cameras, without_camera
from cbrs.sim.world import open_world

SVC, REQ = PREFIXES["svc"], PREFIXES["req"]
NO_CEILING_CAMERAS = (
    "DELETE WHERE { GRAPH graph:map { svc:CeilingCamera01 ?p ?o } };"
    " DELETE WHERE { GRAPH graph:map { svc:CeilingCamera02 ?p ?o } }"
)
GOAL_ONLY = """@prefix cbrs: <https://w3id.org/cbrs/core#> .
@prefix home: <https://w3id.org/cbrs/home#> .
@prefix req:  <https://w3id.org/cbrs/requirement#> .
@prefix svc:  <https://w3id.org/cbrs/service#> .
req:{name} a cbrs:Requirement ; cbrs:requestedBy svc:CytonDualArm01 ; cbrs:deviceName "CytonDualArm01" ;
    cbrs:serviceName "{name}" ;
    cbrs:hasOWLSModel [ a cbrs:OWLSModel ;
        cbrs:hasEffect [ a cbrs:Effect ; cbrs:conditionSubject home:Pen ; cbrs:conditionPredicate home:{relation} ;
            cbrs:conditionObject home:{object} ] ] .
"""


@pytest.fixture
def no_world(monkeypatch: pytest.MonkeyPatch) -> None:
    def built(*_: Any, **__: Any) -> Any:
        raise AssertionError("the simulated home was built")

    monkeypatch.setattr("cbrs.sim.world.open_world", built)


@pytest.fixture(scope="module")
def kb() -> Iterator[KnowledgeBase]:
    """The bundled store, for the runner's own checks (the tasks added to it have no plan)."""
    store = KnowledgeBase.open(":memory:")
    yield store
    store.close()


@pytest.fixture(scope="module")
def bundled(tmp_path_factory: pytest.TempPathFactory) -> str:
    """The bundled store, for ``cbrs run`` (seeded once)."""
    location = str(tmp_path_factory.mktemp("refused_early") / "bundled")
    KnowledgeBase.open(location).close()
    return location


@pytest.fixture(scope="module")
def blind_store(tmp_path_factory: pytest.TempPathFactory) -> Iterator[str]:
    """The bundled home without its two ceiling cameras: the robot's locators and the person's tracker look
    with cameras the map does not place."""
    location = str(tmp_path_factory.mktemp("refused_early") / "store")
    kb = KnowledgeBase.open(location)
    try:
        kb.update(NO_CEILING_CAMERAS)
    finally:
        kb.close()
    yield location


def runnable(kb: KnowledgeBase) -> tuple[set[str], Callable[[Sequence[Advertisement]], Mapping[str, str]]]:
    """What the simulated home will implement, by the store (as ``cbrs run`` works it out before building it)."""
    placed = map_cameras(kb)
    names = set(implementations(kb).names()) - set(without_camera(kb.advertisements(), placed))
    return names, lambda ads: without_camera(ads, placed)


def test_a_task_no_component_meets_is_refused_before_the_home_is_built(no_world: None, bundled: str) -> None:
    runner = CliRunner()
    text = runner.invoke(cli, ["--store", bundled, "run", "RouteToGoal"])
    assert text.exit_code == 1 and isinstance(text.exception, SystemExit), text.output
    assert text.output.startswith("req:RouteToGoal: no plan. What no component provides:\n  - no component provides")
    as_json = runner.invoke(cli, ["--store", bundled, "run", "RouteToGoal", "--json", "--seed", "4"])
    assert as_json.exit_code == 1
    found = json.loads(as_json.output)
    assert found["status"] == "unsolvable" and "execution" not in found
    assert found["seed"] == 4 and found["sim_seconds"] == 0.0  # nothing was simulated
    assert found["plan"]["status"] == "unsolvable" and found["plan"]["unsatisfied"]


def test_the_early_answer_is_the_one_a_run_gives_after_perceiving(kb: KnowledgeBase) -> None:
    names, why_not = runnable(kb)
    early = refusal_before_world(kb, REQ + "RouteToGoal", names, Composer(kb), why_not)
    assert early is not None and early.report is None
    before = set(kb.store.quads())
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        late = run_task(kb, REQ + "RouteToGoal", SimEnvironment(world, kb), composer=Composer(kb))
    assert late.report is None and set(kb.store.quads()) == before
    assert [u.text() for u in early.composition.unsatisfied] == [u.text() for u in late.composition.unsatisfied]
    assert early.to_dict() == late.to_dict()


def test_a_camera_the_map_does_not_place_is_named_in_the_early_refusal(no_world: None, blind_store: str) -> None:
    """With no ceiling camera the robot cannot be located: refused before the home is built, the locator
    named with why (before, the run said the simulation had no skill for its service name)."""
    text = CliRunner().invoke(cli, ["--store", blind_store, "run", "RobotSelfPosition"])
    assert text.exit_code == 1 and isinstance(text.exception, SystemExit), text.output
    assert "no component provides output selfPosition (home:RobotPosition)" in text.output
    assert (
        "svc:LocateMobileRobot_CeilingCamera01 was planned for it but cannot run here: it looks with"
        " CeilingCamera01, which the map does not place" in text.output
    )
    assert "has no skill for its service name" not in text.output


def test_a_task_whose_goal_the_home_might_hold_at_the_start_is_not_refused_early(blind_store: str) -> None:
    """FetchMyPen without a tracker has no plan, unless the pen is with the person already: only the home
    can tell (a goal that holds wants no step), so the home is built first. A goal of a relation no
    perception decides (a pen's marker) is refused at once; one perception decides (the pen full of
    water) is left to the run, though no component provides it either."""
    kb = KnowledgeBase.open(blind_store)
    try:
        names, why_not = runnable(kb)
        assert Composer(kb).compose("FetchMyPen", belief=True).plan is not None  # over every component
        assert refusal_before_world(kb, "FetchMyPen", names, Composer(kb), why_not) is None
    finally:
        kb.close()


@pytest.mark.parametrize(
    ("relation", "obj", "early"), [("hasMarker", "ColourMarker", True), ("contains", "Water", False)]
)
def test_only_a_goal_no_perception_could_find_holding_is_refused_early(
    kb: KnowledgeBase, tmp_path: Path, relation: str, obj: str, early: bool
) -> None:
    name = f"Pen{relation.capitalize()}"
    task = tmp_path / "task.ttl"
    task.write_text(GOAL_ONLY.replace("{name}", name).replace("{relation}", relation).replace("{object}", obj))
    kb.load([task], graph="requirements")
    assert Composer(kb).compose(REQ + name, belief=True).plan is None  # no component provides it
    names, why_not = runnable(kb)
    refused = refusal_before_world(kb, REQ + name, names, Composer(kb), why_not)
    assert (refused is not None) is early
    if refused is not None:
        assert refused.composition.plan is None and refused.report is None


def test_every_bundled_task_the_home_can_run_goes_on_to_the_home(kb: KnowledgeBase) -> None:
    names, why_not = runnable(kb)
    composer = Composer(kb)
    for requirement in kb.requirements():
        planned = composer.compose(requirement.iri, belief=True).plan
        if planned is None or not all(step.component in names for step in planned.steps):
            continue
        assert refusal_before_world(kb, requirement.iri, names, composer, why_not) is None, requirement.iri
