"""Benchmark: query response time over an OWLS-TC collection, once it is loaded.

Loads the collection (default ../shared/owls-tc4) into an in-memory store, prepares each matcher
(reads the service pool, lays it out), then times Matchmaker.rank by requirement IRI for every
request: reading the request from the store, scoring and ordering the whole pool.

Run: python bench/owls_tc.py [FOLDER] [--method sem-str] [--repeat 3]
(default: sem-str, the paper's method on IO/PE alone, and sem-str-text, the hybrid with text)
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import time
from pathlib import Path

from cbrs.reasoner.matchmaker import Matchmaker
from cbrs.reasoner.methods import METHODS
from cbrs.reasoner.owlstc import load_collection

DEFAULT = Path(__file__).resolve().parents[2] / "shared" / "owls-tc4"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("folder", nargs="?", type=Path, default=DEFAULT)
    parser.add_argument(
        "--method", action="append", choices=METHODS, help="repeatable; default sem-str and sem-str-text"
    )
    parser.add_argument("--repeat", type=int, default=3, help="passes over the requests (the first is cold)")
    args = parser.parse_args()
    print(
        f"machine: {platform.machine()} {platform.system()}, {os.cpu_count()} cores, python {platform.python_version()}"
    )
    loaded = load_collection(args.folder)
    requests = [iri for iris in loaded.requirements.values() for iri in iris]
    print(
        f"inputs: {args.folder}: {sum(map(len, loaded.advertisements.values()))} services, {len(requests)} "
        f"requests, loaded in {loaded.seconds:.1f} s"
    )
    for method in args.method or ["sem-str", "sem-str-text"]:
        start = time.perf_counter()
        matcher = Matchmaker(loaded.kb, method).prepare()
        prepared = time.perf_counter() - start
        passes = []
        for _ in range(args.repeat):
            samples = []
            for iri in requests:
                begin = time.perf_counter()
                matcher.rank(iri, explain=0)
                samples.append((time.perf_counter() - begin) * 1000)
            passes.append(samples)
        first, rest = passes[0], [s for p in passes[1:] for s in p]
        line = f"{method}: prepare {prepared:.1f} s; first pass mean {statistics.fmean(first):.2f} ms"
        if rest:
            line += f"; later passes mean {statistics.fmean(rest):.2f} ms, p50 {statistics.median(rest):.2f} ms"
        print(line)


if __name__ == "__main__":
    main()
