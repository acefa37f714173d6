"""The occupancy grid measured in the home, and A* / Dijkstra on it."""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterator

import networkx as nx
import numpy as np
import pytest

from cbrs.sim import (
    HomeWorld,
    NoFreeCellError,
    NoPathError,
    OccupancyGrid,
    OutsideMapError,
    UnknownAlgorithmError,
    build_occupancy_grid,
    plan_path,
)
from cbrs.sim.layout import MAP_RESOLUTION
from cbrs.sim.mapping import inflate
from cbrs.sim.planning import _astar, _dijkstra, _Grid, _shortcut, approach_point, snap_to_free
from tests.home_layout import HANDOVER_POSE, TABLE, WALLS


@pytest.fixture(scope="module")
def world() -> Iterator[HomeWorld]:
    with HomeWorld.create(seed=2) as w:
        yield w


@pytest.fixture(scope="module")
def grid(world: HomeWorld) -> OccupancyGrid:
    return build_occupancy_grid(world)


def test_grid_covers_the_home(grid: OccupancyGrid) -> None:
    assert grid.shape == (180, 200)
    assert grid.resolution == MAP_RESOLUTION
    assert grid.world_to_cell(0.01, 0.01) == (0, 0)
    assert grid.world_to_cell(9.99, 8.99) == (179, 199)
    row, col = grid.world_to_cell(3.27, 1.52)
    x, y = grid.cell_to_world(row, col)
    assert abs(x - 3.27) <= MAP_RESOLUTION / 2 and abs(y - 1.52) <= MAP_RESOLUTION / 2
    with pytest.raises(OutsideMapError) as error:
        grid.world_to_cell(10.5, 2.0)
    assert (error.value.x, error.value.y) == (10.5, 2.0)


def test_walls_are_occupied_and_doors_open(grid: OccupancyGrid) -> None:
    assert len(WALLS) == 10
    for wall in WALLS:
        along_x = wall.xmax - wall.xmin > wall.ymax - wall.ymin
        for t in np.linspace(0.05, 0.95, 7):
            x = wall.xmin + t * (wall.xmax - wall.xmin) if along_x else (wall.xmin + wall.xmax) / 2
            y = (wall.ymin + wall.ymax) / 2 if along_x else wall.ymin + t * (wall.ymax - wall.ymin)
            x, y = min(max(x, 0.01), 9.99), min(max(y, 0.01), 8.99)
            assert grid.is_occupied(x, y), (wall.name, x, y)
    assert not grid.is_occupied(6.0, 2.1)  # living room - kitchen door
    assert not grid.is_occupied(2.5, 5.0)  # living room - bedroom door
    assert grid.is_free(6.0, 2.1)  # the 1 m door leaves room for the base's 0.6 m


def test_furniture_robot_and_person_are_occupied(world: HomeWorld, grid: OccupancyGrid) -> None:
    for x in np.linspace(TABLE.xmin + 0.05, TABLE.xmax - 0.05, 5):
        for y in np.linspace(TABLE.ymin + 0.05, TABLE.ymax - 0.05, 5):
            assert grid.is_occupied(float(x), float(y))
    assert grid.is_occupied(7.75, 2.55)  # the dual-arm robot's torso
    person = world.pose("Person").position
    assert grid.is_occupied(person[0], person[1])
    base = world.base_pose()
    assert not grid.is_occupied(base.x, base.y)  # the base does not map itself
    assert not grid.is_occupied(3.0, 3.0) and not grid.is_occupied(8.0, 1.0)


def test_inflation_keeps_the_base_radius_from_obstacles(grid: OccupancyGrid) -> None:
    west = TABLE.xmin  # the table's west edge, 1 m from the kitchen wall
    assert grid.is_occupied(west + 0.05, 3.75)
    assert not grid.is_occupied(west - grid.inflation_radius + 0.05, 3.75)
    assert not grid.is_free(west - grid.inflation_radius + 0.05, 3.75)  # within the base's radius of the table
    assert grid.is_free(west - grid.inflation_radius - 0.1, 3.75)
    assert not grid.is_free(3.0, 0.2)  # 0.2 m from the south wall
    single = np.zeros((11, 11), dtype=bool)
    single[5, 5] = True
    grown = inflate(single, 2.0)
    assert grown[5, 7] and grown[3, 5] and not grown[5, 8] and not grown[7, 7]


