"""A home with no mobile base (docs/simulation.md, "A home with no mobile base"): the home check takes it; the
simulation builds no base, and the components that work one have no implementation; a task of the arms runs
(one simulation run); a task for the base is refused before the world is built, naming the base's components
and why; `cbrs home` says what such a home allows. A home of two bases is taken too: a run drives the base its
plan's steps name, and a plan naming two, or none, is refused; two started on each other are refused."""

from __future__ import annotations

import json
from collections.abc import Iterator
from dataclasses import replace
from types import SimpleNamespace
from typing import cast

import pytest
from click.testing import CliRunner
from markupsafe import escape

from cbrs.actions.composer import Composer
from cbrs.actions.runner import run_task
from cbrs.app import App
from cbrs.cli_home import home
from cbrs.home_plan import NO_BASE, SEVERAL_BASES, survey
from cbrs.kb import KnowledgeBase
from cbrs.kb.home_check import HomeError, NoMobileBaseError, check_home
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.semantic_map import SemanticMap
from cbrs.sim.components import SimEnvironment
from cbrs.sim.mapping import OccupancyGrid
from cbrs.sim.run_checks import WhichBaseError, base_for, map_bases, without_base
from cbrs.sim.services import provide_grid_map
from cbrs.sim.values import decode
from cbrs.sim.world import HomeWorld, open_world
from cbrs.tasks import refusal_in_home
from tests.helpers_examples import updated_store

SVC, WORLD = PREFIXES["svc"], PREFIXES["world"]
NO_BASE_RU, TWO_BASES_RU = "lab6_no_base.ru", "lab6_two_bases.ru"
BASE_WORDS = "it works the mobile base (drives it, loads its platform or finds its marker), and graph:map has none"


@pytest.fixture(scope="module")
def no_base() -> KnowledgeBase:
    return updated_store(NO_BASE_RU)


@pytest.fixture(scope="module")
def world(no_base: KnowledgeBase) -> Iterator[HomeWorld]:
    with open_world(seed=0, semantic_map=SemanticMap.read(no_base)) as built:
        yield built


def test_the_update_takes_the_base_and_all_said_of_it_out_of_the_map(no_base: KnowledgeBase) -> None:
    smap = SemanticMap.read(no_base)
    check_home(smap)  # no HomeError
    assert smap.robots == {} and map_bases(no_base) == set()
    assert map_bases(updated_store()) == {SVC + "P3DX01"}
    rows = no_base.query(
        "SELECT ?s WHERE { GRAPH <https://w3id.org/cbrs/graph/map> { ?s ?p ?o FILTER(CONTAINS(STR(?s), 'P3DX01')) } }"
    )
    assert list(rows) == []  # its platform, marker and the marker's colours went with it


def test_cbrs_home_says_what_a_home_with_no_base_allows(no_base: KnowledgeBase) -> None:
    assert survey(no_base).bases() == NO_BASE and survey(updated_store()).bases() == "P3DX01"
    done = CliRunner().invoke(home, [], obj=App(":memory:", no_base))
    assert done.exit_code == 0, done.output
    assert "0 mobile robots" in done.output
    assert "mobile robots: none: a task that drives the base, loads its platform or finds its marker is refused" in (
        done.output
    )
    assert "check: the simulation can build this home" in done.output
    said = json.loads(CliRunner().invoke(home, ["--json"], obj=App(":memory:", no_base)).output)
    assert said["verdict"] == "ok" and said["mobile_robots"] == NO_BASE


@pytest.mark.parametrize(
    ("task", "named"),
    [
        pytest.param("FetchMyPen", ["NavigateToPlace_P3DX01", "HandOverOntoPlatform_CytonDualArm01"], id="fetch"),
        # no plan from the map at all (the locator's precondition, the base's marker, is gone): named all the same
        pytest.param("RobotSelfPosition", ["LocateMobileRobot_CeilingCamera01"], id="self-position"),
    ],
)
def test_a_task_for_the_base_is_refused_before_the_world_is_built(
    no_base: KnowledgeBase, task: str, named: list[str]
) -> None:
    result = refusal_in_home(no_base, task, Composer(no_base))
    assert result is not None and result.report is None  # no plan, and no world was built
    unrunnable = dict(result.composition.unsatisfied[0].unrunnable)
    for component in named:
        assert unrunnable[SVC + component] == BASE_WORDS


def test_a_task_of_the_arms_is_not_refused_before_the_world(no_base: KnowledgeBase) -> None:
    assert refusal_in_home(no_base, "RobotArmServeACup", Composer(no_base)) is None


def test_with_a_base_or_several_no_component_is_left_out_for_it(no_base: KnowledgeBase) -> None:
    ads = Composer(no_base).advertisements
    assert without_base(ads, {SVC + "P3DX01"}) == {} == without_base(ads, {SVC + "P3DX01", SVC + "P3DX02"})
    assert without_base(ads, set())[SVC + "NavigateToPlace_P3DX01"] == BASE_WORDS
    assert SVC + "PickUpObject_CytonDualArm01" not in without_base(ads, set())


@pytest.fixture(scope="module")
def two_bases() -> KnowledgeBase:
    return updated_store(TWO_BASES_RU)


def test_two_bases_are_taken_and_said(two_bases: KnowledgeBase) -> None:
    """docs/examples/lab6_two_bases.ru: the home is taken, cbrs home says what it allows, and a task for a
    base goes on to the world (its plan says which base)."""
    smap = SemanticMap.read(two_bases)
    check_home(smap)  # no HomeError
    assert sorted(smap.robots) == [SVC + "P3DX01", SVC + "P3DX02"]
    assert survey(two_bases).bases() == f"P3DX01, P3DX02; {SEVERAL_BASES}"
    assert refusal_in_home(two_bases, "FetchMyPen", Composer(two_bases)) is None


