"""A seventh-round trial (docs/tasks.md, "A seventh round"): the lab's own path planner as a program.

Registers docs/examples/lab7_lab_planner.ttl over the bridge of a running `cbrs serve` (the cbrs SDK,
docs/components.md) and answers each call with a home:Path (docs/values.md): a breadth-first search
on the occupancy grid it is given, inflated by the grid's inflationRadius, with the path's corners cut
where the straight line stays free (an "any-angle" path: fewer waypoints than the bundled A*).

    CBRS_UPDATE_TOKEN=secret python docs/examples/lab7_lab_planner.py --bridge ws://127.0.0.1:9090

--misbehave through-walls answers the straight line from start to goal (a planner that ignores the
map); --misbehave late answers after 15 s; --misbehave silent never answers.
"""

from __future__ import annotations

import argparse
import base64
import itertools
import os
import time
from collections import deque
from pathlib import Path

import numpy as np

from cbrs.component import Component

HERE = Path(__file__).resolve().parent
HOME = "https://w3id.org/cbrs/home#"


def occupancy(grid: dict) -> np.ndarray:
    """The grid's cells as a boolean array [row, column], inflated by its inflation radius."""
    width, height = int(grid["width"]), int(grid["height"])
    bits = np.unpackbits(np.frombuffer(base64.b64decode(grid["cells"]), dtype=np.uint8))
    cells = bits[: width * height].reshape(height, width).astype(bool)
    radius = int(np.ceil(float(grid.get("inflationRadius", 0.3)) / float(grid["resolution"])))
    inflated = cells.copy()
    for dr in range(-radius, radius + 1):
        for dc in range(-radius, radius + 1):
            if dr * dr + dc * dc > radius * radius:
                continue
            inflated |= np.roll(np.roll(cells, dr, axis=0), dc, axis=1)
    return inflated


def plan(grid: dict, start: tuple[float, float], goal: tuple[float, float]) -> list[list[float]]:
    res, (ox, oy) = float(grid["resolution"]), (float(grid["origin"][0]), float(grid["origin"][1]))
    occupied = occupancy(grid)
    rows, cols = occupied.shape

    def cell(p: tuple[float, float]) -> tuple[int, int]:
        return (min(max(int((p[1] - oy) / res), 0), rows - 1), min(max(int((p[0] - ox) / res), 0), cols - 1))

    def centre(c: tuple[int, int]) -> list[float]:
        return [round(ox + (c[1] + 0.5) * res, 3), round(oy + (c[0] + 0.5) * res, 3)]

    def nearest_free(c: tuple[int, int]) -> tuple[int, int]:
        free = np.argwhere(~occupied)
        best = free[np.argmin(((free - np.array(c)) ** 2).sum(axis=1))]
        return (int(best[0]), int(best[1]))

    s, g = cell(start), cell(goal)
    s = s if not occupied[s] else nearest_free(s)
    g = g if not occupied[g] else nearest_free(g)
    came: dict[tuple[int, int], tuple[int, int] | None] = {s: None}
    queue = deque([s])
    while queue and g not in came:
        r, c = queue.popleft()
        for dr, dc in ((1, 0), (-1, 0), (0, 1), (0, -1), (1, 1), (1, -1), (-1, 1), (-1, -1)):
            n = (r + dr, c + dc)
            if 0 <= n[0] < rows and 0 <= n[1] < cols and not occupied[n] and n not in came:
                came[n] = (r, c)
                queue.append(n)
    if g not in came:
        raise RuntimeError(f"no free way from {start} to {goal}")
    cells = [g]
    while came[cells[-1]] is not None:
        cells.append(came[cells[-1]])  # type: ignore[arg-type]
    cells.reverse()

    def clear(a: tuple[int, int], b: tuple[int, int]) -> bool:
        steps = max(abs(b[0] - a[0]), abs(b[1] - a[1])) * 2 + 1
        for t in np.linspace(0.0, 1.0, steps):
            if occupied[round(a[0] + (b[0] - a[0]) * t), round(a[1] + (b[1] - a[1]) * t)]:
                return False
        return True

    corners = [cells[0]]
    i = 0
    while i < len(cells) - 1:
        j = len(cells) - 1
        while j > i + 1 and not clear(cells[i], cells[j]):
            j -= 1
        corners.append(cells[j])
        i = j
    return [centre(c) for c in corners]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--bridge", default="ws://127.0.0.1:9090")
    parser.add_argument("--misbehave", choices=["through-walls", "late", "silent"])
    args = parser.parse_args()
    planner = Component((HERE / "lab7_lab_planner.ttl").read_text())

    @planner.handler
    def plan_path(request: dict) -> dict:
        start = (float(request["start"]["x"]), float(request["start"]["y"]))
        goal = (float(request["goal"]["x"]), float(request["goal"]["y"]))
        print(f"lab planner: asked from {start} to {goal}", flush=True)
        if args.misbehave == "late":
            time.sleep(15)
        if args.misbehave == "silent":
            time.sleep(3600)
        if args.misbehave == "through-walls":
            waypoints = [list(start), list(goal)]
        else:
            waypoints = plan(request["map"], start, goal)
        length = sum(float(np.hypot(b[0] - a[0], b[1] - a[1])) for a, b in itertools.pairwise(waypoints))
        print(f"lab planner: {len(waypoints)} waypoints, {length:.2f} m", flush=True)
        return {
            "path": {
                "@type": HOME + "Path",
                "waypoints": waypoints,
                "length": round(length, 3),
                "algorithm": "lab-any-angle",
            }
        }

    planner.run(args.bridge, token=os.environ.get("CBRS_UPDATE_TOKEN"))


if __name__ == "__main__":
    main()
