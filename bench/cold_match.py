"""Benchmark: `cbrs match` in a fresh process over an on-disk OWLS-TC store, against the same match in memory.

Run: python bench/cold_match.py [FOLDER] [--requirement IRI] [--method sem-str] [--repeat 3] [--store DIR]
[--json FILE]

The collection (default ../shared/owls-tc4) is loaded twice, as `cbrs load` loads it: its services, then
its requests as requirements, with its ontology/ folder as the catalogue. Once into an on-disk store by
`cbrs --store DIR load` (a temporary directory unless --store names one; an existing one is reused),
once into a `:memory:` store in this process. Then, `repeat` times each:

* cold: `cbrs --store DIR match REQUIREMENT` as a new process, wall time: interpreter start, imports,
  opening the store, reading the advertisements and the taxonomy, ranking, printing;
* anchor: the same command's work in this process on the in-memory store, through a fresh
  KnowledgeBase (nothing cached from the load or an earlier sample): reading, ranking, formatting.

Prints the machine and load average, the inputs, every sample, the medians, their ratio (goal <= 2x)
and whether both printed the same ranking; `--json FILE` writes the row as a list of records.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from importlib.metadata import version
from pathlib import Path
from typing import Any

from cbrs.cli_reasoner import ranking_text
from cbrs.kb import KnowledgeBase
from cbrs.kb.catalog import Catalogue
from cbrs.reasoner.methods import METHODS

DEFAULT = Path(__file__).resolve().parents[2] / "shared" / "owls-tc4"
GOAL = 2.0
"""The cold command may take at most this many times the in-memory work."""


def cbrs(*args: str) -> tuple[float, str]:
    """Run the cbrs command in a new interpreter; its wall time and what it printed."""
    start = time.perf_counter()
    done = subprocess.run([sys.executable, "-m", "cbrs", *args], capture_output=True, text=True, check=False)
    seconds = time.perf_counter() - start
    if done.returncode != 0:
        raise SystemExit(f"cbrs {' '.join(args)} failed ({done.returncode}):\n{done.stderr}")
    return seconds, done.stdout


def load_on_disk(store: Path, folder: Path) -> float:
    catalogue = str(folder / "ontology")
    first, _ = cbrs("--store", str(store), "load", "--catalog", catalogue, str(folder / "services"))
    second, _ = cbrs(
        "--store", str(store), "load", "--graph", "requirements", "--catalog", catalogue, str(folder / "queries")
    )
    return first + second


def load_in_memory(folder: Path) -> tuple[KnowledgeBase, list[str], float]:
    """The collection in a seeded in-memory store, as `cbrs load` puts it; the requests' IRIs, sorted."""
    start = time.perf_counter()
    kb = KnowledgeBase.open(":memory:")
    catalogue = Catalogue.open(folder / "ontology")
    kb.load([folder / "services"], catalogue=catalogue)
    report = kb.load([folder / "queries"], graph="requirements", catalogue=catalogue)
    requests = sorted(service.iri for item in report.files if item.owls is not None for service in item.owls.services)
    return kb, requests, time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("folder", nargs="?", type=Path, default=DEFAULT, help="an OWLS-TC style collection")
    parser.add_argument("--requirement", help="the request to rank for (default: the first request by IRI)")
    parser.add_argument("--method", choices=METHODS, default="sem-str")
    parser.add_argument("--top", type=int, default=10, help="candidates printed (cbrs match --top)")
    parser.add_argument("--repeat", type=int, default=3, help="samples of each")
    parser.add_argument("--store", type=Path, help="keep the on-disk store here (reused if it exists)")
    parser.add_argument("--json", type=Path, help="also write the row to FILE as a list of records")
    args = parser.parse_args()

    print(
        f"machine: {platform.platform()}, {os.cpu_count()} cores, python {platform.python_version()}, "
        f"pyoxigraph {version('pyoxigraph')}; load average at start {os.getloadavg()[0]:.2f}"
    )
    kb, requests, memory_load = load_in_memory(args.folder)
    requirement = args.requirement or requests[0]
    temporary = args.store is None
    store = Path(tempfile.mkdtemp(prefix="cold_match_")) / "store" if args.store is None else args.store
    try:
        if store.exists():
            print(f"on-disk store: {store}, reused")
        else:
            print(f"on-disk store: {store}, loaded by cbrs load in {load_on_disk(store, args.folder):.1f} s")
        print(
            f"inputs: {args.folder} ({len(requests)} requests), loaded in memory in {memory_load:.1f} s; "
            f"requirement {requirement}; method {args.method}; top {args.top}; repeat {args.repeat}"
        )
        command = ["--store", str(store), "match", requirement, "--method", args.method, "--top", str(args.top)]
        cold, anchor = [], []
        printed = expected = ""
        for _ in range(args.repeat):
            seconds, printed = cbrs(*command)
            cold.append(seconds)
            start = time.perf_counter()
            expected = ranking_text(KnowledgeBase(kb.store), requirement, args.top, 0, args.method)
            anchor.append(time.perf_counter() - start)
        start_up, _ = cbrs("--help")
    finally:
        if temporary:
            shutil.rmtree(store.parent, ignore_errors=True)

    value, base = statistics.median(cold), statistics.median(anchor)
    ratio = value / base
    print(f"\ncbrs match, new process, on-disk store (s): {' '.join(f'{s:.2f}' for s in cold)}")
    print(f"same work in this process, in-memory store (s): {' '.join(f'{s:.2f}' for s in anchor)}")
    print(f"process start alone (cbrs --help): {start_up:.2f} s")
    print(f"same ranking printed: {'yes' if printed.strip() == expected.strip() else 'NO'}")
    met = ratio <= GOAL
    verdict = "met" if met else "not met"
    print(f"\nmedian {value:.2f} s cold vs {base:.2f} s in memory: {ratio:.2f}x (goal <= {GOAL:g}x: {verdict})")
    print(f"load average at end {os.getloadavg()[0]:.2f}")
    if args.json is not None:
        record: dict[str, Any] = {
            "row": "cbrs match in a fresh process over an on-disk OWLS-TC store vs the same work in memory",
            "value": round(value, 3),
            "anchor": round(base, 3),
            "ratio": round(ratio, 3),
            "unit": "s",
            "goal": f"<= {GOAL:g}x",
            "met": met,
        }
        args.json.write_text(json.dumps([record], indent=2) + "\n", encoding="utf-8")
        print(f"written to {args.json}")


if __name__ == "__main__":
    main()
