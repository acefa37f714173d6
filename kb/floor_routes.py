"""How far a mobile base drives to a point of the home, from the store alone: round what stands in its way.

The simulation's map server measures its occupancy grid by casting rays in the built world
(``sim/mapping.py``); ``cbrs plan``, the plans page and the task editor build no world, and a run must
choose as they do (``actions/base_choice.py``). So the same grid is rasterised here from the semantic
map's geometry, by the simulation's rules: one cell every ``resolution`` metres over the rooms' extent,
occupied where its centre lies under something taller than ``obstacle_height`` (walls, furniture, the
dispensers, the robots' torsos, objects, each person as a disc of ``person_radius``, the camera housings a
loaded base would meet, and every *other* mobile base at its pose in the map), the obstacles grown by the
driving base's footprint radius plus half a cell. The search is the simulation's: 8-connected, no corner
cut, a start or goal in an obstacle moved to the nearest free cell within ``snap`` metres; the cell path is
then cut to the corners the base needs (line of sight), which is what the base drives.

A route's length is that drive plus the straight gaps from the base's pose to the first free cell and from
the last one to the point (the pen on the table the base stops short of): never shorter than the straight
line, and equal to it, within a cell, where nothing stands between. What the store does not give a
geometry (the arms' posture, a person's size, a thing with no extent) is no obstacle here; a home with no
rooms, or a point off their extent, has no grid: :meth:`Routes.route` then says why and gives no length,
and the caller falls back to the straight line (docs/simulation.md, "A home with no mobile base").
Grids and routes are kept per map geometry (a few of each), so a page asked twice searches once.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterable
from dataclasses import dataclass, field
from functools import lru_cache
from heapq import heappop, heappush

import numpy as np
from numpy.typing import NDArray

from cbrs.kb.semantic_map import MapError, MobileRobot, SemanticMap, local_name

__all__ = ["FloorGrid", "Route", "RouteSettings", "Routes", "base_radius", "inflate"]

Point = tuple[float, float]
Cell = tuple[int, int]
Bounds = tuple[float, float, float, float]  # the rooms' extent: min x, max x, min y, max y


@dataclass(frozen=True)
class RouteSettings:
    """The grid's model: the simulation's map server's, by default (tests/test_base_routes.py checks each
    against ``sim.layout``, ``sim.mapping`` and ``sim.planning``)."""

    resolution: float = 0.05  # m per cell: sim.layout.MAP_RESOLUTION
    obstacle_height: float = 0.03  # m: anything taller blocks a base (sim.mapping.OBSTACLE_HEIGHT)
    person_radius: float = 0.22  # m: the mannequin's widest part, its shirt (sim.layout.SHIRT_RADIUS)
    snap: float = 1.0  # m: how far a start or goal in an obstacle may move to a free cell (sim.planning.SNAP_RADIUS)
    radius_step: float = 0.05  # m: a base's footprint radius is rounded up to this (sim.world's base_radius)


@dataclass(frozen=True)
class _Footprint:
    """Something standing on the floor, seen from above: a rectangle about (x, y) turned by yaw, or a disc."""

    x: float
    y: float
    half: Point  # half length and half width; a disc: (radius, radius)
    yaw: float = 0.0
    disc: bool = False
    name: str = ""


@dataclass(frozen=True, eq=False)
class FloorGrid:
    """The occupancy grid one base drives on: row i is y, column j is x, cell (0, 0) starts at ``origin``."""

    resolution: float
    origin: Point
    occupied: NDArray[np.bool_] = field(repr=False)
    inflated: NDArray[np.bool_] = field(repr=False)
    """Cells the base's centre must avoid: obstacles grown by ``radius`` plus half a cell."""
    radius: float

    def cell(self, point: Point) -> Cell | None:
        """The (row, column) containing ``point``; None off the grid."""
        col = math.floor((point[0] - self.origin[0]) / self.resolution)
        row = math.floor((point[1] - self.origin[1]) / self.resolution)
        rows, cols = self.occupied.shape
        return (row, col) if 0 <= row < rows and 0 <= col < cols else None

    def centre(self, cell: Cell) -> Point:
        return (self.origin[0] + (cell[1] + 0.5) * self.resolution, self.origin[1] + (cell[0] + 0.5) * self.resolution)