@pytest.mark.parametrize(
    ("start", "goal"),
    [((3.0, 1.5), HANDOVER_POSE.xy), ((1.0, 1.0), (4.0, 7.5)), ((9.0, 1.0), (1.0, 4.0))],
    ids=["to-handover", "to-bedroom", "across"],
)
def test_astar_and_dijkstra_find_equally_short_collision_free_paths(
    grid: OccupancyGrid, start: tuple[float, float], goal: tuple[float, float]
) -> None:
    astar = plan_path(grid, start, goal, "astar")
    dijkstra = plan_path(grid, start, goal, "dijkstra")
    assert astar.length == pytest.approx(dijkstra.length, rel=1e-9)
    assert astar.length >= math.dist(start, goal) - 2 * MAP_RESOLUTION
    for path in (astar, dijkstra):
        assert math.dist(path.waypoints[0], start) < MAP_RESOLUTION
        assert math.dist(path.waypoints[-1], goal) < MAP_RESOLUTION
        for a, b in zip(path.waypoints, path.waypoints[1:], strict=False):
            for t in np.linspace(0.0, 1.0, 50):
                assert grid.is_free(a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]))


def test_path_to_the_bedroom_goes_through_its_door(grid: OccupancyGrid) -> None:
    path = plan_path(grid, (1.0, 1.0), (4.0, 7.5))
    crossing = [
        (a, b) for a, b in zip(path.waypoints, path.waypoints[1:], strict=False) if (a[1] - 5.0) * (b[1] - 5.0) < 0
    ]
    assert len(crossing) == 1
    (a, b) = crossing[0]
    x_at_wall = a[0] + (5.0 - a[1]) / (b[1] - a[1]) * (b[0] - a[0])
    assert 2.0 < x_at_wall < 3.0


def test_a_goal_in_an_obstacle_is_snapped_to_the_nearest_free_cell(grid: OccupancyGrid) -> None:
    goal = (TABLE.xmin + 0.05, 3.75)  # on the table, by its west edge
    path = plan_path(grid, (3.0, 1.5), goal)
    assert grid.is_free(*path.goal)
    assert math.dist(path.goal, goal) < grid.inflation_radius + 0.05 + 2 * MAP_RESOLUTION
    assert path.goal[0] < TABLE.xmin - grid.inflation_radius
    row, col = snap_to_free(grid, 3.0, 3.0)
    assert grid.cell_to_world(row, col) == grid.cell_to_world(*grid.world_to_cell(3.0, 3.0))


def test_planning_fails_clearly(grid: OccupancyGrid) -> None:
    for algorithm in ("astar", "dijkstra"):
        with pytest.raises(NoPathError) as error:
            plan_path(grid, (3.0, 1.5), (8.0, 7.0), algorithm)  # the walled-off north-east corner
        assert error.value.goal == (8.0, 7.0) and error.value.algorithm == algorithm
    with pytest.raises(NoFreeCellError) as blocked:
        plan_path(grid, (7.75, 3.75), (3.0, 1.5))  # the middle of the table, > 1 m from free space
    assert (blocked.value.x, blocked.value.y) == (7.75, 3.75)
    with pytest.raises(UnknownAlgorithmError):
        plan_path(grid, (3.0, 1.5), (4.0, 1.5), "rrt")


def test_approach_point_stops_short_of_the_target() -> None:
    assert approach_point((4.0, 0.0), (0.0, 0.0), 1.0) == pytest.approx((3.0, 0.0))
    assert approach_point((0.5, 0.0), (0.0, 0.0), 1.0) == (0.0, 0.0)


Cell = tuple[int, int]


def _networkx_graph(grid: OccupancyGrid) -> nx.Graph[Cell]:
    """The graph the planner used to build from the grid (the reference its own searches must match):
    built once per grid, it is searched for every pair of cells and both algorithms."""
    free, r = grid.free, grid.resolution
    graph: nx.Graph[Cell] = nx.Graph()
    graph.add_nodes_from((int(i), int(j)) for i, j in np.argwhere(free))
    right = free[:, :-1] & free[:, 1:]
    up = free[:-1, :] & free[1:, :]
    block = free[:-1, :-1] & free[1:, 1:] & free[1:, :-1] & free[:-1, 1:]
    edges = [((int(i), int(j)), (int(i), int(j) + 1), r) for i, j in np.argwhere(right)]
    edges += [((int(i), int(j)), (int(i) + 1, int(j)), r) for i, j in np.argwhere(up)]
    edges += [((int(i), int(j)), (int(i) + 1, int(j) + 1), r * math.sqrt(2.0)) for i, j in np.argwhere(block)]
    edges += [((int(i), int(j) + 1), (int(i) + 1, int(j)), r * math.sqrt(2.0)) for i, j in np.argwhere(block)]
    graph.add_weighted_edges_from(edges)
    return graph


