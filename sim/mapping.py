"""The map server: a 2D occupancy grid of the home, measured by casting rays down at every cell.

A cell is occupied when the first thing its vertical ray hits (other than the mobile base itself)
stands higher than ``OBSTACLE_HEIGHT``: walls, furniture, the dual-arm robot and the person. Only the
cells inside some body's bounding box (seen from above) are cast: elsewhere the ray could meet
nothing but the floor, so those cells are free without asking (about a tenth of the 36,000 rays are
cast; the grid is the same, tested). The
table top counts although the base could drive under part of it, like the conservative maps made
from a ceiling view. The inflated grid grows every obstacle by the base's radius, so a planner can
treat the base as a point.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pybullet as p
from numpy.typing import NDArray

from cbrs.kb.floor_routes import inflate  # the map server's dilation, here for its callers
from cbrs.sim.errors import OutsideMapError
from cbrs.sim.layout import MAP_RESOLUTION
from cbrs.sim.world import HomeWorld

__all__ = ["OBSTACLE_HEIGHT", "OccupancyGrid", "build_occupancy_grid", "inflate", "overhead"]

OBSTACLE_HEIGHT = 0.03
"""Anything taller than 3 cm blocks the base (the floor is at 0)."""
RAY_TOP = 3.0
"""Rays start above everything in the home (walls 1 m, the person 1.66 m) and end below the floor; a
ceiling camera hung lower is seen through when the loaded base passes under it (:func:`overhead`)."""
RAY_BATCH = 8192
"""pybullet caps one rayTestBatch call; stay well below the cap."""


@dataclass(frozen=True, eq=False)
class OccupancyGrid:
    """Cells of ``resolution`` metres; row i is y, column j is x; cell (0, 0) starts at ``origin``."""

    resolution: float
    origin: tuple[float, float]
    occupied: NDArray[np.bool_] = field(repr=False)
    """Cells with an obstacle, as measured."""
    inflated: NDArray[np.bool_] = field(repr=False)
    """Cells the base's centre must avoid (obstacles grown by ``inflation_radius`` plus half a cell)."""
    inflation_radius: float

    @property
    def shape(self) -> tuple[int, int]:
        rows, cols = self.occupied.shape
        return (int(rows), int(cols))

    @property
    def free(self) -> NDArray[np.bool_]:
        """Cells where the base's centre may be."""
        free: NDArray[np.bool_] = ~self.inflated
        return free

    def world_to_cell(self, x: float, y: float) -> tuple[int, int]:
        """(row, column) of the cell containing a world point; ``OutsideMapError`` off the map."""
        col = math.floor((x - self.origin[0]) / self.resolution)
        row = math.floor((y - self.origin[1]) / self.resolution)
        rows, cols = self.shape
        if not (0 <= row < rows and 0 <= col < cols):
            raise OutsideMapError(x, y)
        return (row, col)

    def cell_to_world(self, row: int, col: int) -> tuple[float, float]:
        """World (x, y) of a cell's centre."""
        return (self.origin[0] + (col + 0.5) * self.resolution, self.origin[1] + (row + 0.5) * self.resolution)

    def is_free(self, x: float, y: float) -> bool:
        row, col = self.world_to_cell(x, y)
        return not bool(self.inflated[row, col])

    def is_occupied(self, x: float, y: float) -> bool:
        """Whether the measured (not inflated) grid has an obstacle at a world point."""
        row, col = self.world_to_cell(x, y)
        return bool(self.occupied[row, col])