@dataclass(frozen=True)
class Route:
    """A base's drive to a point. ``metres`` is None when there is none, ``why`` then saying so (no free
    cell near the point, not connected to where the base stands, or no grid to route on)."""

    base: str
    start: Point
    goal: Point
    straight: float
    metres: float | None
    waypoints: tuple[Point, ...] = ()
    """From the free cell where the base sets off, through the corners it needs, to where it stops."""
    why: str = ""
    grid: bool = True
    """False: the store gave nothing to route on (``why`` says what); True: the grid answered, yes or no."""


def base_radius(footprint: Point, step: float = RouteSettings.radius_step) -> float:
    """A footprint's circumscribed radius, rounded up to ``step``: how far obstacles are grown for it."""
    return math.ceil(math.hypot(footprint[0] / 2, footprint[1] / 2) / step - 1e-9) * step


class Routes:
    """Routes in one semantic map, for each of its mobile bases: each base's grid is rasterised on first use."""

    def __init__(self, smap: SemanticMap, settings: RouteSettings | None = None) -> None:
        self.map, self.settings = smap, settings or RouteSettings()

    def route(self, base: str, goal: Point) -> Route:
        """The way ``base`` (an IRI of the map's mobile bases) drives from its pose in the map to ``goal``."""
        robot = self._robot(base)
        start = (robot.start.x, robot.start.y)
        straight = math.dist(start, goal)
        try:
            extent = self.map.extent()
        except MapError:
            return Route(base, start, goal, straight, None, why="the map has no rooms to lay a grid over", grid=False)
        for what, point in (("it stands", start), ("it goes", goal)):
            if not extent.contains_xy(*point):
                why = f"where {what}, ({point[0]:.2f}, {point[1]:.2f}), is off the rooms' extent"
                return Route(base, start, goal, straight, None, why=why, grid=False)
        found = _search(*self._model(base), start, goal)
        if isinstance(found, str):
            return Route(base, start, goal, straight, None, why=found)
        waypoints, metres = found
        return Route(base, start, goal, straight, metres, waypoints)

    def grid(self, base: str) -> FloorGrid:
        """The grid ``base`` drives on: every obstacle but itself, grown by its radius (a map with no rooms:
        the :class:`MapError` that says so)."""
        return _grid(*self._model(base))

    def _robot(self, base: str) -> MobileRobot:
        robot = self.map.robots.get(base)
        if robot is None:
            raise MapError(base, f"is no mobile base of the map (its bases: {', '.join(sorted(self.map.robots))})")
        return robot

    def _model(self, base: str) -> tuple[tuple[_Footprint, ...], Bounds, float, RouteSettings]:
        """What ``base``'s grid is made of, hashable: the obstacles, the rooms' extent, its radius, the settings."""
        extent = self.map.extent()
        others = tuple(sorted(_obstacles(self.map, self.settings, without=base), key=_order))
        bounds = (extent.min_x, extent.max_x, extent.min_y, extent.max_y)
        return others, bounds, base_radius(self._robot(base).footprint, self.settings.radius_step), self.settings


def _order(footprint: _Footprint) -> tuple[object, ...]:
    return (footprint.name, footprint.x, footprint.y, footprint.half, footprint.yaw, footprint.disc)


def _obstacles(smap: SemanticMap, settings: RouteSettings, without: str) -> Iterable[_Footprint]:
    """What stands on the floor higher than a base may drive over, as the simulation builds it from the map."""
    low = settings.obstacle_height
    boxed = {*smap.walls, *smap.furniture, *smap.bodies}
    boxed |= {part.iri for d in smap.dispensers.values() for part in (d.body, d.spout, d.lever)}
    for iri in sorted(boxed):
        thing = smap.things.get(iri)
        if thing is not None and thing.box.max_z > low:
            yield _box(local_name(iri), thing.box.min_x, thing.box.max_x, thing.box.min_y, thing.box.max_y)
    for obj in smap.objects.values():
        support = smap.things.get(obj.support or "")
        if (support.box.max_z if support is not None else 0.0) + obj.size[2] > low:
            half = (obj.size[0] / 2, obj.size[1] / 2)
            disc = obj.shape == "cylinder"
            if disc:
                half = (min(half), min(half))
            yield _Footprint(obj.start.x, obj.start.y, half, obj.start.yaw, disc, obj.name)
    for person in smap.people.values():
        r = settings.person_radius
        yield _Footprint(person.start.x, person.start.y, (r, r), disc=True, name=person.name)
    for iri, robot in smap.robots.items():  # the others stand where the map puts them
        if iri != without:
            half = (robot.footprint[0] / 2, robot.footprint[1] / 2)
            yield _Footprint(robot.start.x, robot.start.y, half, robot.start.yaw, name=robot.name)
    yield from _housings(smap, low)


