"""Two bases whose plans cost alike and match alike (docs/simulation.md, "A home with no mobile base"): the
base with the least to drive to where its plan first goes is taken, measured in the map round what stands
in the way (kb.floor_routes; tests/test_base_routes.py checks the routes against the simulation's), then the
first by IRI; ``cbrs plan`` and the plans page choose as a run does, from the store alone; a task no robot requests
designates the chosen base's marker colours. One simulation run: FetchMyPenAnyBase with P3DX02 by the door."""

from __future__ import annotations

import json
import math
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from types import SimpleNamespace
from typing import cast

import pytest
from click.testing import CliRunner

from cbrs.actions.base_choice import (
    BaseChoice,
    BaseTies,
    FirstDrive,
    MapDrives,
    base_groups,
    choose_base,
    choose_in_map,
    map_bases,
    on_behalf,
)
from cbrs.actions.composer import Composer, CompositionResult
from cbrs.actions.runner import run_task
from cbrs.app import App
from cbrs.cli_actions import _base_note, plan
from cbrs.kb import KnowledgeBase, Requirement
from cbrs.kb.floor_routes import Routes
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.semantic_map import AmbiguousDesignatorError, Pose, SemanticMap, designate
from cbrs.sparql_service import SparqlService
from cbrs.web import create_app
from tests.helpers_examples import EXAMPLES

SVC, HOME, WORLD = PREFIXES["svc"], PREFIXES["home"], PREFIXES["world"]
P1, P2 = SVC + "P3DX01", SVC + "P3DX02"
TASK = "https://example.org/lab6#FetchMyPenAnyBase"
BEHIND_WALL = Path(__file__).parent / "data" / "base_behind_wall.ru"  # P3DX02 in the bedroom, by the wall


def _home(*updates: str | Path) -> KnowledgeBase:
    """Two Pioneers with their own components (the same QoS) and FetchMyPenAnyBase, asked by no robot."""
    kb = KnowledgeBase.open(":memory:")
    for name in ("lab6_two_bases.ru", *updates):
        kb.update((EXAMPLES / name).read_text(encoding="utf-8"))
    kb.registry.register((EXAMPLES / "lab6_second_base_components.ttl").read_text(encoding="utf-8"))
    kb.load([EXAMPLES / "lab6b_fetch_any_base.ttl"], graph="requirements")
    return kb


@pytest.fixture(scope="module")
def by_the_door() -> KnowledgeBase:
    """P3DX02 moved from the bedroom to the kitchen door: nearer the pen than P3DX01, and second by IRI."""
    return _home("lab6_second_base_near_table.ru")


@pytest.fixture(scope="module")
def plans(by_the_door: KnowledgeBase) -> dict[str, CompositionResult]:
    """The task composed over every component, and with each base's own alone."""
    composer = Composer(by_the_door)
    groups = base_groups(by_the_door, map_bases(by_the_door))
    every = frozenset().union(*groups.values())
    found = {"every": composer.compose(TASK)}
    for base, own in groups.items():
        kept = [ad for ad in composer.advertisements if ad.iri not in every - own]
        found[base] = Composer(by_the_door, advertisements=kept).compose(TASK)
    return found


def _stub(components: tuple[str, ...]) -> CompositionResult:
    steps = tuple(SimpleNamespace(candidates=(c,)) for c in components)
    found = SimpleNamespace(plan=SimpleNamespace(steps=steps, cost=86.75, similarity=0.9), attempts=())
    return cast(CompositionResult, found)


GROUPS = {P1: frozenset({"nav1"}), P2: frozenset({"nav2"})}
ONE, TWO = _stub(("nav1",)), _stub(("nav2",))


def _compose(avoid: frozenset[str]) -> CompositionResult:
    return ONE if "nav2" in avoid else TWO


def _drives(
    metres: dict[str, float | None], straight: dict[str, float] | None = None, measure: str = "route"
) -> Callable[[str, CompositionResult], FirstDrive | None]:
    """Each base's first drive: ``metres`` its route (None: no route; a base missing: nothing the map places),
    ``straight`` its straight line (the route's, by default)."""

    def drive(base: str, found: CompositionResult) -> FirstDrive | None:
        assert found is (ONE if base == P1 else TWO)  # each base's own plan is measured
        if base not in metres:
            return None
        away, line = metres[base], (straight or {}).get(base, metres[base] or 1.0)
        why = "" if away is not None else "nothing connects where it stands (5.40, 5.60) to (8.50, 2.20)"
        why = "the map has no rooms to lay a grid over" if measure == "line" else why
        return FirstDrive(5, f"nav{base[-1]}", (WORLD + "Pen",), away, line, measure, why)

    return drive