def _networkx_path(
    graph: nx.Graph[Cell], resolution: float, source: Cell, target: Cell, algorithm: str
) -> tuple[list[Cell], float] | None:
    """The cell path and length networkx's searches find on the grid's ``graph``."""
    try:
        if algorithm == "astar":
            cells = nx.astar_path(graph, source, target, lambda a, b: resolution * math.hypot(a[0] - b[0], a[1] - b[1]))
        else:
            cells = nx.dijkstra_path(graph, source, target)
    except nx.NetworkXNoPath:
        return None
    return cells, sum(graph.edges[a, b]["weight"] for a, b in itertools.pairwise(cells))


def _same_as_networkx(
    grid: OccupancyGrid, start: tuple[float, float], goal: tuple[float, float], graph: nx.Graph[Cell]
) -> None:
    source, target = snap_to_free(grid, *start), snap_to_free(grid, *goal)
    for algorithm, search in (("astar", _astar), ("dijkstra", _dijkstra)):
        expected = _networkx_path(graph, grid.resolution, source, target, algorithm)
        assert search(_Grid(grid), source, target) == (expected[0] if expected else None)
        if expected is None:
            with pytest.raises(NoPathError):
                plan_path(grid, start, goal, algorithm)
            continue
        cells, length = expected
        path = plan_path(grid, start, goal, algorithm)
        assert path.length == length and path.cells == len(cells)
        assert list(path.waypoints) == _shortcut(grid, [grid.cell_to_world(i, j) for i, j in cells])


@pytest.mark.parametrize("seed", range(24))
def test_the_searches_find_the_paths_networkx_finds(seed: int) -> None:
    """The very same cells, on random grids full of equally short paths (and none where there is none)."""
    rng = np.random.default_rng(seed)
    rows, cols = int(rng.integers(3, 40)), int(rng.integers(3, 40))
    blocked = rng.random((rows, cols)) < rng.uniform(0.0, 0.35)
    grid = OccupancyGrid(0.05, (0.0, 0.0), blocked, blocked, 0.0)
    free = np.argwhere(~blocked)
    graph = _networkx_graph(grid)
    for _ in range(6 if len(free) >= 2 else 0):
        a, b = rng.choice(len(free), 2)
        start = grid.cell_to_world(int(free[a][0]), int(free[a][1]))
        _same_as_networkx(grid, start, grid.cell_to_world(int(free[b][0]), int(free[b][1])), graph)


def test_the_searches_find_the_paths_networkx_finds_in_the_home(grid: OccupancyGrid) -> None:
    graph = _networkx_graph(grid)
    for start, goal in [((3.0, 1.5), HANDOVER_POSE.xy), ((3.0, 1.5), (2.5, 7.5)), ((8.5, 2.2), (1.0, 4.0))]:
        _same_as_networkx(grid, start, goal, graph)


def _every_ray(world: HomeWorld) -> np.ndarray:
    """The occupied cells with a ray cast down at every cell, seeing through the base (the reference)."""
    import pybullet as p

    home, r = world.extent, MAP_RESOLUTION
    cols, rows = round((home.xmax - home.xmin) / r), round((home.ymax - home.ymin) / r)
    jj, ii = np.meshgrid(np.arange(cols), np.arange(rows))
    xs, ys = home.xmin + (jj.ravel() + 0.5) * r, home.ymin + (ii.ravel() + 0.5) * r
    heights = np.full(xs.size, -1.0)
    base = world.body(world.base_name)
    for start in range(0, xs.size, 4096):
        top = np.full(xs[start : start + 4096].size, 3.0)
        for _ in range(3):
            hits = p.rayTestBatch(
                np.column_stack([xs[start : start + 4096], ys[start : start + 4096], top]).tolist(),
                np.column_stack([xs[start : start + 4096], ys[start : start + 4096], np.full(top.size, -0.5)]).tolist(),
                physicsClientId=world.client,
            )
            through = np.array([hit[0] == base for hit in hits])
            zs = np.array([hit[3][2] for hit in hits])
            done = ~through & np.array([hit[0] >= 0 for hit in hits])
            heights[start : start + 4096][done] = zs[done]
            top = np.where(through, zs - 1e-3, top)
    occupied: np.ndarray = (heights > 0.03).reshape(rows, cols)
    return occupied


def test_only_rays_that_may_meet_something_are_cast_and_the_grid_is_the_same(
    world: HomeWorld, grid: OccupancyGrid
) -> None:
    """Rays outside every body's bounding box would meet the bare floor: not casting them changes no cell
    (the module's home as built, then another seed's with the base moved under the arms)."""
    from cbrs.sim.geometry import Pose2D

    assert np.array_equal(grid.occupied, _every_ray(world))
    with HomeWorld.create(seed=3) as moved:
        moved.base.place(Pose2D(8.3, 2.2, 0.3))  # under the arms, by the table
        assert np.array_equal(build_occupancy_grid(moved).occupied, _every_ray(moved))