def _housings(smap: SemanticMap, low: float) -> Iterable[_Footprint]:
    """The cameras' housings (and masts) a loaded base would meet: one mounted on something stands on it;
    one hung from the ceiling is passed under when higher than the platforms and the tallest object on them
    (``sim.mapping.overhead``)."""
    platform = max((robot.platform_height or 0.0 for robot in smap.robots.values()), default=0.0)
    clearance = platform + max((obj.size[2] for obj in smap.objects.values()), default=0.0)
    for camera in smap.cameras.values():
        if camera.size is None:
            continue
        x, y, z = camera.position
        bottom = z - camera.size[2] / 2
        if camera.mount is None and bottom > clearance:
            continue
        if z + camera.size[2] / 2 > low:
            yield _Footprint(x, y, (camera.size[0] / 2, camera.size[1] / 2), name=camera.name)


def _box(name: str, x0: float, x1: float, y0: float, y1: float) -> _Footprint:
    return _Footprint((x0 + x1) / 2, (y0 + y1) / 2, ((x1 - x0) / 2, (y1 - y0) / 2), name=name)


@lru_cache(maxsize=8)
def _grid(obstacles: tuple[_Footprint, ...], bounds: Bounds, radius: float, settings: RouteSettings) -> FloorGrid:
    res = settings.resolution
    cols, rows = round((bounds[1] - bounds[0]) / res), round((bounds[3] - bounds[2]) / res)
    xs = bounds[0] + (np.arange(cols) + 0.5) * res
    ys = bounds[2] + (np.arange(rows) + 0.5) * res
    gx, gy = np.meshgrid(xs, ys)  # [row, col]
    occupied = np.zeros((rows, cols), dtype=bool)
    for o in obstacles:
        dx, dy = gx - o.x, gy - o.y
        if o.disc:
            occupied |= dx * dx + dy * dy <= o.half[0] * o.half[0]
            continue
        c, s = math.cos(o.yaw), math.sin(o.yaw)
        u, v = c * dx + s * dy, -s * dx + c * dy
        occupied |= (np.abs(u) <= o.half[0] + 1e-9) & (np.abs(v) <= o.half[1] + 1e-9)
    inflated = inflate(occupied, (radius + res / 2) / res)
    return FloorGrid(res, (bounds[0], bounds[2]), occupied, inflated, radius)


def inflate(occupied: NDArray[np.bool_], radius_cells: float) -> NDArray[np.bool_]:
    """Obstacles grown by a disc of ``radius_cells`` (a morphological dilation with shifted copies): the map
    server's (``sim.mapping``) and the routes' grids alike."""
    rows, cols = occupied.shape
    out = occupied.copy()
    reach = math.ceil(radius_cells)
    for di in range(-reach, reach + 1):
        for dj in range(-reach, reach + 1):
            if (di == 0 and dj == 0) or di * di + dj * dj > radius_cells * radius_cells + 1e-9:
                continue
            src = occupied[max(0, -di) : rows - max(0, di), max(0, -dj) : cols - max(0, dj)]
            out[max(0, di) : rows - max(0, -di), max(0, dj) : cols - max(0, -dj)] |= src
    return out


@lru_cache(maxsize=64)
def _search(
    obstacles: tuple[_Footprint, ...], bounds: Bounds, radius: float, settings: RouteSettings, start: Point, goal: Point
) -> tuple[tuple[Point, ...], float] | str:
    """The waypoints and the length of the drive from ``start`` to ``goal``, or why there is none."""
    grid = _grid(obstacles, bounds, radius, settings)
    ends = []
    for what, point in (("where the base stands", start), ("where it goes", goal)):
        cell = _snap(grid, point, settings.snap)
        if cell is None:
            return f"no cell within {settings.snap:g} m of {what} ({point[0]:.2f}, {point[1]:.2f}) is free for it"
        ends.append(cell)
    cells = _astar(grid, ends[0], ends[1])
    if cells is None:
        return (
            f"nothing connects where it stands ({start[0]:.2f}, {start[1]:.2f}) to ({goal[0]:.2f}, {goal[1]:.2f}) "
            f"with {radius:.2f} m of clearance"
        )
    points = _corners(grid, [grid.centre(cell) for cell in cells])
    driven = sum(math.dist(a, b) for a, b in itertools.pairwise(points))
    return tuple(points), math.dist(start, points[0]) + driven + math.dist(points[-1], goal)


