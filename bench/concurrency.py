"""Benchmark: cbrs serve under concurrent load, the scenarios tests/test_concurrency.py checks, with figures.

Run: python bench/concurrency.py [--seconds S] [--readers 8] [--workers 4,8] [--batch 20] [--publishers 16]
     [--topics 4] [--subscribers 2] [--window 500]

The server (the seeded bundled knowledge base on disk, an update token) runs in a child process, so it
has an interpreter lock of its own; the clients are threads in this process (httpx, websockets sync),
on the same machine. First R readers alternate a count of the writer's batches and the
``advertisements`` query on /sparql while one writer sends INSERT DATA batches to /update, for S
seconds, once per query-worker count W (with R > W some queries are refused with 503 busy, and the
readers retry at once). Then P rosbridge publishers on T topics, each topic with N subscribers and one
more subscribed to every topic; publishers hold back while a subscriber of their topic is --window
messages behind, so no message is dropped and every one is owed. Prints the machine, the inputs, rates,
latency percentiles and whether everything owed arrived.
"""

from __future__ import annotations

import argparse
import multiprocessing
import os
import platform
import shutil
import statistics
import sys
import tempfile
from itertools import pairwise
from multiprocessing.synchronize import Event
from pathlib import Path

import httpx

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # the scenarios live in tests/ (run from anywhere)

from cbrs.kb import KnowledgeBase
from cbrs.kb.queries import QueryLibrary
from cbrs.kb.resources import query_dir
from cbrs.server import ServeConfig, Server
from cbrs.sparql_service import EndpointConfig
from tests.helpers_concurrency import (
    BATCH_QUERY,
    BridgeLoad,
    SparqlLoad,
    batches_seen,
    bridge_load,
    sparql_load,
)

TOKEN = "bench-token"
WAIT = 60.0


def serve(folder: str, workers: int, ports: multiprocessing.Queue[tuple[int, int]], stop: Event) -> None:
    """The child process: cbrs's Server over an on-disk store, until told to stop."""
    kb = KnowledgeBase.open(Path(folder) / "store")
    config = ServeConfig(port=0, bridge_port=0, endpoint=EndpointConfig(update_token=TOKEN, workers=workers))
    server = Server(kb, config)
    server.start()
    ports.put((server.http_port, server.bridge_port))
    stop.wait()
    server.stop()
    kb.close()


def percentiles(samples: list[float]) -> str:
    if len(samples) < 2:
        return f"{'-':>8} {'-':>8}"
    cuts = statistics.quantiles(samples, n=20)
    return f"{statistics.median(samples) * 1000:>8.2f} {cuts[18] * 1000:>8.2f}"


def consistency(load: SparqlLoad, base: str) -> str:
    """Torn snapshots and backward steps the readers saw (both must be 0), and whether the store holds
    exactly the batches the writer was told were committed."""
    final = httpx.post(
        base + "/sparql",
        content=BATCH_QUERY.encode("utf-8"),
        headers={"Content-Type": "application/sparql-query", "Accept": "application/sparql-results+json"},
        timeout=WAIT,
    )
    count, _ = batches_seen(final.json())
    torn = sum(count != load.batch * (last + 1) for seen in load.counts for count, last in seen)
    backwards = sum(later < earlier for seen in load.counts for (earlier, _), (later, _) in pairwise(seen))
    stable = len({answer for answers in load.stable for answer in answers})
    whole = "yes" if count == load.batch * load.committed else "NO"
    return (
        f"torn {torn}, backwards {backwards}, distinct answers to the untouched query {stable}, "
        f"final count {count} = {load.batch} x {load.committed} committed: {whole}"
    )


def report_sparql(workers: int, load: SparqlLoad) -> None:
    answered = len(load.read_latencies)
    print(
        f"{workers:>7} {len(load.counts):>7} {answered / load.seconds:>9.0f} {load.busy / load.seconds:>7.0f} "
        f"{percentiles(load.read_latencies)} {len(load.update_latencies) / load.seconds:>9.1f} "
        f"{percentiles(load.update_latencies)} {load.committed:>9} {len(load.errors):>6}"
    )


