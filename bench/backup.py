"""Benchmark: cbrs export and cbrs restore (kb/backup.py) on a seeded store and on one holding OWLS-TC 4.

Run: python bench/backup.py [--owls-tc DIR] [--on-disk] [--url http://127.0.0.1:7878] [--repeat N]. Times
export to N-Quads, TriG and gzipped N-Quads, reading the file back, and the restore's write, on an embedded
store (in memory, or a directory with --on-disk) and, with --url, on a running Oxigraph server (its cbrs
graphs are replaced). With --owls-tc the collection is loaded first (its services and ontologies, about
143,000 more triples), as a lab's long-kept store would hold.
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
import tempfile
from pathlib import Path

import pyoxigraph as ox
from timing import median_ms

from cbrs.kb import KnowledgeBase
from cbrs.kb.backup import read_backup
from cbrs.kb.catalog import Catalogue


def measure(kb: KnowledgeBase, folder: Path, repeat: int) -> None:
    triples = kb.store.count() if kb.store.__class__.__name__ == "EmbeddedStore" else "-"
    print(f"\nstore: {kb.store.location} ({triples} quads)")
    print(f"{'operation':<36} {'p50 ms':>10}  size")
    for name in ("store.nq", "store.trig", "store.nq.gz"):
        path = folder / name
        elapsed = median_ms(lambda path=path: kb.export(path), repeat)
        print(f"{'export ' + name:<36} {elapsed:>10.1f}  {path.stat().st_size / 1e6:.1f} MB")
    path = folder / "store.nq"
    elapsed = median_ms(lambda: read_backup(path), repeat)
    print(f"{'read store.nq':<36} {elapsed:>10.1f}")
    backup = read_backup(path)
    elapsed = median_ms(lambda: kb.restore(backup), repeat)
    print(f"{'restore store.nq (write)':<36} {elapsed:>10.1f}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--owls-tc", type=Path, help="an OWLS-TC 4 folder to load first")
    parser.add_argument("--on-disk", action="store_true", help="the embedded store in a directory")
    parser.add_argument("--url", help="also a running Oxigraph server (its cbrs graphs are replaced)")
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    print(f"machine: {platform.machine()} {platform.system()}, {os.cpu_count()} cores, python {sys.version.split()[0]}")
    print(f"pyoxigraph {ox.__version__}; repeat {args.repeat}, median")
    with tempfile.TemporaryDirectory() as scratch:
        folder = Path(scratch)
        locations = [str(folder / "store") if args.on_disk else ":memory:"] + ([args.url] if args.url else [])
        for location in locations:
            kb = KnowledgeBase.open(location)
            if args.owls_tc is not None:
                catalogue = Catalogue.open(args.owls_tc / "ontology")
                kb.load([args.owls_tc / "services"], catalogue=catalogue)
            measure(kb, folder, args.repeat)
            kb.close()


if __name__ == "__main__":
    main()
