"""Benchmark: the SHACL check of service descriptions (kb/shapes.py) on three loads, and its share.

(a) the paper testbed (``open_testbed_kb``: the bundled ontology graph, then the 20x100 testbed, into a
fresh in-memory store); (b) the home-robot OWL-S collection (tests/data/robot_services: its ontology
and its 69 services, one ``kb.load``); (c) ``cbrs register --update`` of one OWL-S file into an empty
in-memory store (``kb.registry.synced``, what the command calls). For each: the wall and CPU seconds
of the whole load and of the shape check inside it (pySHACL and what surrounds it), medians of
``--repeat`` runs in this process after one warm-up, with the load average. CPU seconds are this
process's: less disturbed than the wall by the other work of a shared machine.

``--compare`` runs each load also with the datatype-choice shortcut off (:func:`shapes._datatype_choices`
giving none: every check against the whole shapes file, as before the shortcut), alternating the two,
so that both see the same machine.

``--cold`` times what a user waits for instead: each load in a fresh process (``cbrs --store :memory:
load`` of the collection, ``cbrs --store :memory: register --update`` of the file, a Python process
opening the testbed), imports and the first parse of the shapes included; with ``--base DIR`` (a source
tree of an earlier commit: ``git archive COMMIT | tar -x -C DIR``, put first on PYTHONPATH) alternating
with it.

Run: python bench/shape_check.py [--repeat 5] [--compare] [--cold [--base DIR]] [--only testbed|robots|register]
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import cbrs.kb.shapes as shapes
from cbrs.kb import KnowledgeBase
from cbrs.kb.store import Store
from cbrs.reasoner.testbed import open_testbed_kb

ROBOTS = Path(__file__).resolve().parents[1] / "tests" / "data" / "robot_services"
ONE_OWLS = ROBOTS / "services" / "ceiling_camera_localiser.owls"


def load_testbed() -> None:
    open_testbed_kb().close()


def load_robots() -> None:
    kb = KnowledgeBase(Store.open(":memory:"))
    kb.load(sorted((ROBOTS / "ontology").iterdir()) + sorted((ROBOTS / "services").glob("*.owls")))
    kb.close()


def register_one_owls() -> None:
    kb = KnowledgeBase.open(":memory:")
    kb.registry.synced(ONE_OWLS.read_bytes(), str(ONE_OWLS))
    kb.close()


LOADS: dict[str, Callable[[], None]] = {"testbed": load_testbed, "robots": load_robots, "register": register_one_owls}


class CheckClock:
    """Wall and CPU seconds spent in the shape check (every call of ``shapes._shape_problems``)."""

    def __init__(self) -> None:
        self.wall = self.cpu = 0.0
        self._inner = shapes._shape_problems

    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        wall, cpu = time.perf_counter(), time.process_time()
        try:
            return self._inner(*args, **kwargs)
        finally:
            self.wall += time.perf_counter() - wall
            self.cpu += time.process_time() - cpu


@contextmanager
def shortcut(on: bool) -> Iterator[None]:
    """The datatype-choice shortcut on (as shipped) or off (the whole shapes file every time)."""
    if on or not hasattr(shapes, "_datatype_choices"):
        yield
        return
    kept = shapes._datatype_choices
    shapes._datatype_choices = lambda: ()  # type: ignore[assignment]
    try:
        yield
    finally:
        shapes._datatype_choices = kept  # type: ignore[assignment]


def run(load: Callable[[], None], on: bool) -> tuple[float, float, float, float]:
    """(wall, cpu, check wall, check cpu) of one run of ``load``."""
    clock = CheckClock()
    shapes._shape_problems = clock  # type: ignore[assignment]
    try:
        with shortcut(on):
            wall, cpu = time.perf_counter(), time.process_time()
            load()
            return time.perf_counter() - wall, time.process_time() - cpu, clock.wall, clock.cpu
    finally:
        shapes._shape_problems = clock._inner  # type: ignore[assignment]


COLD: dict[str, list[str]] = {
    "testbed": ["-c", "from cbrs.reasoner.testbed import open_testbed_kb; open_testbed_kb().close()"],
    "robots": [
        "-m", "cbrs", "--store", ":memory:", "load",
        *map(str, sorted((ROBOTS / "ontology").iterdir())), str(ROBOTS / "services"),
    ],
    "register": ["-m", "cbrs", "--store", ":memory:", "register", "--update", str(ONE_OWLS)],
}  # fmt: skip


def cold_seconds(name: str, base: Path | None) -> float:
    """The wall seconds of one fresh process running load ``name``, from ``base``'s sources if given."""
    env = dict(os.environ)
    if base is not None:
        env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(base), env.get("PYTHONPATH")]))
    start = time.perf_counter()
    # From the root directory: Python puts the working directory first on the path, before PYTHONPATH.
    subprocess.run([sys.executable, *COLD[name]], check=True, env=env, capture_output=True, cwd="/")
    return time.perf_counter() - start


def cold(names: list[str], repeat: int, base: Path | None) -> None:
    trees: list[Path | None] = [None, base] if base is not None else [None]
    for name in names:
        samples: dict[Path | None, list[float]] = {tree: [] for tree in trees}
        loads = []
        for _ in range(repeat):
            for tree in trees:
                samples[tree].append(cold_seconds(name, tree))
            loads.append(os.getloadavg()[0])
        for tree in trees:
            label = "this" if tree is None else str(tree)
            print(
                f"{name:9} {label}: {statistics.median(samples[tree]):6.2f} s wall, a fresh process "
                f"(median of {repeat}: {' '.join(f'{t:.2f}' for t in samples[tree])}; "
                f"load average {min(loads):.1f}-{max(loads):.1f})"
            )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--repeat", type=int, default=5, help="timed runs of each load (after one warm-up)")
    parser.add_argument("--compare", action="store_true", help="also run with the shortcut off, alternating")
    parser.add_argument("--only", choices=sorted(LOADS), action="append", help="run only this load (repeatable)")
    parser.add_argument("--cold", action="store_true", help="time fresh processes instead (imports included)")
    parser.add_argument("--base", type=Path, help="with --cold: alternate with this source tree of another commit")
    args = parser.parse_args()
    if args.cold:
        cold(args.only or list(LOADS), args.repeat, args.base)
        return
    modes = [True, False] if args.compare else [True]
    for name in args.only or list(LOADS):
        load = LOADS[name]
        for on in modes:
            run(load, on)  # warm-up: imports, the parsed shapes, the queries
        samples: dict[bool, list[tuple[float, float, float, float]]] = {on: [] for on in modes}
        loads = []
        for _ in range(args.repeat):
            for on in modes:
                samples[on].append(run(load, on))
            loads.append(os.getloadavg()[0])
        for on in modes:
            columns = list(zip(*samples[on], strict=True))
            wall, cpu, check_wall, check_cpu = (statistics.median(column) for column in columns)
            label = "shortcut" if on else "full    "
            print(
                f"{name:9} {label} load {wall:6.2f} s wall {cpu:6.2f} s cpu | check {check_wall:6.2f} s wall "
                f"{check_cpu:6.2f} s cpu  (medians of {args.repeat}; load average {min(loads):.1f}-{max(loads):.1f})"
            )


if __name__ == "__main__":
    main()