def _snap(grid: FloorGrid, point: Point, reach: float) -> Cell | None:
    """The free cell nearest ``point`` within ``reach`` (its own, if free); the first in row order of ties."""
    cell = grid.cell(point)
    if cell is not None and not grid.inflated[cell]:
        return cell
    free = np.argwhere(~grid.inflated)
    if free.size == 0:
        return None
    centres = np.asarray(grid.origin) + (free[:, ::-1] + 0.5) * grid.resolution
    distances = np.hypot(centres[:, 0] - point[0], centres[:, 1] - point[1])
    best = int(np.argmin(distances))
    return None if distances[best] > reach else (int(free[best, 0]), int(free[best, 1]))


def _astar(grid: FloorGrid, source: Cell, target: Cell) -> list[Cell] | None:
    """A shortest 8-connected cell path (a diagonal only past two free cells), by A* with the octile
    distance, which never overestimates (ties: the deeper first); None when ``target`` is not reached.
    Cells are numbered row by row on the grid padded with a border of obstacles: no bounds checks."""
    rows, cols = grid.inflated.shape
    w = cols + 2
    padded = np.ones((rows + 2, w), dtype=bool)
    padded[1:-1, 1:-1] = grid.inflated
    blocked: list[bool] = padded.ravel().tolist()
    d = math.sqrt(2.0)
    k = d - 1.0
    src, tgt = (source[0] + 1) * w + source[1] + 1, (target[0] + 1) * w + target[1] + 1
    ti, tj = divmod(tgt, w)
    moves = [(step, 1.0, step, step) for step in (-1, 1, -w, w)]
    moves += [(dy + dx, d, dy, dx) for dy in (-w, w) for dx in (-1, 1)]  # both cells beside it free too
    best: dict[int, float] = {src: 0.0}
    parent: dict[int, int] = {}
    done: set[int] = set()
    queue: list[tuple[float, float, int]] = [(0.0, 0.0, src)]
    while queue:
        _, deep, node = heappop(queue)
        if node in done:
            continue
        if node == tgt:
            path = [node]
            while path[-1] in parent:
                path.append(parent[path[-1]])
            return [(cell // w - 1, cell % w - 1) for cell in reversed(path)]
        done.add(node)
        for step, cost, a, b in moves:
            cell = node + step
            if blocked[cell] or blocked[node + a] or blocked[node + b]:
                continue
            g = cost - deep
            if g < best.get(cell, math.inf):
                best[cell], parent[cell] = g, node
                ci, cj = divmod(cell, w)
                ai, aj = abs(ci - ti), abs(cj - tj)
                heappush(queue, (g + (ai + k * aj if ai > aj else aj + k * ai), -g, cell))
    return None


def _in_sight(grid: FloorGrid, a: Point, points: NDArray[np.float64]) -> NDArray[np.bool_]:
    """Whether each segment from ``a`` to one of ``points`` keeps to free cells, sampled at least every
    quarter cell (as the simulation's line of sight), all at once."""
    longest = float(np.max(np.hypot(points[:, 0] - a[0], points[:, 1] - a[1]), initial=0.0))
    samples = max(2, math.ceil(longest / (grid.resolution / 4.0)) + 1)
    t = np.linspace(0.0, 1.0, samples)
    xs = a[0] + np.outer(points[:, 0] - a[0], t)
    ys = a[1] + np.outer(points[:, 1] - a[1], t)
    cols = np.floor((xs - grid.origin[0]) / grid.resolution).astype(np.intp)
    rows = np.floor((ys - grid.origin[1]) / grid.resolution).astype(np.intp)
    return np.logical_not(grid.inflated[rows, cols].any(axis=1))


def _corners(grid: FloorGrid, points: list[Point]) -> list[Point]:
    """The corners the base needs: from each kept point, on to the farthest one in sight."""
    along = np.asarray(points, dtype=np.float64)
    kept, index = [points[0]], 0
    while index < len(points) - 1:
        ahead = _in_sight(grid, points[index], along[index + 2 :])
        seen = np.flatnonzero(ahead)
        index = index + 2 + int(seen[-1]) if seen.size else index + 1
        kept.append(points[index])
    return kept
