"""Benchmark: reading the semantic map and the named queries it runs, on a store given by --store.

Run: python bench/map_read.py [--store PATH] [--repeat N]. The bundled in-memory store by default; a
store that also holds a large ontology (OWLS-TC 4, docs/owls.md) is where a query's plan shows.
Prints the machine, the store's size and the figures (docs/ontologies.md, "Queries and Oxigraph's planner").
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
from collections.abc import Callable

import pyoxigraph
from timing import samples_ms

from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.semantic_map import SemanticMap

HOME = PREFIXES["home"]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--store", default=":memory:", help="the store (a directory; :memory: seeds the bundled data)")
    parser.add_argument("--repeat", type=int, default=10, help="runs per measured operation")
    args = parser.parse_args()
    kb = KnowledgeBase.open(args.store)
    print(
        f"machine: {platform.machine()} {platform.system()} {platform.release()}, {os.cpu_count()} cores, "
        f"python {platform.python_version()}, pyoxigraph {pyoxigraph.__version__}, load {os.getloadavg()[0]:.1f}"
    )
    print(f"store: {args.store}, {sum(kb.statistics().values())} triples in named graphs; repeat {args.repeat}")
    operations: list[tuple[str, Callable[[], object]]] = [
        ("SemanticMap.read", lambda: SemanticMap.read(kb)),
        ("designate, class bound", lambda: kb.select("designate", {"class": HOME + "Container"})),
        ("designate, every class", lambda: kb.queries.select_every(kb.store, "designate")),
        ("map_types", lambda: kb.select("map_types")),
        ("map_facts", lambda: kb.select("map_facts")),
    ]
    print(f"\n{'operation':<26} {'p50 ms':>9} {'max ms':>9}")
    for name, action in operations:
        samples = samples_ms(action, args.repeat, warm=True)
        print(f"{name:<26} {statistics.median(samples):>9.2f} {max(samples):>9.2f}")
    kb.close()


if __name__ == "__main__":
    main()
