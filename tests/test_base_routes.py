"""kb.floor_routes: how far a base drives, round what stands, from the store's map alone; checked against the
simulation's map server (its ray-cast grid and its A*) in a home where the straight line misleads: P3DX02
parked in the bedroom behind the kitchen's wall (tests/data/base_behind_wall.ru)."""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
import pytest
from numpy.typing import NDArray

from cbrs.kb import KnowledgeBase
from cbrs.kb.floor_routes import Route, Routes, RouteSettings, base_radius
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.semantic_map import Box, MapError, SemanticMap, Thing
from tests.helpers_examples import EXAMPLES

SVC, HOME, WORLD = PREFIXES["svc"], PREFIXES["home"], PREFIXES["world"]
P1, P2 = SVC + "P3DX01", SVC + "P3DX02"
BEHIND_WALL = Path(__file__).parent / "data" / "base_behind_wall.ru"
DOCK = (8.5, 2.2)  # the kitchen table's docking pose: where a drive to fetch the pen goes


@pytest.fixture(scope="module")
def smap() -> SemanticMap:
    kb = KnowledgeBase.open(":memory:")
    kb.update((EXAMPLES / "lab6_two_bases.ru").read_text(encoding="utf-8"))
    kb.update(BEHIND_WALL.read_text(encoding="utf-8"))
    try:
        return SemanticMap.read(kb)
    finally:
        kb.close()


@dataclass(frozen=True)
class Served:
    """What the simulation's map server measures for one base driving: its grid and its path to the dock."""

    inflation: float
    occupied: NDArray[np.bool_]
    inflated: NDArray[np.bool_]
    metres: float  # its waypoints' length, with the straight gaps from the base's pose and to the dock


@pytest.fixture(scope="module")
def served(smap: SemanticMap) -> dict[str, Served]:
    """The built world, unmoved by the seed (the store's poses), measured for each base as a run's would be."""
    from cbrs.sim.mapping import build_occupancy_grid
    from cbrs.sim.planning import plan_path
    from cbrs.sim.world import Spread, open_world

    found = {}
    with open_world(seed=0, semantic_map=smap, spread=Spread(0.0, 0.0, 0.0, 0.0, 0.0)) as world:
        for base, robot in sorted(smap.robots.items()):
            world.drive(robot.name)
            grid = build_occupancy_grid(world, inflation_radius=world.grid_inflation, ignore=(robot.name,))
            start = (robot.start.x, robot.start.y)
            way = [start, *plan_path(grid, start, DOCK).waypoints, DOCK]
            metres = sum(math.dist(a, b) for a, b in itertools.pairwise(way))
            found[base] = Served(world.grid_inflation, grid.occupied, grid.inflated, metres)
    return found


def test_the_settings_are_the_map_servers() -> None:
    from cbrs.sim.layout import MAP_RESOLUTION, SHIRT_RADIUS
    from cbrs.sim.mapping import OBSTACLE_HEIGHT
    from cbrs.sim.planning import SNAP_RADIUS

    settings = RouteSettings()
    assert (settings.resolution, settings.obstacle_height) == (MAP_RESOLUTION, OBSTACLE_HEIGHT)
    assert (settings.person_radius, settings.snap) == (SHIRT_RADIUS, SNAP_RADIUS)


def test_the_grid_is_the_map_servers_but_for_the_arms(smap: SemanticMap, served: dict[str, Served]) -> None:
    """Rasterised from the store, each base's grid is the one the simulation measures by casting rays, the
    other base standing in it, except where the arms at rest reach past the torso: the store gives their
    mounts, not their posture."""
    routes = Routes(smap)
    mounts = [arm.mount[:2] for arm in smap.arms.values()]
    for base, measured in served.items():
        grid = routes.grid(base)
        assert grid.radius == pytest.approx(measured.inflation) == base_radius(smap.robots[base].footprint)
        differ = np.argwhere(grid.occupied != measured.occupied)
        assert len(differ) > 0  # the arms are there
        for row, col in differ:
            cell = (grid.origin[0] + (col + 0.5) * 0.05, grid.origin[1] + (row + 0.5) * 0.05)
            assert min(math.dist(cell, mount) for mount in mounts) < 0.4, cell
        assert (grid.occupied & ~measured.occupied).sum() == 0  # the store's obstacles are all measured


def test_the_route_is_the_simulated_drive_and_the_straight_line_is_not(
    smap: SemanticMap, served: dict[str, Served]
) -> None:
    """P3DX02 is the nearer in a straight line, through the kitchen's wall; round it, by the bedroom's door
    and the kitchen's, it has nearly twice P3DX01's drive, as the simulation's A* finds on its own grid."""
    routes = Routes(smap)
    found = {base: routes.route(base, DOCK) for base in (P1, P2)}
    for base, route in found.items():
        assert route.metres == pytest.approx(served[base].metres, rel=0.02), base
        assert route.metres >= route.straight
    assert found[P2].straight < found[P1].straight and found[P1].metres < found[P2].metres  # type: ignore[operator]
    assert found[P1].metres < 1.05 * found[P1].straight  # nothing much stands between P3DX01 and the kitchen
    by_the_door = [point for point in found[P2].waypoints if 4.7 <= point[1] <= 5.3]
    assert by_the_door and all(2.0 < x < 3.0 for x, _ in by_the_door)  # out through the bedroom's door


def test_in_the_open_the_route_is_the_straight_line(smap: SemanticMap) -> None:
    route = Routes(smap).route(P1, (1.0, 1.0))  # the living room's south-west, nothing between
    assert route.straight <= route.metres <= route.straight + 2 * math.hypot(0.025, 0.025) + 1e-9  # to cells' centres
    assert len(route.waypoints) == 2


def _walled(smap: SemanticMap, iri: str, box: Box) -> SemanticMap:
    return replace(smap, things={**smap.things, iri: Thing(iri, (HOME + "Wall",), box)}, walls=smap.walls | {iri})


def test_no_route_is_said_with_why(smap: SemanticMap) -> None:
    """A closed door: the base cannot get there; a goal deep in an obstacle: no free cell near it; no rooms:
    no grid, said so (the caller then takes the straight line)."""
    door = _walled(smap, WORLD + "BedroomDoorClosed", Box(2.0, 3.0, 4.95, 5.05, 0.0, 1.0))
    shut = Routes(door).route(P2, DOCK)
    assert shut.metres is None and shut.grid and "nothing connects where it stands (5.40, 5.60)" in shut.why
    assert Routes(door).route(P1, DOCK).metres is not None  # the other base's way is open
    table = Routes(smap).route(P1, (7.75, 3.75))  # the middle of the kitchen table
    assert table.metres is None and "no cell within 1 m of where it goes (7.75, 3.75) is free" in table.why
    roomless = Routes(replace(smap, rooms=frozenset())).route(P1, DOCK)
    assert (roomless.metres, roomless.grid) == (None, False) and "no rooms" in roomless.why
    assert roomless.straight == pytest.approx(math.dist((3.0, 1.5), DOCK))
    with pytest.raises(MapError, match="is no mobile base of the map"):
        Routes(smap).route(WORLD + "KitchenTable", DOCK)


def test_a_route_is_the_same_asked_again(smap: SemanticMap) -> None:
    first = Routes(smap).route(P2, DOCK)
    again = Routes(replace(smap)).route(P2, DOCK)  # another reading of the same map: the same route
    assert isinstance(first, Route) and again == first