def test_plans_alike_go_to_the_base_with_the_least_to_drive() -> None:
    mixed = _stub(("nav1", "nav2"))
    found, chosen = choose_base(_compose, mixed, GROUPS, drive=_drives({P1: 5.38, P2: 3.3}))
    assert found is TWO and chosen is not None and (chosen.base, chosen.rule) == (P2, "nearest")
    assert "the least to drive: 3.30 m" in chosen.why and "to Pen" in chosen.why and "P3DX01's 5.38 m" in chosen.why
    assert [base for base, _ in chosen.drives] == [P1, P2] and chosen.to_dict()["drives"][1]["drive"]["metres"] == 3.3
    # as far, or a plan that drives to nothing the map places: the first by IRI, said so
    _, chosen = choose_base(_compose, mixed, GROUPS, drive=_drives({P1: 4.0, P2: 4.0}))
    assert chosen is not None and (chosen.base, chosen.rule) == (P1, "iri") and "as far" in chosen.why
    _, chosen = choose_base(_compose, mixed, GROUPS, drive=_drives({P1: 5.38}))
    assert chosen is not None and chosen.base == P1 and "P3DX02's plan drives to nothing the map places" in chosen.why
    # --base-ties iri: the distance is not asked
    _, chosen = choose_base(_compose, mixed, GROUPS, drive=_drives({}), ties=BaseTies.IRI)
    assert chosen is not None and (chosen.base, chosen.rule) == (P1, "iri") and chosen.drives == ()


def test_the_route_decides_not_the_straight_line() -> None:
    """Nearer in a straight line, farther round the walls: the route decides, and the why says both; a base
    that cannot get there at all is not taken, and with none that can, the first by IRI, said why."""
    mixed = _stub(("nav1", "nav2"))
    drives = _drives({P1: 5.63, P2: 10.12}, straight={P1: 5.54, P2: 4.60})
    found, chosen = choose_base(_compose, mixed, GROUPS, drive=drives)
    assert found is ONE and chosen is not None and (chosen.base, chosen.rule) == (P1, "nearest")
    assert (
        "5.63 m from where it stands in the map to Pen, round what stands in the way (5.54 m in a straight line)"
        in (chosen.why)
    )
    assert "P3DX02's 10.12 m (4.60 m)" in chosen.why
    said = chosen.to_dict()["drives"][1]["drive"]
    assert (said["metres"], said["straight"], said["measure"]) == (10.12, 4.6, "route") and "why" not in said
    # P3DX02 cannot get there: P3DX01 alone can, however far
    _, chosen = choose_base(_compose, mixed, GROUPS, drive=_drives({P1: 20.0, P2: None}, straight={P2: 1.0}))
    assert chosen is not None and (chosen.base, chosen.rule) == (P1, "nearest")
    assert "it alone can get to Pen" in chosen.why and "P3DX02 cannot get there (nothing connects" in chosen.why
    assert chosen.to_dict()["drives"][1]["drive"]["metres"] is None
    _, chosen = choose_base(_compose, mixed, GROUPS, drive=_drives({P1: None, P2: None}))
    assert chosen is not None and (chosen.base, chosen.rule) == (P1, "iri") and "no base can get to" in chosen.why
    # no grid to route on: the straight lines, said so
    by_line = _drives({P1: 5.54, P2: 4.60}, measure="line")
    _, chosen = choose_base(_compose, mixed, GROUPS, drive=by_line)
    assert chosen is not None and (chosen.base, chosen.rule) == (P2, "nearest")
    assert "4.60 m from where it stands in the map to Pen, in a straight line (the map gives no way" in chosen.why


def test_the_first_drive_is_measured_in_the_map(
    by_the_door: KnowledgeBase, plans: dict[str, CompositionResult]
) -> None:
    """Where FetchMyPen's navigation parks, the docking pose of the pen's table, by the route the map leaves."""
    groups = base_groups(by_the_door, map_bases(by_the_door))
    drives = MapDrives(by_the_door, groups)
    dock = drives.map.things[WORLD + "KitchenTable"].dock
    assert dock is not None
    for base in (P1, P2):
        drive = drives(base, plans[base])
        assert drive is not None and drive.towards == (WORLD + "Pen",) and drive.measure == "route"
        assert drive.component.endswith("NavigateToPlace_" + base[-6:])  # the base's own navigation
        robot = drives.map.robots[base].start
        assert drive.straight == pytest.approx(math.hypot(dock.x - robot.x, dock.y - robot.y))
        assert drive.metres == Routes(drives.map).route(base, (dock.x, dock.y)).metres
    assert plans[P1].plan is not None and plans[P2].plan is not None
    assert (plans[P1].plan.cost, plans[P1].plan.similarity) == (plans[P2].plan.cost, plans[P2].plan.similarity)
    found, chosen = choose_base(lambda avoid: plans[_kept(avoid)], plans["every"], groups, drive=drives)
    assert chosen is not None and (chosen.base, chosen.rule) == (P2, "nearest") and found is plans[P2]
    # where lab6_two_bases.ru parks it, in the bedroom, P3DX02 is the farther
    moved = replace(drives.map.robots[P2], start=Pose(2.0, 7.0))
    bedroom = MapDrives(by_the_door, groups, replace(drives.map, robots={**drives.map.robots, P2: moved}))
    _, chosen = choose_base(lambda avoid: plans[_kept(avoid)], plans["every"], groups, drive=bedroom)
    assert chosen is not None and (chosen.base, chosen.rule) == (P1, "nearest")


