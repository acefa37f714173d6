"""Path planning on the inflated occupancy grid with A* and Dijkstra.

The graph has one node per free cell and 8-connected edges weighted by their length in metres;
a diagonal step is only allowed when both cells beside it are free, so paths never cut a corner of
an obstacle. A* uses the straight-line distance, which never overestimates, so both searches return
paths of the same (shortest) length. A start or goal inside an obstacle is moved to the nearest free
cell first. The cell path is then shortened to the corners that are needed (line of sight on the
inflated grid), which is what the base drives along.

The searches walk the grid itself rather than a graph built from it: building networkx's graph of a
home's 20,000 free cells took longer than the search (0.3-0.45 s per grid, and every decoded grid
is a new one). They are networkx's ``astar_path`` and ``dijkstra_path`` step for step, with each
cell's neighbours in the order networkx's graph held them, so they return the very same paths
(tests/test_sim_mapping.py compares them on random grids).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass
from heapq import heappop, heappush
from typing import Literal

import numpy as np

from cbrs.sim.errors import NoFreeCellError, NoPathError, UnknownAlgorithmError
from cbrs.sim.mapping import OccupancyGrid

__all__ = ["ALGORITHMS", "SNAP_RADIUS", "PlannedPath", "approach_point", "first_obstacle", "plan_path", "snap_to_free"]

Algorithm = Literal["astar", "dijkstra"]
ALGORITHMS: tuple[str, ...] = ("astar", "dijkstra")
SNAP_RADIUS = 1.0
"""A start or goal may be moved at most this far (m) to reach a free cell."""

Cell = tuple[int, int]


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


class _Grid:
    """The 8-connected graph of a grid's free cells, read off the grid as the search goes."""

    def __init__(self, grid: OccupancyGrid) -> None:
        rows, cols = grid.shape
        padded = np.zeros((rows + 2, cols + 2), dtype=bool)  # a border of obstacles: no bounds checks
        padded[1:-1, 1:-1] = grid.free
        self.free: list[list[bool]] = padded.tolist()
        self.straight = grid.resolution
        self.diagonal = grid.resolution * math.sqrt(2.0)

    def neighbours(self, cell: Cell) -> list[tuple[Cell, float]]:
        """The cells one step from ``cell`` with the step's length, in the order networkx's graph of
        the grid listed them (its edges were added right, up, up-right, up-left, each row by row)."""
        i, j = cell
        f = self.free
        below, here, above = f[i], f[i + 1], f[i + 2]  # rows i - 1, i, i + 1 (padded by one)
        c = j + 1
        found: list[tuple[Cell, float]] = []
        if not here[c]:
            return found
        r, d = self.straight, self.diagonal
        if here[c - 1]:
            found.append(((i, j - 1), r))
        if here[c + 1]:
            found.append(((i, j + 1), r))
        if below[c]:
            found.append(((i - 1, j), r))
        if above[c]:
            found.append(((i + 1, j), r))
        if below[c - 1] and below[c] and here[c - 1]:
            found.append(((i - 1, j - 1), d))
        if above[c + 1] and above[c] and here[c + 1]:
            found.append(((i + 1, j + 1), d))
        if below[c + 1] and below[c] and here[c + 1]:
            found.append(((i - 1, j + 1), d))
        if above[c - 1] and above[c] and here[c - 1]:
            found.append(((i + 1, j - 1), d))
        return found


def _astar(graph: _Grid, source: Cell, target: Cell) -> list[Cell] | None:
    """networkx's astar_path with the straight-line heuristic; None when the target is not reached."""
    r = graph.straight
    counter = itertools.count()
    queue: list[tuple[float, int, Cell, float, Cell | None]] = [(0, next(counter), source, 0, None)]
    enqueued: dict[Cell, tuple[float, float]] = {}
    explored: dict[Cell, Cell | None] = {}
    while queue:
        _, _, node, dist, parent = heappop(queue)
        if node == target:
            path = [node]
            back = parent
            while back is not None:
                path.append(back)
                back = explored[back]
            path.reverse()
            return path
        if node in explored:
            if explored[node] is None:
                continue
            if enqueued[node][0] < dist:
                continue
        explored[node] = parent
        for neighbour, cost in graph.neighbours(node):
            ncost = dist + cost
            if neighbour in enqueued:
                qcost, h = enqueued[neighbour]
                if qcost <= ncost:
                    continue
            else:
                h = r * math.hypot(neighbour[0] - target[0], neighbour[1] - target[1])
            enqueued[neighbour] = ncost, h
            heappush(queue, (ncost + h, next(counter), neighbour, ncost, node))
    return None


def _dijkstra(graph: _Grid, source: Cell, target: Cell) -> list[Cell] | None:
    """networkx's dijkstra_path (a node's predecessor is the one that last shortened it); None when
    the target is not reached."""
    counter = itertools.count()
    fringe: list[tuple[float, int, Cell]] = [(0, next(counter), source)]
    dist: dict[Cell, float] = {}
    seen: dict[Cell, float] = {source: 0}
    previous: dict[Cell, Cell] = {}
    while fringe:
        dist_v, _, v = heappop(fringe)
        if v in dist:
            continue
        dist[v] = dist_v
        if v == target:
            break
        for u, cost in graph.neighbours(v):
            vu_dist = dist_v + cost
            if u in dist:
                continue
            if u not in seen or vu_dist < seen[u]:
                seen[u] = vu_dist
                heappush(fringe, (vu_dist, next(counter), u))
                previous[u] = v
    if target not in dist:
        return None
    path = [target]
    while path[-1] in previous:
        path.append(previous[path[-1]])
    path.reverse()
    return path


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


def first_obstacle(grid: OccupancyGrid, waypoints: Sequence[tuple[float, float]]) -> tuple[float, float] | None:
    """The first point of the legs between ``waypoints`` on an obstacle the grid measured (not inflated), or
    off the grid; None when the base's centre can follow them. A path from a planner in another process is
    checked so before the base drives it: one that ignores the map (a straight line through a wall or the
    arms' torso) drove the base into the torso, where no ceiling camera could see its marker again."""
    rows, cols = grid.shape
    for a, b in itertools.pairwise(waypoints):
        samples = max(2, math.ceil(math.dist(a, b) / (grid.resolution / 4.0)) + 1)
        xs, ys = np.linspace(a[0], b[0], samples), np.linspace(a[1], b[1], samples)
        cols_at = np.floor((xs - grid.origin[0]) / grid.resolution).astype(np.intp)
        rows_at = np.floor((ys - grid.origin[1]) / grid.resolution).astype(np.intp)
        inside = (rows_at >= 0) & (rows_at < rows) & (cols_at >= 0) & (cols_at < cols)
        hit = ~inside
        hit[inside] = grid.occupied[rows_at[inside], cols_at[inside]]
        if hit.any():
            first = int(np.argmax(hit))
            return (float(xs[first]), float(ys[first]))
    return None


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
    graph = _Grid(grid)
    cells = (_astar if algorithm == "astar" else _dijkstra)(graph, source, target)
    if cells is None:
        raise NoPathError(start, goal, algorithm)
    steps = (graph.straight if a[0] == b[0] or a[1] == b[1] else graph.diagonal for a, b in itertools.pairwise(cells))
    length = float(sum(steps))
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
