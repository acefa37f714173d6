"""Benchmark: what keeping graph:entailed up to date costs a write on a remote store, in requests and time.

Run: python bench/standard_terms_remote.py [--repeat N] [--url URL] [--owls-tc FOLDER]. Without --url it
starts ``oxigraph serve --union-default-graph`` in memory on a free loopback port (bench/remote_store.py)
and stops it at the end; with --url it uses that server, which must be empty (a Virtuoso's ``/sparql``).
The store is seeded, then each write is timed as a user's command makes it, with the HTTP requests it sent
counted: a whole refresh of graph:entailed, a load of a small file (loaded again each time: a remote load
always refreshes), a registration and a deregistration, a data update (on a remote store, a whole
refresh). With --owls-tc the OWLS-TC services are loaded (once) and the refresh and the data update
timed again on that store. Medians of --repeat runs; the requests of one run.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import platform
import time
from collections.abc import Callable, Iterator
from pathlib import Path

import pyoxigraph as ox
from remote_store import oxigraph_server
from standard_terms import CAMERA, REGISTRATION  # the same registration as the embedded bench's
from timing import median_ms

from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import GraphName
from cbrs.kb.remote_store import RemoteStore

DATA = Path(__file__).resolve().parents[1] / "tests" / "data"
UPDATE = "INSERT DATA { GRAPH <urn:bench:g> { <urn:bench:s> a home:Sensor } }"


class Requests:
    """Counts the HTTP requests every RemoteStore sends (wraps its one sending method)."""

    def __init__(self) -> None:
        self.sent = 0

    @contextlib.contextmanager
    def counting(self) -> Iterator[None]:
        send = RemoteStore._post

        def counted(store: RemoteStore, *args: object, **kwargs: object) -> object:
            self.sent += 1
            return send(store, *args, **kwargs)  # type: ignore[arg-type]

        RemoteStore._post = counted  # type: ignore[assignment,method-assign]
        try:
            yield
        finally:
            RemoteStore._post = send  # type: ignore[method-assign]

    def of(self, action: Callable[[], object]) -> int:
        before = self.sent
        action()
        return self.sent - before


def measure(kb: KnowledgeBase, repeat: int, requests: Requests, writes: bool) -> dict[str, tuple[int, float]]:
    """Requests of one run and median ms of each write."""
    registry = kb.registry
    actions: dict[str, Callable[[], object]] = {"whole refresh": kb.refresh_standard_terms}
    if writes:
        actions["load a small file (5 triples)"] = lambda: kb.load([DATA / "mini_world.ttl"], graph="world")
        actions["register"] = lambda: registry.register(REGISTRATION)
        actions["deregister"] = lambda: registry.deregister(CAMERA)
    actions["data update (INSERT DATA)"] = lambda: kb.update(UPDATE)
    figures = {}
    for name, action in actions.items():
        if name == "register":
            sent = requests.of(action)
            registry.deregister(CAMERA)
            ms = median_ms(lambda: (registry.register(REGISTRATION), registry.deregister(CAMERA)), repeat)
            figures[name] = (sent, ms)
            continue
        if name == "deregister":
            registry.register(REGISTRATION)
            sent = requests.of(action)
            figures[name] = (sent, figures["register"][1])  # timed with the registration above
            continue
        figures[name] = (requests.of(action), median_ms(action, repeat))
    return figures


def report(title: str, kb: KnowledgeBase, figures: dict[str, tuple[int, float]]) -> None:
    print(f"{title}: {kb.store.count()} quads, {kb.store.count(GraphName.ENTAILED)} in graph:entailed")
    print(f"  {'write':<36} {'requests':>9} {'median ms':>10}")
    for name, (sent, ms) in figures.items():
        shown = "(with register)" if name == "deregister" else f"{ms:.1f}"
        print(f"  {name:<36} {sent:>9} {shown:>10}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--url", help="an empty SPARQL server to use instead of a fresh oxigraph serve")
    parser.add_argument("--owls-tc", type=Path, help="also time the refresh on a store holding OWLS-TC's services")
    args = parser.parse_args()
    load = os.getloadavg() if hasattr(os, "getloadavg") else (float("nan"),) * 3
    print(
        f"machine: {platform.machine()} {platform.system()} {platform.release()}, {os.cpu_count()} cores "
        f"(load {load[0]:.1f} {load[1]:.1f} {load[2]:.1f}), python {platform.python_version()}, "
        f"pyoxigraph {ox.__version__}; repeat {args.repeat}, median"
    )
    requests = Requests()
    with contextlib.ExitStack() as stack:
        url = args.url or stack.enter_context(oxigraph_server(on_disk=False))[0]
        stack.enter_context(requests.counting())
        start = time.perf_counter()
        kb = KnowledgeBase.open(url)
        stack.callback(kb.close)
        seeded = time.perf_counter() - start
        server = kb.store.server if isinstance(kb.store, RemoteStore) else "embedded"
        print(f"server: {url} ({server}); seeded in {seeded:.2f} s, {requests.sent} requests")
        report("bundled", kb, measure(kb, args.repeat, requests, writes=True))
        if args.owls_tc is not None:
            start = time.perf_counter()
            sent = requests.of(lambda: kb.load([args.owls_tc / "services"], catalogue=args.owls_tc / "ontology"))
            print(f"OWLS-TC services loaded in {time.perf_counter() - start:.1f} s, {sent} requests")
            report("owls-tc", kb, measure(kb, max(1, args.repeat // 2), requests, writes=False))
    load = os.getloadavg() if hasattr(os, "getloadavg") else (float("nan"),) * 3
    print(f"load average at the end: {load[0]:.1f} {load[1]:.1f} {load[2]:.1f}")


if __name__ == "__main__":
    main()
