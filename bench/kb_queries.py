"""Benchmark: seeding a store with the bundled data, reading descriptions, and each named query.

Run: python bench/kb_queries.py [--repeat N]. Prints the machine, the inputs and the figures.
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics

import pyoxigraph
from timing import samples_ms

from cbrs.kb import KnowledgeBase, Store
from cbrs.kb.resources import bundled_files

# A sample value per parameter name, bound where a query requires that parameter (or where the bench
# times the bound form: action_ordering for one action). A required parameter with no sample here is
# reported and its query skipped, so a new named query never stops the bench.
SAMPLES = {
    "description": "svc:LocateMobileRobot_CeilingCamera01",
    "concept": "home:RobotPosition",
    "resource": "home:Cup",
    "action": "act:RobotArmServeACup",
    "namespace": "https://w3id.org/cbrs/home#",
    "graph": "graph:services",
}
TIMED_BOUND = {"action_ordering"}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--repeat", type=int, default=50, help="runs per measured operation")
    args = parser.parse_args()

    print(
        f"machine: {platform.machine()} {platform.system()} {platform.release()}, {os.cpu_count()} cores, "
        f"python {platform.python_version()}, pyoxigraph {pyoxigraph.__version__}"
    )
    print(f"inputs: bundled files {', '.join(f.path.name for f in bundled_files())}; repeat {args.repeat}")

    seed = samples_ms(lambda: KnowledgeBase(Store.open(":memory:")).seed(), max(3, args.repeat // 10))
    kb = KnowledgeBase.open(":memory:")
    stats = kb.statistics()
    print(f"store: {sum(stats.values())} triples, {len(kb.select('advertisements'))} advertisements")
    print(f"\n{'operation':<34} {'p50 ms':>9} {'p95 ms':>9}")
    print(f"{'seed in-memory store':<34} {statistics.median(seed):>9.2f} {max(seed):>9.2f}")

    def read_all() -> object:
        kb._reader.clear_cache()
        return kb.advertisements()

    rows = samples_ms(read_all, max(3, args.repeat // 10))
    print(f"{'read all advertisements (cold)':<34} {statistics.median(rows):>9.2f} {max(rows):>9.2f}")
    for name in kb.queries.names():
        query = kb.queries.get(name)
        values = {
            p.name: SAMPLES[p.name]
            for p in query.parameters.values()
            if p.name in SAMPLES and (p.required or name in TIMED_BOUND)
        }
        missing = [p.name for p in query.parameters.values() if p.required and p.name not in values]
        if missing:
            print(f"{'query ' + name:<34} skipped: no sample value for {', '.join(missing)}")
            continue
        samples = sorted(samples_ms(lambda n=name, v=values: kb.select(n, v), args.repeat))  # type: ignore[misc]
        p95 = samples[min(len(samples) - 1, int(len(samples) * 0.95))]
        print(f"{'query ' + name:<34} {statistics.median(samples):>9.2f} {p95:>9.2f}")


if __name__ == "__main__":
    main()