def test_behind_the_wall_cbrs_plan_takes_the_base_with_the_shorter_route() -> None:
    """P3DX02 parked behind the kitchen's wall (tests/data/base_behind_wall.ru) is the nearer in a straight
    line; ``cbrs plan`` takes P3DX01, from the store alone, whose drive is the shorter round the walls (as
    the simulation's planner finds: tests/test_base_routes.py)."""
    kb = _home(BEHIND_WALL)
    try:
        said = CliRunner().invoke(plan, [TASK, "--no-store", "--json"], obj=App(":memory:", kb))
    finally:
        kb.close()
    assert said.exit_code == 0, said.output
    chosen = json.loads(said.output)["base"]
    assert (chosen["base"], chosen["rule"]) == (P1, "nearest") and "round what stands in the way" in chosen["why"]
    drives = {each["base"]: each["drive"] for each in chosen["drives"]}
    assert drives[P2]["straight"] < drives[P1]["straight"] and drives[P1]["metres"] < drives[P2]["metres"]
    assert drives[P1]["measure"] == drives[P2]["measure"] == "route"


def _kept(avoid: frozenset[str]) -> str:
    """The base whose components a composition without ``avoid`` keeps."""
    return P1 if SVC + "NavigateToPlace_P3DX02" in avoid else P2


def test_cbrs_plan_says_the_base_and_why(by_the_door: KnowledgeBase) -> None:
    said = CliRunner().invoke(plan, [TASK, "--no-store", "--json"], obj=App(":memory:", by_the_door))
    assert said.exit_code == 0, said.output
    found = json.loads(said.output)
    assert (found["base"]["base"], found["base"]["rule"]) == (P2, "nearest")
    components = [step["component"] for step in found["steps"]]
    assert SVC + "NavigateToPlace_P3DX02" in components and not any(c.endswith("P3DX01") for c in components)
    note = _base_note(BaseChoice(P2, found["base"]["why"]))  # the text's note
    assert note == f"\nnote: the plan works svc:P3DX02, as cbrs run would choose it: {found['base']['why']}"


def test_the_plans_page_shows_the_base_chosen(by_the_door: KnowledgeBase) -> None:
    client = create_app(SparqlService(by_the_door)).test_client()
    twin = client.get("/plans.json", query_string={"task": TASK}).get_json()
    assert twin["base"]["base"] == P2 and twin["base"]["rule"] == "nearest"
    assert not any(step["component"].endswith("P3DX01") for step in twin["composition"]["steps"])
    page = client.get("/plans", query_string={"task": TASK}).get_data(as_text=True)
    assert "as a run would choose it: its plan and P3DX01&#39;s cost alike" in page


def test_a_home_of_one_base_plans_as_before() -> None:
    kb = KnowledgeBase.open(":memory:")
    composition = _stub(("nav1",))  # the store is asked for its bases only
    assert map_bases(kb) == {P1} and choose_in_map(Composer(kb), "FetchMyPen", composition) == (composition, None)
    assert _base_note(None) == ""


def test_no_requester_designates_the_chosen_bases_marker_colours(by_the_door: KnowledgeBase) -> None:
    colours = HOME + "ColourOfMarker"
    with pytest.raises(AmbiguousDesignatorError):  # two markers, no requester: which?
        designate(by_the_door, colours)
    requirement = cast(Requirement, by_the_door.description(TASK))
    assert requirement.requested_by is None
    chosen = BaseChoice(P2, "why")
    on = on_behalf({TASK: requirement}, chosen)[TASK]
    assert on.requested_by == P2 and on_behalf({TASK: requirement}, None)[TASK] is requirement
    assert designate(by_the_door, colours, prefer=on.requested_by) == WORLD + "P3DX02MarkerColours"


def test_a_run_drives_the_nearer_base_with_its_own_marker(by_the_door: KnowledgeBase) -> None:
    """The one simulation run: asked by no robot, with P3DX02 by the door, the run drives P3DX02 and
    locates it by its own marker (the other's colours would have the plan work two bases: refused)."""
    from cbrs.sim.components import SimEnvironment
    from cbrs.sim.world import open_world

    with open_world(seed=0, semantic_map=SemanticMap.read(by_the_door)) as world:
        result = run_task(by_the_door, TASK, SimEnvironment(world, by_the_door), composer=Composer(by_the_door))
    assert result.base is not None and (result.base.base, result.base.rule) == (P2, "nearest")
    assert result.succeeded, result.to_dict()
    assert result.report is not None
    used = {attempt.component for step in result.report.steps for attempt in step.attempts}
    assert SVC + "DeliverObject_P3DX02" in used and not any(c.endswith("P3DX01") for c in used)
