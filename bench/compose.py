"""Benchmark: composing the paper's scenarios, and composition over larger synthetic pools.

Run: python bench/compose.py [--repeat N] [--sizes 100,300,1000] [--queries Q] [--seed S].
Prints the machine, the inputs and the figures. Synthetic pools come from reasoner.synthetic (random
is-a tree with parts, ads with 1-3 inputs, 1-2 outputs, an effect half of the time); most of their
random requirements have no plan, which is the expensive case (the whole graph is searched).
The pool (components and the edges among them) is built once per composer and shared by requirements.
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import time

from cbrs.actions.composer import Composer, PlanStatus
from cbrs.actions.model import ActionLibrary
from cbrs.kb import KnowledgeBase
from cbrs.reasoner import synthetic

TASKS = ["PutCupBelowOfTapOfWaterDispenser", "FetchMyPen", "RobotArmServeACup"]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--sizes", default="100,300,1000")
    parser.add_argument("--queries", type=int, default=20)
    parser.add_argument("--seed", type=int, default=7)
    args = parser.parse_args()
    print(f"machine: {platform.platform()}, {os.cpu_count()} cores, python {platform.python_version()}")
    print(f"inputs: bundled home; repeat {args.repeat}; synthetic sizes {args.sizes}, ", end="")
    print(f"{args.queries} requirements each, seed {args.seed}")

    kb = KnowledgeBase.open(":memory:")
    start = time.perf_counter()
    composer = Composer(kb)
    _ = composer.advertisements
    print(
        f"\ncomposer set-up (taxonomy index, action library, {len(composer.advertisements)} advertisements): "
        f"{(time.perf_counter() - start) * 1000:.0f} ms"
    )
    print(f"{'task':<34} {'steps':>5} {'first ms':>9} {'median ms':>10}")
    for task in TASKS:
        samples = []
        steps = 0
        for _ in range(args.repeat + 1):
            start = time.perf_counter()
            result = composer.compose(task)
            samples.append((time.perf_counter() - start) * 1000)
            steps = len(result.plan.steps) if result.plan else 0
        print(f"{task:<34} {steps:>5} {samples[0]:>9.1f} {statistics.median(samples[1:]):>10.1f}")

    print(f"\n{'pool':>6} {'classes':>8} {'edges':>7} {'build ms':>9} {'planned':>8} {'median ms':>10} {'p95 ms':>8}")
    for size in (int(s) for s in args.sizes.split(",")):
        classes = max(200, size * 2)
        index, pool, requirements = synthetic.build(classes, size, args.queries, args.seed)
        start = time.perf_counter()
        engine = Composer(kb, index=index, actions=ActionLibrary(), advertisements=pool)
        edges = sum(len(e) for by_need in engine.pool.into.values() for e in by_need.values())
        built = (time.perf_counter() - start) * 1000
        samples, planned = [], 0
        for requirement in requirements:
            start = time.perf_counter()
            result = engine.compose(requirement)
            samples.append((time.perf_counter() - start) * 1000)
            planned += result.status is PlanStatus.PLANNED
        samples.sort()
        p95 = samples[min(len(samples) - 1, int(0.95 * len(samples)))]
        print(
            f"{size:>6} {classes:>8} {edges:>7} {built:>9.0f} {planned:>4}/{len(requirements):<3} "
            f"{statistics.median(samples):>10.1f} {p95:>8.1f}"
        )


if __name__ == "__main__":
    main()
