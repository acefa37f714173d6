"""Benchmark: what materialising the standard terms (graph:entailed, kb/standard_terms.py) costs.

Run: python bench/standard_terms.py [--owls-tc FOLDER] [--repeat N] [--json FILE]. On an in-memory store
seeded with the bundled files, and (with --owls-tc, default ../shared/owls-tc4 when it exists) on one
that also holds the OWLS-TC services, it measures: the triples graph:entailed holds against the rest;
a whole refresh; a registration followed by a deregistration, with the incremental update of
graph:entailed and without it (the anchor, measured in the same run); and seeding with and without the
refresh. Medians of --repeat runs.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import time
from pathlib import Path

import pyoxigraph as ox
from timing import median_ms

from cbrs.kb import KnowledgeBase, Store
from cbrs.kb.namespaces import GraphName
from cbrs.kb.registry import ComponentRegistry
from cbrs.kb.standard_terms import PendingUpdate, StandardTerms

DEFAULT_OWLS_TC = Path(__file__).resolve().parents[2] / "shared" / "owls-tc4"
CAMERA = "https://w3id.org/cbrs/service#BenchCamera"
REGISTRATION = f"""@prefix cbrs: <https://w3id.org/cbrs/core#> . @prefix home: <https://w3id.org/cbrs/home#> .
<{CAMERA}> a cbrs:DynamicPerceptionComponent ;
    cbrs:device <https://w3id.org/cbrs/service#CeilingCamera02> ;
    cbrs:deviceName "CeilingCamera02" ; cbrs:serviceName "LocateMobileRobot" ;
    cbrs:hasOWLSModel [ a cbrs:OWLSModel ;
        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterType home:MarkerColour ] ;
        cbrs:hasOutput [ a cbrs:Parameter ; cbrs:parameterType home:RobotLocation ] ] ;
    cbrs:hasQoSModel [ a cbrs:QoSModel ; cbrs:updateRate 5.0 ] .
"""


class _NoTerms(StandardTerms):
    """A StandardTerms that does nothing: the registry's work without the incremental update."""

    def begin(self) -> frozenset[ox.Quad]:
        return frozenset()

    def changed(self, before: object, removed: object, added: object) -> object:  # type: ignore[override]
        return None


def measure(kb: KnowledgeBase, repeat: int) -> dict[str, float]:
    store = kb.store
    entailed = store.count(GraphName.ENTAILED)
    terms = StandardTerms(store)

    def round_trip(registry: ComponentRegistry) -> None:
        registry.register(REGISTRATION)
        registry.deregister(CAMERA)

    return {
        "quads_other_graphs": store.count() - entailed,
        "quads_entailed": entailed,
        "refresh_ms": median_ms(terms.refresh, repeat),
        "register_deregister_ms": median_ms(lambda: round_trip(kb.registry), repeat),
        "register_deregister_without_ms": median_ms(
            lambda: round_trip(ComponentRegistry(store, _NoTerms(store))), repeat
        ),
    }


class _NoEntailment(KnowledgeBase):
    """A KnowledgeBase whose writes leave graph:entailed alone: the seed's work without the refresh."""

    def _entail(self, update: PendingUpdate | None = None) -> None:
        pass


def seed_ms(repeat: int) -> tuple[float, float]:
    plain = median_ms(lambda: _NoEntailment(Store.open(":memory:")).seed(), repeat)
    with_terms = median_ms(lambda: KnowledgeBase(Store.open(":memory:")).seed(), repeat)
    return plain, with_terms


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--owls-tc", type=Path, default=DEFAULT_OWLS_TC if DEFAULT_OWLS_TC.is_dir() else None)
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--json", type=Path)
    args = parser.parse_args()
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print(
        f"machine: {platform.machine()} {platform.system()} {platform.release()}, {os.cpu_count()} cores "
        f"(load {load:.1f}), python {platform.python_version()}, pyoxigraph {ox.__version__}; "
        f"repeat {args.repeat}, median"
    )
    rows = {}
    plain, with_terms = seed_ms(args.repeat)
    rows["seed"] = {"without_ms": plain, "with_ms": with_terms}
    kb = KnowledgeBase.open(":memory:")
    rows["bundled"] = measure(kb, args.repeat)
    if args.owls_tc is not None:
        start = time.perf_counter()
        kb.load([args.owls_tc / "services"], catalogue=args.owls_tc / "ontology")
        rows["owls-tc"] = {"load_s": time.perf_counter() - start, **measure(kb, args.repeat)}
    print(f"seed the bundled files: {plain:.0f} ms without graph:entailed, {with_terms:.0f} ms with it")
    print(
        f"{'store':<10} {'quads':>8} {'entailed':>9} {'refresh ms':>11} {'reg+dereg ms':>13} "
        f"{'without ms':>11} {'ratio':>6}"
    )
    for name in ("bundled", "owls-tc"):
        if name in rows:
            r = rows[name]
            ratio = r["register_deregister_ms"] / r["register_deregister_without_ms"]
            print(
                f"{name:<10} {r['quads_other_graphs']:>8.0f} {r['quads_entailed']:>9.0f} {r['refresh_ms']:>11.1f} "
                f"{r['register_deregister_ms']:>13.1f} {r['register_deregister_without_ms']:>11.1f} {ratio:>6.1f}"
            )
    if args.json:
        args.json.write_text(json.dumps(rows, indent=2), encoding="utf-8")


if __name__ == "__main__":
    main()
