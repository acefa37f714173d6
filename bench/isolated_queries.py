"""Benchmark: what evaluating ``cbrs query``'s text in a query worker costs, on disk and in memory.

Run: python bench/isolated_queries.py [--repeat N]

Part 1 runs ``cbrs query`` whole (a child process each time, as a person runs it) on the bundled store,
on disk and in memory, with a text that does not sort (evaluated in the command's process) and the same
text with ``ORDER BY`` (evaluated in a query worker, :mod:`cbrs.isolated_queries`), turn about, and prints
the median wall time of each and their ratio. Part 2 splits a worker's cost inside one process: the same
sorting text evaluated in-process and printed (the anchor), evaluated by :class:`IsolatedQueries` (a
worker started, a snapshot taken, the query answered and parsed back, the worker stopped), and the
snapshot alone. Part 3 (``--forms N``) says which forms of query and update abort pyoxigraph over ``N``
random stores of 40 readings, dateTimes some with a time zone and some without, each in a child process
of its own: what decides which texts ``cbrs query`` sends to a worker.
"""

from __future__ import annotations

import argparse
import os
import platform
import random
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pyoxigraph as ox

from cbrs.isolated_queries import IsolatedQueries
from cbrs.kb import KnowledgeBase
from cbrs.kb.store import EmbeddedStore
from cbrs.output import render_result

PLAIN = "SELECT ?c ?label WHERE { ?c a owl:Class ; rdfs:label ?label } LIMIT 20"
SORTED = "SELECT ?c ?label WHERE { ?c a owl:Class ; rdfs:label ?label } ORDER BY ?label LIMIT 20"


def _median_ms(samples: list[float]) -> float:
    return 1000 * statistics.median(samples)


def whole_command(location: str, repeat: int) -> tuple[float, float]:
    """Median seconds of ``cbrs query`` with PLAIN and with SORTED, run turn about."""
    times: dict[str, list[float]] = {PLAIN: [], SORTED: []}
    for _ in range(repeat):
        for text in (PLAIN, SORTED):
            start = time.perf_counter()
            subprocess.run(
                [sys.executable, "-m", "cbrs", "--store", location, "query", text, "--format", "json"],
                check=True,
                capture_output=True,
            )
            times[text].append(time.perf_counter() - start)
    return _median_ms(times[PLAIN]), _median_ms(times[SORTED])


def parts(kb: KnowledgeBase, repeat: int) -> tuple[float, float, float]:
    """Median seconds of SORTED in this process, through a worker, and of a snapshot alone."""
    store = kb.store
    assert isinstance(store, EmbeddedStore)
    inside, isolated, snapshots = [], [], []
    for _ in range(repeat):
        start = time.perf_counter()
        render_result(kb.query(SORTED), "json")
        inside.append(time.perf_counter() - start)
        start = time.perf_counter()
        with IsolatedQueries(store) as queries:
            result = queries.query(SORTED)
            assert isinstance(result, ox.QuerySolutions)
            render_result(result, "json")
        isolated.append(time.perf_counter() - start)
        target = Path(tempfile.mkdtemp(prefix="cbrs-bench-snapshot-")) / "snapshot"
        try:
            start = time.perf_counter()
            store.snapshot(target)  # what a worker's query takes first (cbrs.query_workers)
            snapshots.append(time.perf_counter() - start)
        finally:
            shutil.rmtree(target.parent, ignore_errors=True)
    return _median_ms(inside), _median_ms(isolated), _median_ms(snapshots)


