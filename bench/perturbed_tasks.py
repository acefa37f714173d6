"""Benchmark: tasks in perturbed homes: the objects moved on their supports, the person and the base
moved on the floor, one world per seed.

Run: python bench/perturbed_tasks.py [--seeds 20] [--object 0.04] [--person 0.8] [--tasks ...] [--json FILE]. The
tasks are the paper's two scenarios and the Turtle-only tasks of tests/data/tasks (a new object
fetched by a goal-only task and through FetchMyPen's hierarchy, the cup put on a new place, a new
object class, a two-level task). Prints the machine, the inputs, one row per
run (seed, outcome, re-plans, simulated seconds, the reason of a failure; "refused" when the check
before a run refused it, before anything moved) and per task the success rate; with --json, the same as a record.
"""

from __future__ import annotations

import argparse
import importlib.metadata
import json
import math
import os
import platform
import time
from pathlib import Path
from typing import Any

from cbrs.actions.composer import Composer
from cbrs.actions.runner import RunResult, run_task
from cbrs.kb import KnowledgeBase
from cbrs.kb.errors import KnowledgeBaseError
from cbrs.kb.semantic_map import SemanticMap
from cbrs.sim.components import SimEnvironment
from cbrs.sim.world import Spread, open_world

DATA = Path(__file__).resolve().parents[1] / "tests" / "data" / "tasks"
TASKS: dict[str, list[tuple[str, str]]] = {
    "RobotArmServeACup": [],
    "FetchMyPen": [],
    "FetchMyPencil": [("map", "pencil_on_the_table.ttl"), ("requirements", "fetch_my_pencil.ttl")],
    "PutCupOnTray": [("map", "tray_place.ttl"), ("requirements", "put_cup_on_tray.ttl")],
    "FetchMyPencilLikeMyPen": [("map", "pencil_on_the_table.ttl"), ("requirements", "fetch_my_pencil_like_my_pen.ttl")],
    "FetchMyChopstick": [
        ("ontology", "chopstick.ttl"),
        ("map", "chopstick.ttl"),
        ("requirements", "fetch_my_chopstick.ttl"),
    ],
    "MorningRoutine": [("ontology", "morning_routine.ttl")],
}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=20, help="world seeds 0..N-1 per task")
    parser.add_argument("--object", type=float, default=0.04, help="how far objects move on their support (m)")
    parser.add_argument("--person", type=float, default=0.8, help="how far the person moves (m)")
    parser.add_argument("--base", type=float, default=0.3, help="how far the base's start moves (m)")
    parser.add_argument("--json", type=Path, help="write the record here")
    parser.add_argument("--tasks", nargs="+", choices=list(TASKS), default=list(TASKS), help="the tasks to run")
    args = parser.parse_args()
    spread = Spread(object=args.object, yaw=0.5, person=args.person, base=args.base, base_yaw=math.pi)
    print(
        f"machine: {platform.platform()}, {os.cpu_count()} cores, python {platform.python_version()}, "
        f"pybullet {importlib.metadata.version('pybullet')}"
    )
    print(f"inputs: tasks {', '.join(args.tasks)}; world seeds 0-{args.seeds - 1}; {spread}; DIRECT, headless\n")
    print(f"{'task':<18} {'seed':>4} {'status':<10} {'re-plans':>8} {'sim s':>6}  reason")
    record: dict[str, Any] = {"spread": spread.__dict__, "seeds": args.seeds, "tasks": {}}
    started = time.perf_counter()
    for task in args.tasks:
        files = TASKS[task]
        kb = KnowledgeBase.open(":memory:")
        for graph, name in files:
            kb.load([DATA / name], graph=graph)
        composer = Composer(kb)
        runs = []
        for seed in range(args.seeds):
            with open_world(seed=seed, semantic_map=SemanticMap.read(kb), spread=spread) as world:
                try:
                    result: RunResult | None = run_task(kb, task, SimEnvironment(world, kb), composer=composer)
                except KnowledgeBaseError as refused:  # the check before a run: nothing moved
                    result, reason = None, f"{type(refused).__name__}: {refused}"
                seconds = world.time
            if result is None:
                status, replans = "refused", 0
            else:
                status = "succeeded" if result.succeeded else ("failed" if result.report else "unsolvable")
                reason = "" if result.succeeded else (result.report.reason if result.report else "no plan")
                replans = len(result.replans)
            runs.append({"seed": seed, "status": status, "replans": replans, "sim_seconds": seconds, "reason": reason})
            print(f"{task:<18} {seed:>4} {status:<10} {replans:>8} {seconds:>6.1f}  {reason[:110]}")
        record["tasks"][task] = runs
    print(f"\n{'task':<18} {'succeeded':>9} {'rate':>6} {'re-planned':>10}")
    for task, runs in record["tasks"].items():
        ok = sum(1 for r in runs if r["status"] == "succeeded")
        replanned = sum(1 for r in runs if r["replans"])
        print(f"{task:<18} {ok:>4} / {len(runs):<2} {ok / len(runs):>6.0%} {replanned:>10}")
    print(f"\n{sum(len(r) for r in record['tasks'].values())} runs in {time.perf_counter() - started:.0f} s")
    if args.json:
        args.json.write_text(json.dumps(record, indent=2), encoding="utf-8")


if __name__ == "__main__":
    main()
