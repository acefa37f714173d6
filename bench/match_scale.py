"""Benchmark: rank 10,000 advertisements for one requirement over a taxonomy of thousands of classes.

The taxonomy, advertisements and requirements are synthetic and seeded (reasoner/synthetic.py).
The index and the pool's array layout are built once; what is timed is Matchmaker.rank for one
requirement: the whole pool scored and ordered, the first --explain candidates explained.

Run: python bench/match_scale.py [--classes 4000] [--ads 10000] [--queries 20] [--method sem-str]
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import time

from cbrs.kb import KnowledgeBase, Store
from cbrs.reasoner.matchmaker import Matchmaker
from cbrs.reasoner.methods import METHODS
from cbrs.reasoner.synthetic import build


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--classes", type=int, default=4000)
    parser.add_argument("--ads", type=int, default=10000)
    parser.add_argument("--queries", type=int, default=20)
    parser.add_argument("--method", choices=METHODS, default="sem-str")
    parser.add_argument("--seed", type=int, default=7)
    parser.add_argument("--explain", type=int, default=10, help="candidates explained in full")
    args = parser.parse_args()
    print(
        f"machine: {platform.machine()} {platform.system()}, {os.cpu_count()} cores, python {platform.python_version()}"
    )
    print(
        f"inputs: {args.classes} classes, {args.ads} advertisements, {args.queries} requirements, "
        f"method {args.method}, seed {args.seed}"
    )
    start = time.perf_counter()
    index, pool, requirements = build(args.classes, args.ads, args.queries, args.seed)
    kb = KnowledgeBase(Store.open(":memory:"))
    matchmaker = Matchmaker(kb, args.method, index=index, advertisements=pool)
    print(f"setup (taxonomy index, pool): {time.perf_counter() - start:.2f} s; index has {len(index)} nodes")
    matchmaker.rank(requirements[0], explain=args.explain)  # lays the pool out as arrays, once
    samples = []
    for requirement in requirements:
        begin = time.perf_counter()
        result = matchmaker.rank(requirement, explain=args.explain)
        samples.append((time.perf_counter() - begin) * 1000)
        assert len(result.candidates) == args.ads
    ordered = sorted(samples)
    print(
        f"rank all {args.ads} (top {args.explain} explained), over {len(samples)} requirements: "
        f"p50 {statistics.median(samples):.1f} ms, p90 {ordered[int(len(ordered) * 0.9) - 1]:.1f} ms, "
        f"max {ordered[-1]:.1f} ms (first requirement {samples[0]:.1f} ms)"
    )


if __name__ == "__main__":
    main()
