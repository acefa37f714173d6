"""Benchmark: how long one small SPARQL update takes, graph:entailed following it node by node or whole.

Run: python bench/update_latency.py [--owls-tc FOLDER | --bundled-only] [--repeat N] [--json FILE]

On an in-memory store seeded with the bundled files, and (with --owls-tc, default ../shared/owls-tc4 when
it exists) on one that also holds the OWLS-TC services (loaded as `cbrs load --catalog` loads them), it
times ``KnowledgeBase.update`` for:

* a one-triple ``INSERT DATA`` of a new, unaligned statement (a robot's observation), then the
  ``DELETE DATA`` of it;
* the same for an aligned one (``a home:Sensor``, which entails ``a sosa:Sensor``);
* a ``DELETE/INSERT ... WHERE`` changing one such statement, which always takes the whole refresh;
* a one-triple ``INSERT DATA`` (then ``DELETE DATA``) in graph:map (a comment on world:Cup), with the
  semantic map checked as ``KnowledgeBase.update`` checks it and without (``check_map=False``): what the
  check costs an update that touches the map. The rows above touch no map, so they pay nothing for it.

Each data update is timed both ways, in turn (a run of RUN as cbrs runs it, then one as the anchor): as
cbrs runs it, graph:entailed followed node by node (kb/standard_terms.py StandardTerms.prepare/updated)
and no shape check when it names no quad in the graphs kb/shapes.py checks; and as every update ran
before, the anchor: the shape check (checked_update), the store's update, a whole refresh. Also timed:
the store's update alone, and with the shape check. Medians and 90th percentiles of the samples; the
machine, inputs and load average are printed.
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

import pyoxigraph as ox

from cbrs.kb import KnowledgeBase
from cbrs.kb.catalog import Catalogue
from cbrs.kb.namespaces import WORLD, GraphName
from cbrs.kb.shapes import checked_update

DEFAULT_OWLS_TC = Path(__file__).resolve().parents[2] / "shared" / "owls-tc4"
GRAPH = "urn:bench:observations"
RUN = 3
"""Data updates in a row, as a robot's writes come: the first write after a whole refresh costs the
in-memory store more (13 to 40 ms on the OWLS-TC store, then 0.1 ms), which alternating one by one with
the anchor would charge to every followed update."""


def texts(kind: str, n: int) -> tuple[str, str]:
    """The INSERT DATA and DELETE DATA of the n-th statement of ``kind`` (plain or aligned)."""
    statement = (
        f'<urn:bench:obs{n}> <urn:bench:value> "{n}"'
        if kind == "plain"
        else f"<urn:bench:sensor{n}> a <https://w3id.org/cbrs/home#Sensor>"
    )
    return (
        f"INSERT DATA {{ GRAPH <{GRAPH}> {{ {statement} }} }}",
        f"DELETE DATA {{ GRAPH <{GRAPH}> {{ {statement} }} }}",
    )


def map_texts(n: int) -> tuple[str, str]:
    """The INSERT DATA and DELETE DATA of the n-th comment on world:Cup in graph:map."""
    statement = f'<{WORLD}Cup> <http://www.w3.org/2000/01/rdf-schema#comment> "bench {n}"'
    return (
        f"INSERT DATA {{ GRAPH <{GraphName.MAP.iri}> {{ {statement} }} }}",
        f"DELETE DATA {{ GRAPH <{GraphName.MAP.iri}> {{ {statement} }} }}",
    )


def where_text(n: int) -> str:
    """A DELETE/INSERT WHERE moving a sensor's statement to the next number."""
    return (
        f"DELETE {{ GRAPH <{GRAPH}> {{ ?s a home:Sensor }} }}"
        f" INSERT {{ GRAPH <{GRAPH}> {{ <urn:bench:w{n}> a home:Sensor }} }}"
        f" WHERE {{ GRAPH <{GRAPH}> {{ ?s a home:Sensor }} FILTER (STRSTARTS(STR(?s), 'urn:bench:w')) }}"
    )


def whole(kb: KnowledgeBase, text: str) -> None:
    """The update as ``KnowledgeBase.update`` ran it before graph:entailed followed data updates node by
    node: the shape check, the store's update, a whole refresh."""
    with checked_update(kb.store):
        kb.store.update(text)
    kb.refresh_standard_terms()


def shape_checked(kb: KnowledgeBase, text: str) -> None:
    with checked_update(kb.store):
        kb.store.update(text)


def timed(action: Callable[[], object]) -> float:
    start = time.perf_counter()
    action()
    return (time.perf_counter() - start) * 1000


def summary(samples: list[float]) -> dict[str, float]:
    ordered = sorted(samples)
    return {"median_ms": statistics.median(ordered), "p90_ms": ordered[int(0.9 * (len(ordered) - 1))]}


