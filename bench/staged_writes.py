"""Benchmark: large writes to a remote store, in one request against staged in batches (kb.staged_writes).

Run: python bench/staged_writes.py --url http://127.0.0.1:7878 [--url http://127.0.0.1:8890/sparql]
[--repeat N] [--json FILE]. Each URL is a running SPARQL server cbrs may write to (oxigraph serve
--union-default-graph, Virtuoso 7 with SPARQL_UPDATE granted); the cbrs graphs on it are dropped before
every run. For each server it times seeding the bundled files and adding 20,000 quads, in one request
and in batches of 1000 and 250 quads, against the embedded in-memory seed measured in the same run.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import sys
import time
from collections.abc import Callable
from pathlib import Path

import httpx
import pyoxigraph as ox

from cbrs.kb import KnowledgeBase, StoreError
from cbrs.kb.loader import parse_file
from cbrs.kb.namespaces import BASE, GraphName
from cbrs.kb.remote_store import RemoteStore
from cbrs.kb.resources import bundled_files

ONE_REQUEST = 10**9
BATCHES = [ONE_REQUEST, 1000, 250]


def median_ms(action: Callable[[], object], before: Callable[[], None], repeat: int) -> float | str:
    samples = []
    for _ in range(repeat):
        before()
        start = time.perf_counter()
        try:
            action()
        except StoreError as error:
            return f"refused: {error.reason[:70]}"
        samples.append((time.perf_counter() - start) * 1000)
    return statistics.median(samples)


def clear(store: RemoteStore) -> None:
    for graph in store.graphs():
        if graph.startswith(BASE):
            store.clear_graph(ox.NamedNode(graph))


def server_name(store: RemoteStore) -> str:
    answer = httpx.post(store.endpoints.query, data={"query": "ASK {}"})
    return answer.headers.get("server", "unknown server")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--url", action="append", required=True, help="a SPARQL server to write to")
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--json", type=Path, help="also write the figures here")
    args = parser.parse_args()

    seed = [quad for item in bundled_files() for quad in parse_file(item.path, item.graph).quads]
    p = ox.NamedNode("http://e/p")
    many = [
        ox.Quad(ox.NamedNode(f"http://e/s{i}"), p, ox.Literal(f"value {i}"), GraphName.WORLD.node)
        for i in range(20_000)
    ]
    anchor = statistics.median(timed_seed() for _ in range(args.repeat))
    print(
        f"machine: {platform.machine()} {platform.system()} {platform.release()}, {os.cpu_count()} cores, "
        f"python {platform.python_version()}, pyoxigraph {ox.__version__}, httpx {httpx.__version__}"
    )
    print(
        f"inputs: the bundled files ({', '.join(f.path.name for f in bundled_files())}): {len(seed)} quads; "
        f"20,000 quads of one literal each; repeat {args.repeat}, median"
    )
    print(f"anchor: seeding an embedded in-memory store, {anchor:.1f} ms\n")
    rows = []
    for url in args.url:
        for batch in BATCHES:
            store = RemoteStore.open(url, timeout=300, batch=batch)
            name = server_name(store)
            for what, quads in (("seed", seed), ("20,000 quads", many)):
                figure = median_ms(lambda s=store, q=quads: s.add(q), lambda s=store: clear(s), args.repeat)
                rows.append(
                    {
                        "server": name,
                        "write": what,
                        "batch": "one request" if batch == ONE_REQUEST else batch,
                        "ms": figure,
                    }
                )
            clear(store)
            store.close()
    print(f"{'server':<40} {'write':<13} {'batch':>12} {'p50 ms':>10} {'/ anchor':>9}")
    for row in rows:
        ms = row["ms"]
        shown = f"{ms:10.1f} {ms / anchor:9.1f}" if isinstance(ms, float) else f"  {ms}"
        print(f"{row['server'][:40]:<40} {row['write']:<13} {row['batch']!s:>12} {shown}")
    if args.json:
        args.json.write_text(json.dumps({"anchor_ms": anchor, "rows": rows}, indent=2), encoding="utf-8")


def timed_seed() -> float:
    start = time.perf_counter()
    KnowledgeBase.open(":memory:").close()
    return (time.perf_counter() - start) * 1000


if __name__ == "__main__":
    sys.exit(main())