def _home_of(smap: SemanticMap) -> HomeWorld:
    """What :func:`base_for` asks of the world (its bases and map), without building one."""
    return cast(HomeWorld, SimpleNamespace(mobiles={r.name: r for r in smap.robots.values()}, map=smap))


def test_the_base_a_plan_works_is_the_one_its_steps_name(two_bases: KnowledgeBase) -> None:
    composer = Composer(two_bases)
    plan = composer.compose("FetchMyPen").plan
    assert plan is not None
    ads = {ad.iri: ad for ad in composer.advertisements}
    world = _home_of(SemanticMap.read(two_bases))
    assert base_for(world, plan, ads, {}) == "P3DX01"  # NavigateToPlace_P3DX01 and the others: the locator names none
    # the locator alone, given P3DX02's marker colours: P3DX02
    locate = next(step for step in plan.steps if "LocateMobileRobot" in step.component)
    marker = {name: {"@id": WORLD + "P3DX02MarkerColours"} for name in {b.source.name for b in locate.inputs}}
    alone = replace(plan, steps=(locate,))
    assert base_for(world, alone, ads, marker) == "P3DX02"
    with pytest.raises(WhichBaseError, match=r"the home has 2 mobile bases \(P3DX01, P3DX02\): the plan's "):
        base_for(world, alone, ads, {})  # nothing names a base
    # a drive by a second base's component besides the first's: two bases, refused naming both
    drive = next(step for step in plan.steps if "NavigateToPlace" in step.component)
    other = replace(
        ads[drive.component], iri=SVC + "NavigateToPlace_P3DX02", device_name="P3DX02", device=SVC + "P3DX02"
    )
    both = replace(plan, steps=(*plan.steps, replace(drive, component=other.iri)))
    with pytest.raises(WhichBaseError, match=r"the plan works two of them \(.*NavigateToPlace_P3DX02 work P3DX02"):
        base_for(world, both, {**ads, other.iri: other}, {})
    one = SemanticMap.read(updated_store())
    assert base_for(_home_of(one), plan, ads, {}) is None  # a home of one: nothing to choose


def test_two_bases_started_on_each_other_are_refused_naming_both() -> None:
    kb = updated_store(TWO_BASES_RU)  # its own: the update moves the second base
    kb.update(
        "PREFIX home: <https://w3id.org/cbrs/home#> PREFIX svc: <https://w3id.org/cbrs/service#> "
        "DELETE { GRAPH <https://w3id.org/cbrs/graph/map> { svc:P3DX02 home:x ?x ; home:y ?y } } "
        "INSERT { GRAPH <https://w3id.org/cbrs/graph/map> { svc:P3DX02 home:x 3.3 ; home:y 1.5 } } "
        "WHERE { GRAPH <https://w3id.org/cbrs/graph/map> { svc:P3DX02 home:x ?x ; home:y ?y } }"
    )
    refused = r"P3DX02 .* starts at \(3\.30, 1\.50\), 0\.30 m from P3DX01 at \(3\.00, 1\.50\)"
    with pytest.raises(HomeError, match=refused):
        check_home(SemanticMap.read(kb))


def test_the_early_refusal_is_the_one_a_run_gives_after_perceiving(no_base: KnowledgeBase, world: HomeWorld) -> None:
    """FetchMyPen, refused before the world is built (nobody holds the pen in a world just built:
    ``sim.perceived.UNSEEN_AT_START``), is refused alike by a run in the built world, which runs no step."""
    early = refusal_in_home(no_base, "FetchMyPen", Composer(no_base))
    started = world.time
    late = run_task(no_base, "FetchMyPen", SimEnvironment(world, no_base), composer=Composer(no_base))
    assert early is not None and late.report is None and world.time == started
    assert early.to_dict() == late.to_dict()


def test_the_world_builds_no_base_and_the_arms_serve_a_cup(no_base: KnowledgeBase, world: HomeWorld) -> None:
    """The one simulation run: RobotArmServeACup with no base, and what the world gives in its place."""
    assert world.mobile is None and world.base_names == ()
    assert "P3DX01" not in world.bodies and "P3DX01" not in world.snapshot()
    with pytest.raises(NoMobileBaseError, match="the mobile base's drive needs one"):
        world.base_pose()
    environment = SimEnvironment(world, no_base)
    assert SVC + "NavigateToPlace_P3DX01" not in environment.registry.names()
    assert environment.unimplemented(Composer(no_base).advertisements)[SVC + "DeliverObject_P3DX01"] == BASE_WORDS
    grid = decode(provide_grid_map(environment.context, {}, "HomeServer01")["map"], OccupancyGrid)
    assert grid.inflation_radius == 0.0 and grid.is_occupied(7.75, 3.75)  # the map server's: no base to inflate for
    environment.context.grid = None
    result = run_task(no_base, "RobotArmServeACup", environment, composer=Composer(no_base))
    assert result.succeeded, result.report
    observed = environment.observe()
    assert not any("P3DX01" in iri for iri in observed.positions)


def test_the_home_page_says_what_a_home_with_no_base_allows(no_base: KnowledgeBase) -> None:
    from cbrs.sparql_service import SparqlService
    from cbrs.web import create_app

    client = create_app(SparqlService(no_base)).test_client()
    assert client.get("/home.json").get_json()["mobile_robots"] == NO_BASE
    page = client.get("/home").get_data(as_text=True)
    assert "Mobile robots" in page and str(escape(NO_BASE)) in page