def measure(kb: KnowledgeBase, repeat: int) -> dict[str, dict[str, float]]:
    """Per-update times on ``kb``: in each repeat and for each kind, a run of :data:`RUN` data updates as
    cbrs follows them, then one as before (whole); then the store alone, the shape check, a WHERE update."""
    kb.refresh_standard_terms()  # graph:entailed known exact, as after the first update of a process
    samples: dict[str, list[float]] = {}
    n = 0

    def sample(label: str, action: Callable[[], object]) -> None:
        samples.setdefault(label, []).append(timed(action))

    for _ in range(repeat):
        for kind in ("plain", "aligned"):
            for _ in range(RUN):
                n += 1
                insert, delete = texts(kind, n)
                sample(f"{kind} INSERT DATA, followed", lambda: kb.update(insert))  # noqa: B023
                sample(f"{kind} DELETE DATA, followed", lambda: kb.update(delete))  # noqa: B023
            if kind == "plain":
                n += 1
                insert, delete = texts("plain", n)
                sample("plain INSERT DATA, store alone", lambda: kb.store.update(insert))  # noqa: B023
                sample("plain DELETE DATA, store alone", lambda: kb.store.update(delete))  # noqa: B023
                n += 1
                insert, delete = texts("plain", n)
                sample("plain INSERT DATA, store + shape check", lambda: shape_checked(kb, insert))  # noqa: B023
                sample("plain DELETE DATA, store + shape check", lambda: shape_checked(kb, delete))  # noqa: B023
            n += 1
            insert, delete = texts(kind, n)
            sample(f"{kind} INSERT DATA, whole", lambda: whole(kb, insert))  # noqa: B023
            sample(f"{kind} DELETE DATA, whole", lambda: whole(kb, delete))  # noqa: B023
        sample("DELETE/INSERT WHERE (whole)", lambda: kb.update(where_text(n)))  # noqa: B023
        for checked in (True, False):
            n += 1
            insert, delete = map_texts(n)
            how = "map checked" if checked else "check_map=False"
            sample(f"map INSERT DATA, {how}", lambda: kb.update(insert, check_map=checked))  # noqa: B023
            sample(f"map DELETE DATA, {how}", lambda: kb.update(delete, check_map=checked))  # noqa: B023
    entailed = set(kb.store.quads(graph=GraphName.ENTAILED.node))
    kb.refresh_standard_terms()
    assert entailed == set(kb.store.quads(graph=GraphName.ENTAILED.node)), "graph:entailed drifted from a whole refresh"
    return {name: summary(values) for name, values in samples.items()}


def report(rows: dict[str, dict[str, object]], name: str, kb: KnowledgeBase, repeat: int) -> None:
    quads = kb.store.count()
    entailed = kb.store.count(GraphName.ENTAILED)
    services = kb.store.count(GraphName.SERVICES)
    results = measure(kb, repeat)
    rows[name] = {"quads": quads, "entailed": entailed, "services_quads": services, **results}
    print(f"\n{name}: {quads} quads, {services} in graph:services, {entailed} in graph:entailed")
    print(f"  {'update':<42} {'median ms':>10} {'p90 ms':>8}")
    for label, figures in results.items():
        print(f"  {label:<42} {figures['median_ms']:>10.2f} {figures['p90_ms']:>8.2f}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--owls-tc", type=Path, default=DEFAULT_OWLS_TC if DEFAULT_OWLS_TC.is_dir() else None)
    parser.add_argument("--bundled-only", action="store_true", help="leave the OWLS-TC store out")
    parser.add_argument("--repeat", type=int, default=20)
    parser.add_argument("--json", type=Path)
    args = parser.parse_args()
    print(
        f"machine: {platform.machine()} {platform.system()} {platform.release()}, {os.cpu_count()} cores, "
        f"python {platform.python_version()}, pyoxigraph {ox.__version__}; load average at start "
        f"{' '.join(f'{x:.2f}' for x in os.getloadavg())}; repeat {args.repeat}"
    )
    rows: dict[str, dict[str, object]] = {}
    report(rows, "bundled", KnowledgeBase.open(":memory:"), args.repeat)  # before the large store exists
    if args.owls_tc is not None and not args.bundled_only:
        big = KnowledgeBase.open(":memory:")
        start = time.perf_counter()
        big.load([args.owls_tc / "services"], catalogue=Catalogue.open(args.owls_tc / "ontology"))
        print(f"\nOWLS-TC services from {args.owls_tc} loaded in {time.perf_counter() - start:.0f} s")
        report(rows, "owls-tc", big, args.repeat)
    print(f"\nload average at end {' '.join(f'{x:.2f}' for x in os.getloadavg())}")
    if args.json:
        args.json.write_text(json.dumps(rows, indent=2), encoding="utf-8")


if __name__ == "__main__":
    sys.exit(main())
