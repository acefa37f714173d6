"""Path planning on the inflated occupancy grid with networkx's A* and Dijkstra.

The graph has one node per free cell and 8-connected edges weighted by their length in metres;
a diagonal step is only allowed when both cells beside it are free, so paths never cut a corner of
an obstacle. A* uses the straight-line distance, which never overestimates, so both searches return
paths of the same (shortest) length. A start or goal inside an obstacle is moved to the nearest free
cell first. The cell path is then shortened to the corners that are needed (line of sight on the
inflated grid), which is what the base drives along.
"""

from __future__ import annotations

import itertools
import math
import weakref
from dataclasses import dataclass
from typing import Literal

import networkx as nx
import numpy as np

from cbrs.sim.errors import NoFreeCellError, NoPathError, UnknownAlgorithmError
from cbrs.sim.mapping import OccupancyGrid

__all__ = ["ALGORITHMS", "SNAP_RADIUS", "PlannedPath", "approach_point", "plan_path", "snap_to_free"]

Algorithm = Literal["astar", "dijkstra"]
ALGORITHMS: tuple[str, ...] = ("astar", "dijkstra")
SNAP_RADIUS = 1.0
"""A start or goal may be moved at most this far (m) to reach a free cell."""

Cell = tuple[int, int]

_graphs: weakref.WeakKeyDictionary[OccupancyGrid, nx.Graph[Cell]] = weakref.WeakKeyDictionary()


@dataclass(frozen=True)
class PlannedPath:
    """A path on the grid (the ontology's Path): the waypoints to drive through and its length."""

    algorithm: str
    start: tuple[float, float]
    goal: tuple[float, float]
    """Start and goal after snapping to free cells (cell centres)."""
    waypoints: tuple[tuple[float, float], ...]
    """World (x, y) corners from the start to the goal, both included."""
    length: float
    """Length of the optimal cell path (m), the quantity both searches minimise."""
    cells: int
    """Number of cells on the cell path."""


def _graph(grid: OccupancyGrid) -> nx.Graph[Cell]:
    cached = _graphs.get(grid)
    if cached is not None:
        return cached
    free = grid.free
    graph: nx.Graph[Cell] = nx.Graph()
    graph.add_nodes_from((int(i), int(j)) for i, j in np.argwhere(free))
    r = grid.resolution
    diagonal = r * math.sqrt(2.0)
    # Right and up neighbours, then the two diagonals with both side cells free.
    right = free[:, :-1] & free[:, 1:]
    up = free[:-1, :] & free[1:, :]
    up_right = free[:-1, :-1] & free[1:, 1:] & free[1:, :-1] & free[:-1, 1:]
    up_left = free[:-1, 1:] & free[1:, :-1] & free[1:, 1:] & free[:-1, :-1]
    edges: list[tuple[Cell, Cell, float]] = []
    edges += [((int(i), int(j)), (int(i), int(j) + 1), r) for i, j in np.argwhere(right)]
    edges += [((int(i), int(j)), (int(i) + 1, int(j)), r) for i, j in np.argwhere(up)]
    edges += [((int(i), int(j)), (int(i) + 1, int(j) + 1), diagonal) for i, j in np.argwhere(up_right)]
    edges += [((int(i), int(j) + 1), (int(i) + 1, int(j)), diagonal) for i, j in np.argwhere(up_left)]
    graph.add_weighted_edges_from(edges)
    _graphs[grid] = graph
    return graph


def snap_to_free(grid: OccupancyGrid, x: float, y: float, radius: float = SNAP_RADIUS) -> tuple[int, int]:
    """The free cell nearest to (x, y): the point's own cell if it is free."""
    row, col = grid.world_to_cell(x, y)
    free = grid.free
    if free[row, col]:
        return (row, col)
    candidates = np.argwhere(free)
    if candidates.size == 0:
        raise NoFreeCellError(x, y, radius)
    centres = grid.origin + (candidates[:, ::-1] + 0.5) * grid.resolution
    distances = np.hypot(centres[:, 0] - x, centres[:, 1] - y)
    best = int(np.argmin(distances))
    if distances[best] > radius:
        raise NoFreeCellError(x, y, radius)
    return (int(candidates[best, 0]), int(candidates[best, 1]))


def _visible(grid: OccupancyGrid, a: tuple[float, float], b: tuple[float, float]) -> bool:
    """Whether the straight segment a-b stays on free cells (sampled every quarter cell)."""
    samples = max(2, math.ceil(math.dist(a, b) / (grid.resolution / 4.0)) + 1)
    xs = np.linspace(a[0], b[0], samples)
    ys = np.linspace(a[1], b[1], samples)
    cols = np.floor((xs - grid.origin[0]) / grid.resolution).astype(np.intp)
    rows = np.floor((ys - grid.origin[1]) / grid.resolution).astype(np.intp)
    return not bool(grid.inflated[rows, cols].any())


def _shortcut(grid: OccupancyGrid, points: list[tuple[float, float]]) -> list[tuple[float, float]]:
    """Keep only the corners needed: from each kept point, jump to the farthest point in sight."""
    kept = [points[0]]
    index = 0
    while index < len(points) - 1:
        nxt = len(points) - 1
        while nxt > index + 1 and not _visible(grid, points[index], points[nxt]):
            nxt -= 1
        kept.append(points[nxt])
        index = nxt
    return kept


def plan_path(
    grid: OccupancyGrid, start: tuple[float, float], goal: tuple[float, float], algorithm: Algorithm | str = "astar"
) -> PlannedPath:
    """Shortest collision-free path for the base's centre from ``start`` to ``goal`` (world x, y).

    ``NoFreeCellError`` if either end is farther than ``SNAP_RADIUS`` from free space,
    ``NoPathError`` if they are not connected (for instance a goal in a closed room).
    """
    if algorithm not in ALGORITHMS:
        raise UnknownAlgorithmError(algorithm, ALGORITHMS)
    source = snap_to_free(grid, *start)
    target = snap_to_free(grid, *goal)
    graph = _graph(grid)
    r = grid.resolution

    def heuristic(a: Cell, b: Cell) -> float:
        return r * math.hypot(a[0] - b[0], a[1] - b[1])

    try:
        if algorithm == "astar":
            cells: list[Cell] = nx.astar_path(graph, source, target, heuristic=heuristic, weight="weight")
        else:
            cells = nx.dijkstra_path(graph, source, target, weight="weight")
    except nx.NetworkXNoPath:
        raise NoPathError(start, goal, algorithm) from None
    length = float(sum(graph.edges[a, b]["weight"] for a, b in itertools.pairwise(cells)))
    points = [grid.cell_to_world(i, j) for i, j in cells]
    waypoints = _shortcut(grid, points) if len(points) > 1 else points
    return PlannedPath(
        algorithm, grid.cell_to_world(*source), grid.cell_to_world(*target), tuple(waypoints), length, len(cells)
    )


def approach_point(target: tuple[float, float], origin: tuple[float, float], distance: float) -> tuple[float, float]:
    """The point ``distance`` short of ``target`` on the line from ``origin``: where to stop next to a person."""
    dx, dy = target[0] - origin[0], target[1] - origin[1]
    norm = math.hypot(dx, dy)
    if norm <= distance:
        return origin
    return (target[0] - dx / norm * distance, target[1] - dy / norm * distance)