def build_occupancy_grid(
    world: HomeWorld,
    resolution: float = MAP_RESOLUTION,
    inflation_radius: float | None = None,
    ignore: Sequence[str] | None = None,
) -> OccupancyGrid:
    """Measure the home's occupancy grid now; the bodies in ``ignore`` (by default the mobile base) are
    seen through, and so is a ceiling camera's housing above what the loaded base reaches (:func:`overhead`:
    one under a 2.7 m ceiling marked the floor below it occupied). Obstacles are
    inflated by ``inflation_radius``, by default the base's (``world.base_radius``)."""
    if inflation_radius is None:
        inflation_radius = world.base_radius
    home = world.extent
    cols = round((home.xmax - home.xmin) / resolution)
    rows = round((home.ymax - home.ymin) / resolution)
    origin = (home.xmin, home.ymin)
    jj, ii = np.meshgrid(np.arange(cols), np.arange(rows))
    xs = origin[0] + (jj.ravel() + 0.5) * resolution
    ys = origin[1] + (ii.ravel() + 0.5) * resolution
    tops = np.full(xs.shape, RAY_TOP)
    heights = np.full(xs.shape, -1.0)
    ignored = [world.body(name) for name in (ignore if ignore is not None else world.base_names)]
    ignored += [body for body in overhead(world) if body not in ignored]
    # A ray outside every other body's bounding box can only meet the floor: it is not cast.
    floor = world.bodies.get("Floor")
    standing = [body for body in world.bodies.values() if body != floor and body not in ignored]
    under = _under_any(world.client, standing, xs, ys)
    heights[~under] = 0.0 if floor is not None else -1.0
    pending = np.flatnonzero(under)
    for _ in range(4):  # a ray is recast below each ignored body it hits; a few rounds are plenty
        if pending.size == 0:
            break
        again = []
        for start in range(0, pending.size, RAY_BATCH):
            chunk = pending[start : start + RAY_BATCH]
            froms = np.column_stack([xs[chunk], ys[chunk], tops[chunk]])
            tos = np.column_stack([xs[chunk], ys[chunk], np.full(chunk.size, -0.5)])
            hits = p.rayTestBatch(froms.tolist(), tos.tolist(), physicsClientId=world.client)
            if len(hits) != chunk.size:
                raise RuntimeError(f"rayTestBatch answered {len(hits)} rays of {chunk.size}")
            bodies = np.fromiter((hit[0] for hit in hits), dtype=np.int64, count=chunk.size)
            zs = np.fromiter((hit[3][2] for hit in hits), dtype=np.float64, count=chunk.size)
            through = np.isin(bodies, ignored)  # seen through: cast again from just below the hit
            tops[chunk[through]] = zs[through] - 1e-3
            again.append(chunk[through])
            hit = ~through & (bodies >= 0)
            heights[chunk[hit]] = zs[hit]
        pending = np.concatenate(again).astype(np.intp)
    occupied = (heights > OBSTACLE_HEIGHT).reshape(rows, cols)
    # An obstacle may reach the edge of its cell, half a cell nearer than the cell's centre.
    radius_cells = (inflation_radius + resolution / 2.0) / resolution
    return OccupancyGrid(resolution, origin, occupied, inflate(occupied, radius_cells), inflation_radius)


def overhead(world: HomeWorld) -> list[int]:
    """The housings of the cameras hung from the ceiling (on no robot) whose every part is higher than the
    base reaches loaded (its platform's top and the tallest object of the map on it): no obstacle to it.
    In the bundled home the ceiling cameras hang 4.5 m up, above the rays' start, and have no housing; a
    lab's housing under a 2.7 m ceiling marked the floor below it occupied. What stands (furniture, walls)
    or moves (the arms, which may come down) stays an obstacle wherever it reaches."""
    platform = max((robot.platform_height or 0.0 for robot in world.mobiles.values()), default=0.0)  # no base: 0
    clearance = platform + max((o.size[2] for o in world.objects.values()), default=0.0)
    above = []
    for camera in world.map.cameras.values():
        body = world.bodies.get(camera.name)
        if body is None or camera.mount is not None:
            continue
        links = range(-1, p.getNumJoints(body, physicsClientId=world.client))
        if all(p.getAABB(body, link, physicsClientId=world.client)[0][2] > clearance for link in links):
            above.append(body)
    return above


def _under_any(
    client: int, bodies: Sequence[int], xs: NDArray[np.floating[Any]], ys: NDArray[np.floating[Any]]
) -> NDArray[np.bool_]:
    """Which points (x, y) lie inside the footprint of some body's bounding box (any link of it)."""
    under = np.zeros(xs.shape, dtype=bool)
    for body in bodies:
        for link in range(-1, p.getNumJoints(body, physicsClientId=client)):
            (x0, y0, _), (x1, y1, _) = p.getAABB(body, link, physicsClientId=client)
            under |= (xs >= x0) & (xs <= x1) & (ys >= y0) & (ys <= y1)
    return under