SEEN_AT = "<http://example.org/lab#seenAt>"
FORMS = {
    "ORDER BY ?t": ("query", f"SELECT ?s ?t WHERE {{ ?s {SEEN_AT} ?t }} ORDER BY ?t"),
    "ORDER BY DESC(?t)": ("query", f"SELECT ?s ?t WHERE {{ ?s {SEEN_AT} ?t }} ORDER BY DESC(?t)"),
    "ORDER BY STR(?t)": ("query", f"SELECT ?s ?t WHERE {{ ?s {SEEN_AT} ?t }} ORDER BY STR(?t)"),
    "subquery ORDER BY, LIMIT": ("query", f"SELECT ?t {{ {{ SELECT ?t {{ ?s {SEEN_AT} ?t }} ORDER BY ?t LIMIT 5 }} }}"),
    "subquery ORDER BY": ("query", f"SELECT ?t {{ {{ SELECT ?t {{ ?s {SEEN_AT} ?t }} ORDER BY ?t }} }}"),
    "CONSTRUCT ORDER BY, LIMIT": ("query", f"CONSTRUCT {{ ?s a ?t }} {{ ?s {SEEN_AT} ?t }} ORDER BY ?t LIMIT 5"),
    "MIN and MAX": ("query", f"SELECT (MIN(?t) AS ?a) (MAX(?t) AS ?b) {{ ?s {SEEN_AT} ?t }}"),
    "GROUP BY ?t": ("query", f"SELECT ?t (COUNT(*) AS ?n) {{ ?s {SEEN_AT} ?t }} GROUP BY ?t"),
    "DISTINCT": ("query", f"SELECT DISTINCT ?t {{ ?s {SEEN_AT} ?t }}"),
    "FILTER(?a < ?b)": ("query", f"SELECT ?a ?b {{ ?x {SEEN_AT} ?a . ?y {SEEN_AT} ?b FILTER(?a < ?b) }}"),
    "update, GRAPH ?g, subquery ORDER BY": (
        "update",
        f"INSERT {{ GRAPH <http://e/g> {{ ?s <http://e/first> true }} }} "
        f"WHERE {{ {{ SELECT ?s {{ GRAPH ?g {{ ?s {SEEN_AT} ?t }} }} ORDER BY ?t LIMIT 5 }} }}",
    ),
    "update, default graph, subquery ORDER BY": (
        "update",
        f"INSERT {{ GRAPH <http://e/g> {{ ?s <http://e/first> true }} }} "
        f"WHERE {{ {{ SELECT ?s {{ ?s {SEEN_AT} ?t }} ORDER BY ?t LIMIT 5 }} }}",
    ),
}
_FORM_CHILD = """
import sys, pyoxigraph as ox
store = ox.Store()
store.load(path=sys.argv[1], format=ox.RdfFormat.N_QUADS)
if sys.argv[2] == "update":
    store.update(sys.stdin.read())  # an update's default graph is the default graph, as cbrs runs updates
else:
    list(store.query(sys.stdin.read(), use_default_graph_as_union=True))  # as cbrs runs queries
"""


def forms(stores: int, folder: Path) -> None:
    """Part 3: for each of FORMS, over how many of ``stores`` random stores it aborts a child process."""
    paths = []
    for seed in range(stores):
        pick = random.Random(seed)
        path = folder / f"readings-{seed}.nq"
        path.write_text(
            "".join(
                f'<http://example.org/lab#r{i}> {SEEN_AT} "2020-01-01T{pick.randrange(24):02d}:00:00'
                f'{pick.choice(["", "Z", "+14:00", "-14:00"])}"^^<http://www.w3.org/2001/XMLSchema#dateTime>'
                " <http://example.org/lab#readings> .\n"
                for i in range(40)
            ),
            encoding="utf-8",
        )
        paths.append(path)
    print(f"part 3: forms that abort pyoxigraph, of {stores} random stores of 40 readings")
    for name, (kind, text) in FORMS.items():
        aborted = 0
        for path in paths:
            done = subprocess.run(
                [sys.executable, "-c", _FORM_CHILD, str(path), kind], input=text, text=True, capture_output=True
            )
            aborted += done.returncode != 0 and "total order" in done.stderr
        print(f"  {name:42} {aborted:3d}")
    short = Path(__file__).parent.parent / "tests" / "data" / "engine_faults" / "short_ordering_panic.rq"
    text = short.read_text(encoding="utf-8")
    empty = folder / "empty.nq"
    empty.write_text("", encoding="utf-8")
    done = subprocess.run(
        [sys.executable, "-c", _FORM_CHILD, str(empty), "query"],
        input="PREFIX xsd: <http://www.w3.org/2001/XMLSchema#>\n" + text,
        text=True,
        capture_output=True,
    )
    verdict = "aborts" if done.returncode != 0 and "total order" in done.stderr else "does not abort"
    print(f"  {short.name} ({len(text)} characters) on an empty store: {verdict}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeat", type=int, default=15)
    parser.add_argument("--forms", type=int, default=20, metavar="N", help="random stores for part 3 (0: skip)")
    args = parser.parse_args()
    print(f"{platform.machine()}, {os.cpu_count()} cores, pyoxigraph {ox.__version__}, median of {args.repeat}")
    folder = Path(tempfile.mkdtemp(prefix="cbrs-bench-isolated-"))
    try:
        disk = str(folder / "store")
        KnowledgeBase.open(disk).close()  # seeded once
        print("part 1: cbrs query, whole command (ms)")
        for name, location in (("on disk", disk), (":memory:", ":memory:")):
            plain, ordered = whole_command(location, args.repeat)
            print(f"  {name:9} in-process {plain:7.0f}  in a worker {ordered:7.0f}  ratio {ordered / plain:.2f}")
        print("part 2: one sorting query inside one process (ms)")
        for name, location in (("on disk", disk), (":memory:", ":memory:")):
            kb = KnowledgeBase.open(location)
            try:
                inside, isolated, snapshot = parts(kb, args.repeat)
                quads = kb.store.count()
            finally:
                kb.close()
            print(
                f"  {name:9} {quads} quads: in-process {inside:6.1f}  through a worker {isolated:6.1f}"
                f"  (of which the snapshot {snapshot:6.1f})  ratio {isolated / inside:.0f}"
            )
        if args.forms:
            forms(args.forms, folder)
    finally:
        shutil.rmtree(folder, ignore_errors=True)


if __name__ == "__main__":
    main()
