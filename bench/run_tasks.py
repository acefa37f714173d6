"""Benchmark: plan and execute the paper's scenarios in the simulated home, headless.

Run: python bench/run_tasks.py [--seeds 0,1,2] [--fail IRI]. Prints the machine, the inputs and, per
task and seed: the outcome, steps, failovers, simulated seconds, wall seconds (world building,
planning and execution) and the real-time factor (simulated / wall seconds of execution).
"""

from __future__ import annotations

import argparse
import importlib.metadata
import os
import platform
import statistics
import time

from cbrs.actions.composer import Composer
from cbrs.actions.runner import run_task
from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import expand
from cbrs.kb.semantic_map import SemanticMap
from cbrs.sim.components import SimEnvironment
from cbrs.sim.world import HomeWorld

TASKS = ("RobotArmServeACup", "FetchMyPen")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", default="0,1,2,3,4")
    parser.add_argument("--fail", action="append", default=[], help="component to fail (prefixed name or IRI)")
    args = parser.parse_args()
    seeds = [int(s) for s in args.seeds.split(",")]
    faults = [expand(f) for f in args.fail]
    print(
        f"machine: {platform.platform()}, {os.cpu_count()} cores, python {platform.python_version()}, "
        f"pybullet {importlib.metadata.version('pybullet')}"
    )
    print(f"inputs: tasks {', '.join(TASKS)}; seeds {seeds}; failing {faults or 'none'}; DIRECT, headless\n")
    kb = KnowledgeBase.open(":memory:")
    composer = Composer(kb)
    print(
        f"{'task':<18} {'seed':>4} {'status':>10} {'steps':>5} {'failovers':>9} {'sim s':>7} "
        f"{'build s':>7} {'run s':>6} {'RTF':>6}"
    )
    factors: dict[str, list[float]] = {task: [] for task in TASKS}
    for task in TASKS:
        for seed in seeds:
            start = time.perf_counter()
            world = HomeWorld.create(seed=seed, semantic_map=SemanticMap.read(kb))
            built = time.perf_counter() - start
            try:
                start = time.perf_counter()
                result = run_task(kb, task, SimEnvironment(world, kb), faults, composer=composer)
                wall = time.perf_counter() - start
                simulated = world.time
            finally:
                world.close()
            report = result.report
            status = report.status.value if report else "no plan"
            steps = len(report.steps) if report else 0
            failovers = sum(1 for s in report.steps if s.failed_over) if report else 0
            factor = simulated / wall if wall > 0 else float("nan")
            factors[task].append(factor)
            print(
                f"{task:<18} {seed:>4} {status:>10} {steps:>5} {failovers:>9} {simulated:>7.1f} "
                f"{built:>7.2f} {wall:>6.2f} {factor:>6.1f}"
            )
    print()
    for task, values in factors.items():
        median = statistics.median(values)
        print(f"{task}: real-time factor median {median:.1f} (min {min(values):.1f}, max {max(values):.1f})")


if __name__ == "__main__":
    main()