def report_bridge(load: BridgeLoad) -> None:
    owed = [
        sum(n for p, n in enumerate(load.published) if load.publisher_topics[p] in heard)
        for heard in load.subscriber_topics
    ]
    got = [sum(map(len, received.values())) for received in load.received]
    in_order = all(
        arrivals == list(range(len(arrivals))) for received in load.received for arrivals in received.values()
    )
    published = sum(load.published)
    print(f"published {published} messages in {load.seconds:.2f} s: {published / load.seconds:,.0f} messages/s")
    print(f"delivered {sum(got)} of {sum(owed)} owed: {sum(got) / load.seconds:,.0f} deliveries/s")
    print(f"per subscriber (received/owed): {' '.join(f'{g}/{o}' for g, o in zip(got, owed, strict=True))}")
    print(f"every message once, in order per publisher: {'yes' if got == owed and in_order else 'NO'}; ", end="")
    print(f"errors: {len(load.errors)}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=5.0, help="of load per scenario")
    parser.add_argument("--readers", type=int, default=8)
    parser.add_argument("--workers", default="4,8", help="query worker counts, one server each")
    parser.add_argument("--batch", type=int, default=20, help="triples per update")
    parser.add_argument("--publishers", type=int, default=16)
    parser.add_argument("--topics", type=int, default=4)
    parser.add_argument("--subscribers", type=int, default=2, help="per topic, plus one on every topic")
    parser.add_argument("--window", type=int, default=500, help="messages a subscriber may lag before publishers wait")
    args = parser.parse_args()
    print(f"machine: {platform.platform()}, {os.cpu_count()} cores, python {platform.python_version()}")
    print(
        f"inputs: {args.seconds:g} s per run; bundled knowledge base on disk, server in a child process; "
        f"{args.readers} readers + 1 writer ({args.batch} triples per INSERT DATA); {args.publishers} publishers "
        f"on {args.topics} topics, {args.subscribers} subscribers per topic + 1 on all, window {args.window}"
    )
    context = multiprocessing.get_context("spawn")
    print(
        f"\n{'workers':>7} {'readers':>7} {'queries/s':>9} {'busy/s':>7} {'read p50':>8} {'read p95':>8} "
        f"{'updates/s':>9} {'upd p50':>8} {'upd p95':>8} {'committed':>9} {'errors':>6}"
    )
    checks = []
    bridge: BridgeLoad | None = None
    for index, workers in enumerate(int(w) for w in args.workers.split(",")):
        folder = tempfile.mkdtemp(prefix="cbrs-bench-")
        ports: multiprocessing.Queue[tuple[int, int]] = context.Queue()
        stop = context.Event()
        child = context.Process(target=serve, args=(folder, workers, ports, stop), daemon=True)
        child.start()
        try:
            http_port, bridge_port = ports.get(timeout=WAIT)
            base = f"http://127.0.0.1:{http_port}"
            stable = QueryLibrary(query_dir()).get("advertisements").text
            load = sparql_load(base, TOKEN, args.readers, args.seconds, stable, args.batch)
            report_sparql(workers, load)
            checks.append(f"workers {workers}: {consistency(load, base)}")
            if index == 0:
                bridge = bridge_load(
                    f"ws://127.0.0.1:{bridge_port}", args.publishers, args.topics, args.subscribers, args.seconds,
                    args.window,
                )  # fmt: skip
        finally:
            stop.set()
            child.join(WAIT)
            shutil.rmtree(folder, ignore_errors=True)
    print("(latencies in ms; queries/s counts answered queries, busy/s the 503 busy refusals)")
    for line in checks:
        print(line)
    if bridge is not None:
        print(f"\nrosbridge: {args.publishers} publishers, {len(bridge.subscriber_topics)} subscribers")
        report_bridge(bridge)


if __name__ == "__main__":
    main()
