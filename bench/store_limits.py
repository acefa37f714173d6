"""Benchmark: cbrs at the store's own limit, side by side with Oxigraph's own server and loader (issue 18).

Run: python bench/store_limits.py [--quick] [--triples N] [--seconds S] [--clients 1,4,8] [--rounds 3]
[--repeat 5] [--rows load,serve,lookups,memory]
[--cbrs-from DIR] [--json FILE]

One run does every row against its anchor, on the same data and the same machine:

- a seeded script writes N triples of N-Triples (``generate``: 10 triples per entity, a type, a label,
  a number and 7 links to other entities), the same file every time for the same N and seed;
- ``cbrs load`` of it into a named graph of a freshly seeded store, against ``oxigraph load --graph``
  into an empty store: triples per second and the size of the store directory afterwards;
- both stores served (``cbrs serve`` and ``oxigraph serve --union-default-graph``, each holding the big
  graph and cbrs's bundled data), then point lookups (``SELECT ?p ?o WHERE { <entity> ?p ?o }`` for a
  seeded random entity, JSON results) from 1, 4 and 8 client processes with one kept-alive HTTP
  connection each (from a loopback address of its own), S seconds a turn, the servers in turns, the
  median of ``--rounds`` turns: queries per second and the 99th percentile of the latency; the turns
  start once both servers are idle (``Served.settle``: ``cbrs serve`` reads what its pages need in the
  background for its first seconds on a big store), so the rows are the steady rate;
- heavy queries (aggregates over the whole store), one at a time: the median time of each;
- the memory of an idle ``cbrs serve`` over the bundled data after it answered a point lookup and a
  heavy query: resident and proportional set size of its whole process tree (query workers included),
  next to ``oxigraph serve`` over the same data.

The load generator runs on the same cores as the server, so both servers share them with it. Prints the
machine (with its load average), the inputs, both figures and the ratio of each row; ``--json FILE``
writes the rows as records ``{row, value, anchor, ratio, unit, goal, met}``.
"""

from __future__ import annotations

import argparse
import http.client
import itertools
import json
import multiprocessing
import os
import platform
import random
import shutil
import socket
import statistics
import subprocess
import sys
import tempfile
import time
import urllib.parse
from pathlib import Path
from typing import Any

PYTHON = sys.executable
NS = "http://example.org/bench/"
GRAPH = "urn:cbrs:bench:data"
JSON_RESULTS = "application/sparql-results+json"
HEAVY = {
    "count all": "SELECT (COUNT(*) AS ?n) WHERE { ?s ?p ?o }",
    "entities per kind": f"SELECT ?kind (COUNT(?s) AS ?n) WHERE {{ ?s a ?kind FILTER(STRSTARTS(STR(?kind), '{NS}')) }} "
    "GROUP BY ?kind ORDER BY ?kind",
    "mean and max value": f"SELECT (AVG(?v) AS ?mean) (MAX(?v) AS ?top) WHERE {{ ?s <{NS}value> ?v }}",
    "links per predicate": f"SELECT ?p (COUNT(*) AS ?n) WHERE {{ ?s ?p ?o FILTER(STRSTARTS(STR(?p), '{NS}link')) }} "
    "GROUP BY ?p ORDER BY ?p",
}


def generate(path: Path, triples: int, seed: int = 18) -> int:
    """Write ``triples`` distinct N-Triples to ``path`` (10 per entity); returns the number of entities."""
    rng = random.Random(seed)
    entities = max(1, triples // 10)
    kinds = [f"<{NS}Kind{k}>" for k in range(20)]
    written = 0
    with path.open("w", encoding="utf-8") as out:
        index = 0
        while written < triples:
            subject = f"<{NS}e{index}>"
            lines = [
                f"{subject} <http://www.w3.org/1999/02/22-rdf-syntax-ns#type> {kinds[rng.randrange(20)]} .\n",
                f'{subject} <http://www.w3.org/2000/01/rdf-schema#label> "entity {index}"@en .\n',
                f'{subject} <{NS}value> "{rng.randrange(1_000_000)}"^^<http://www.w3.org/2001/XMLSchema#integer> .\n',
            ]
            lines += [f"{subject} <{NS}link{k}> <{NS}e{rng.randrange(entities)}> .\n" for k in range(7)]
            taken = lines[: triples - written]
            out.writelines(taken)
            written += len(taken)
            index += 1
    return index


# -- processes and HTTP -------------------------------------------------------------------------------


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


def _ask(connection: http.client.HTTPConnection, path: str, query: str) -> bytes:
    connection.request("GET", f"{path}?{urllib.parse.urlencode({'query': query})}", headers={"Accept": JSON_RESULTS})
    response = connection.getresponse()
    body = response.read()
    if response.status != 200:
        raise RuntimeError(f"{path} answered {response.status}: {body[:200]!r}")
    return body


class Served:
    """A server process (cbrs serve or oxigraph serve) and where its SPARQL endpoint is."""

    def __init__(self, label: str, argv: list[str], port: int, path: str, source: Path | None = None) -> None:
        self.label, self.port, self.path = label, port, path
        env, cwd = None, None
        if source is not None:  # cbrs from there: first on the path, and the working directory (python -m
            # and -c put the working directory before PYTHONPATH, so the checkout run from would win)
            env, cwd = {**os.environ, "PYTHONPATH": str(source)}, source
        self.process = subprocess.Popen(argv, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env, cwd=cwd)
        deadline = time.monotonic() + 120
        while True:
            try:
                with socket.create_connection(("127.0.0.1", port), timeout=1):
                    pass
                connection = http.client.HTTPConnection("127.0.0.1", port, timeout=30)
                _ask(connection, path, "ASK {}")
                connection.close()
                return
            except (OSError, RuntimeError, http.client.HTTPException):
                if self.process.poll() is not None or time.monotonic() > deadline:
                    raise RuntimeError(f"{label} did not start ({argv})") from None
                time.sleep(0.05)

    def settle(self, idle: float = 0.05, most: float = 120.0) -> float:
        """Wait until the server's process used less than ``idle`` of a core over a second (at most
        ``most`` seconds); returns the seconds waited. ``cbrs serve`` over a big store reads what its
        first pages need in a background thread once it answers (``cbrs.web.warmup``: 17-23 s of a core
        on 1M triples), and lookups measured meanwhile are the first seconds', not the steady rate."""
        start = time.monotonic()
        clock = os.sysconf("SC_CLK_TCK")

        def used() -> float:
            fields = Path(f"/proc/{self.process.pid}/stat").read_text().rsplit(")", 1)[1].split()
            return (int(fields[11]) + int(fields[12])) / clock

        while time.monotonic() - start < most:
            before = used()
            time.sleep(1.0)
            if used() - before < idle:
                break
        return time.monotonic() - start

    def stop(self) -> None:
        self.process.terminate()
        try:
            self.process.wait(15)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()


def serve_cbrs(store: Path, source: Path | None = None) -> Served:
    """``cbrs serve`` over ``store`` (an absolute path); with ``source``, the cbrs package in that
    directory (another version), so two versions can be measured side by side in one run."""
    port = _free_port()
    argv = [PYTHON, "-m", "cbrs", "--store", str(store), "serve", "--port", str(port), "--bridge-port", "0"]
    return Served("cbrs serve" if source is None else f"cbrs serve ({source})", argv, port, "/sparql", source)


def serve_oxigraph(oxigraph: str, location: Path) -> Served:
    port = _free_port()
    argv = [oxigraph, "serve", "--location", str(location), "--bind", f"127.0.0.1:{port}", "--union-default-graph"]
    return Served("oxigraph serve", argv, port, "/query")


# -- rows ---------------------------------------------------------------------------------------------


def _client(port: int, path: str, entities: int, seed: int, warm: float, seconds: float, out: Any) -> None:
    """One client process: point lookups on one kept-alive connection; sends back its latencies."""
    rng = random.Random(seed)
    # each client from an address of its own, as robots are: cbrs shares its query workers per address
    source = (f"127.0.0.{10 + seed % 200}", 0)
    connection = http.client.HTTPConnection("127.0.0.1", port, timeout=30, source_address=source)
    latencies: list[float] = []
    start = time.perf_counter()
    measuring = start + warm
    end = measuring + seconds
    while True:
        now = time.perf_counter()
        if now >= end:
            break
        query = f"SELECT ?p ?o WHERE {{ <{NS}e{rng.randrange(entities)}> ?p ?o }}"
        _ask(connection, path, query)
        if now >= measuring:
            latencies.append(time.perf_counter() - now)
    connection.close()
    out.send(latencies)
    out.close()


def run_clients(served: Served, entities: int, clients: int, warmup: float, seconds: float) -> list[float]:
    """The latencies (s) of the point lookups ``clients`` processes had answered in ``seconds`` after
    ``warmup`` seconds left out."""
    context = multiprocessing.get_context("fork")
    pipes, processes = [], []
    for index in range(clients):
        receive, send = context.Pipe(duplex=False)
        args = (served.port, served.path, entities, index, warmup, seconds, send)
        process = context.Process(target=_client, args=args)
        process.start()
        pipes.append(receive)
        processes.append(process)
    latencies = [x for pipe in pipes for x in pipe.recv()]
    for process in processes:
        process.join()
    return latencies


def point_lookups(served: Served, entities: int, clients: int, seconds: float) -> tuple[float, float]:
    """Queries per second and p99 latency (ms) of ``clients`` processes sending point lookups."""
    latencies = sorted(run_clients(served, entities, clients, 0.5, seconds))
    return len(latencies) / seconds, latencies[min(len(latencies) - 1, int(len(latencies) * 0.99))] * 1000


def heavy_query(served: Served, query: str, repeat: int) -> float:
    """The median seconds of ``query``, asked one at a time (after one unmeasured run)."""
    connection = http.client.HTTPConnection("127.0.0.1", served.port, timeout=300)
    _ask(connection, served.path, query)
    samples = []
    for _ in range(repeat):
        start = time.perf_counter()
        _ask(connection, served.path, query)
        samples.append(time.perf_counter() - start)
    connection.close()
    return statistics.median(samples)


def tree_memory(pid: int) -> tuple[float, float, int]:
    """Resident and proportional set size (MB) of ``pid`` and all its descendants, and how many processes."""
    pids, pending = [], [pid]
    while pending:
        current = pending.pop()
        pids.append(current)
        for task in Path(f"/proc/{current}/task").glob("*"):  # a child belongs to the thread that started it
            try:
                pending.extend(int(child) for child in (task / "children").read_text().split())
            except OSError:
                continue
    rss = pss = 0
    for current in pids:
        try:
            for line in Path(f"/proc/{current}/smaps_rollup").read_text().splitlines():
                if line.startswith("Rss:"):
                    rss += int(line.split()[1])
                elif line.startswith("Pss:"):
                    pss += int(line.split()[1])
        except OSError:
            continue
    return rss / 1024, pss / 1024, len(pids)


def du(path: Path) -> float:
    """Megabytes of the files under ``path``."""
    return sum(f.stat().st_size for f in path.rglob("*") if f.is_file()) / 1e6


def _timed(argv: list[str]) -> float:
    start = time.perf_counter()
    subprocess.run(argv, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return time.perf_counter() - start


# -- the run ------------------------------------------------------------------------------------------


class Rows:
    """The records of a run, printed as they come."""

    def __init__(self) -> None:
        self.records: list[dict[str, Any]] = []

    def add(self, row: str, value: float, anchor: float | None, unit: str, goal: str) -> None:
        ratio = value / anchor if anchor else None
        limit = float(goal.split()[1].rstrip("x"))
        measure = ratio if goal.endswith("x") else value
        met = measure is not None and (measure >= limit if goal.startswith(">=") else measure <= limit)
        self.records.append(
            {"row": row, "value": round(value, 4), "anchor": None if anchor is None else round(anchor, 4),
             "ratio": None if ratio is None else round(ratio, 3), "unit": unit, "goal": goal, "met": met}
        )  # fmt: skip
        shown_anchor = "" if anchor is None else f"{anchor:12.4g}"
        shown_ratio = "" if ratio is None else f"{ratio:6.2f}x"
        verdict = "met" if met else "NOT met"
        print(f"  {row:<46} {value:12.4g} {shown_anchor:>12} {shown_ratio:>7}  {unit:<10} {goal:<9} {verdict}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--triples", type=int, default=1_000_000, help="size of the generated data set")
    parser.add_argument("--seconds", type=float, default=5.0, help="seconds of one turn of point lookups")
    parser.add_argument("--clients", default="1,4,8", help="client processes, comma-separated")
    parser.add_argument("--repeat", type=int, default=5, help="runs of each heavy query (median taken)")
    parser.add_argument("--rounds", type=int, default=3, help="turns of each server per client count (median)")
    parser.add_argument("--quick", action="store_true", help="200,000 triples, 2 s turns, 3 repeats")
    parser.add_argument("--oxigraph", default=shutil.which("oxigraph") or str(Path(PYTHON).parent / "oxigraph"))
    parser.add_argument(
        "--rows",
        default="load,serve,memory",
        help="which rows to run, comma-separated (lookups: the point lookups without the heavy queries)",
    )
    parser.add_argument(
        "--cbrs-from",
        type=Path,
        help="serve cbrs from the cbrs package in this directory (another version) for the serving rows",
    )
    parser.add_argument("--json", type=Path, help="write the rows to FILE as a JSON list of records")
    args = parser.parse_args()
    if args.quick:
        args.triples, args.seconds, args.repeat, args.rounds = 200_000, 2.0, 3, 3
    clients = [int(c) for c in args.clients.split(",")]
    version = subprocess.run([args.oxigraph, "--version"], capture_output=True, text=True, check=True).stdout.strip()
    print(f"machine: {platform.platform()}, {os.cpu_count()} cores, python {platform.python_version()}, "
          f"load average {os.getloadavg()[0]:.2f}")  # fmt: skip
    print(f"anchor: {version} (serve --union-default-graph, load --graph)")
    print(f"inputs: {args.triples} triples; cbrs from {args.cbrs_from or 'this checkout'}; "
          f"point lookups {args.seconds:g} s per client count {clients}; "
          f"heavy queries x{args.repeat}; rows {args.rows}")  # fmt: skip
    wanted = set(args.rows.split(","))
    rows = Rows()
    with tempfile.TemporaryDirectory(prefix="cbrs-store-limits-") as name:
        folder = Path(name)
        seed = folder / "seed.nq"
        _seed_dump(seed)
        print(f"\n  {'row':<46} {'cbrs':>12} {'anchor':>12} {'ratio':>7}  {'unit':<10} {'goal':<9}")
        if wanted & {"load", "serve", "lookups"}:
            cbrs_store, ox_store, entities = _load_rows(rows, args, folder, "load" in wanted)
            _oxigraph_load(args.oxigraph, ox_store, seed)  # the bundled data too: both stores hold the same
            if wanted & {"serve", "lookups"}:
                _serving_rows(rows, args, cbrs_store, ox_store, entities, clients, heavy="serve" in wanted)
        if "memory" in wanted:
            _memory_rows(rows, args, folder, seed)
    if args.json is not None:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        args.json.write_text(json.dumps(rows.records, indent=2) + "\n")
        print(f"\nwritten to {args.json}")


def _load_rows(rows: Rows, args: Any, folder: Path, report: bool) -> tuple[Path, Path, int]:
    """Generate the data, load it both ways; the two stores and the number of entities."""
    data = folder / "data.nt"
    entities = generate(data, args.triples)
    size = data.stat().st_size / 1e6
    print(f"  data: {args.triples} triples, {size:.0f} MB of N-Triples, {entities} entities, seed 18")
    cbrs_store, ox_store = folder / "cbrs", folder / "oxigraph"
    _cbrs(["--store", str(cbrs_store), "init"])  # seeded first: the load is timed on its own
    cbrs_load = _timed([PYTHON, "-m", "cbrs", "--store", str(cbrs_store), "load", str(data), "--graph", GRAPH])
    ox_load = _timed([args.oxigraph, "load", "--location", str(ox_store), "--file", str(data), "--graph", GRAPH])
    if report:
        rows.add("cbrs load, triples/s", args.triples / cbrs_load, args.triples / ox_load, "triples/s", ">= 0.5x")
        rows.add("store size on disk after the load", du(cbrs_store), du(ox_store), "MB", "<= 1.5x")
    data.unlink()
    return cbrs_store, ox_store, entities


def _cbrs(argv: list[str]) -> None:
    subprocess.run([PYTHON, "-m", "cbrs", *argv], check=True, stdout=subprocess.DEVNULL)


def _oxigraph_load(oxigraph: str, location: Path, data: Path) -> None:
    subprocess.run(
        [oxigraph, "load", "--location", str(location), "--file", str(data)], check=True, capture_output=True
    )


def _seed_dump(path: Path) -> None:
    from cbrs.kb import KnowledgeBase

    kb = KnowledgeBase.open(":memory:")
    path.write_bytes(kb.store.dump())
    kb.close()


def _serving_rows(
    rows: Rows, args: Any, cbrs_store: Path, ox_store: Path, entities: int, clients: list[int], heavy: bool = True
) -> None:
    """Both servers up at once, measured in turns (ABBA...) so that a change in the machine's other load
    falls on both alike; each figure is the median of ``args.rounds`` turns. The heavy queries' row
    too unless ``heavy`` is false (``--rows lookups``: the point lookups alone)."""
    rates: dict[tuple[str, int], float] = {}
    p99: dict[tuple[str, int], float] = {}
    timings: dict[str, dict[str, float]] = {"cbrs": {}, "oxigraph": {}}
    servers = {"cbrs": serve_cbrs(cbrs_store, args.cbrs_from)}
    try:
        servers["oxigraph"] = serve_oxigraph(args.oxigraph, ox_store)
        settled = {label: served.settle() for label, served in servers.items()}
        print(f"  servers idle after start: cbrs {settled['cbrs']:.1f} s, oxigraph {settled['oxigraph']:.1f} s "
              "(the steady rate is measured from then)")  # fmt: skip
        for count in clients:
            samples: dict[str, list[tuple[float, float]]] = {"cbrs": [], "oxigraph": []}
            for turn in range(args.rounds):
                for label in ("cbrs", "oxigraph") if turn % 2 == 0 else ("oxigraph", "cbrs"):
                    samples[label].append(point_lookups(servers[label], entities, count, args.seconds))
            for label, taken in samples.items():
                rates[label, count] = statistics.median(rate for rate, _ in taken)
                p99[label, count] = statistics.median(latency for _, latency in taken)
        for name, query in HEAVY.items() if heavy else ():
            for label, served in servers.items():
                timings[label][name] = heavy_query(served, query, args.repeat)
    finally:
        for served in servers.values():
            served.stop()
    for count in clients:
        rows.add(f"point lookups, {count} client{'s' if count > 1 else ''}, queries/s", rates["cbrs", count],
                 rates["oxigraph", count], "queries/s", ">= 0.8x")  # fmt: skip
    for count in clients:
        rows.add(f"point lookups p99 latency, {count} client{'s' if count > 1 else ''}", p99["cbrs", count],
                 p99["oxigraph", count], "ms", "<= 2x")  # fmt: skip
    if len(clients) > 1:
        more = all(rates["cbrs", b] > rates["cbrs", a] for a, b in itertools.pairwise(clients))
        shown = {label: ", ".join(f"{rates[label, c]:.0f}" for c in clients) for label in ("cbrs", "oxigraph")}
        print(f"  more clients, more queries/s (cbrs): {more} ({shown['cbrs']}; oxigraph {shown['oxigraph']})")
    if not heavy:
        return
    for name in HEAVY:
        ours, theirs = timings["cbrs"][name] * 1000, timings["oxigraph"][name] * 1000
        print(f"  heavy: {name:<28} cbrs {ours:8.1f} ms   oxigraph {theirs:8.1f} ms")
    total_cbrs, total_ox = sum(timings["cbrs"].values()), sum(timings["oxigraph"].values())
    rows.add("heavy queries (aggregates), queries/s", len(HEAVY) / total_cbrs, len(HEAVY) / total_ox, "queries/s",
             ">= 0.95x")  # fmt: skip


def _memory_rows(rows: Rows, args: Any, folder: Path, seed: Path) -> None:
    """Memory of each server's process tree over the bundled data: 2 s after a point lookup and a heavy
    query, and (cbrs) once its idle query worker has been stopped, ``query_worker_idle`` later."""
    from cbrs.settings import setting

    store, ox_store = folder / "idle-cbrs", folder / "idle-oxigraph"
    _cbrs(["--store", str(store), "init"])
    _oxigraph_load(args.oxigraph, ox_store, seed)
    idle = setting("query_worker_idle").resolve()
    figures: dict[str, tuple[float, float, int]] = {}
    for label, start in (
        ("cbrs", lambda: serve_cbrs(store)),
        ("oxigraph", lambda: serve_oxigraph(args.oxigraph, ox_store)),
    ):
        served: Served = start()  # type: ignore[no-untyped-call]
        try:
            connection = http.client.HTTPConnection("127.0.0.1", served.port, timeout=60)
            _ask(connection, served.path, "SELECT ?p ?o WHERE { <https://w3id.org/cbrs/home#Cup> ?p ?o }")
            _ask(connection, served.path, "SELECT ?p (COUNT(*) AS ?n) WHERE { ?s ?p ?o } GROUP BY ?p")
            connection.close()
            time.sleep(2.0)
            figures[label] = tree_memory(served.process.pid)
            if label == "cbrs":
                time.sleep(idle + 1.0)
                figures["cbrs idle"] = tree_memory(served.process.pid)
        finally:
            served.stop()
    for label, (rss, pss, count) in figures.items():
        print(f"  memory, {label:<9}: {count} process(es), RSS {rss:6.1f} MB, PSS {pss:6.1f} MB")
    anchor = figures["oxigraph"][0]
    rows.add("server memory after a heavy query (RSS, tree)", figures["cbrs"][0], anchor, "MB", "<= 100")
    rows.add(f"server memory at idle, {idle:g} s later (RSS, tree)", figures["cbrs idle"][0], anchor, "MB", "<= 100")


if __name__ == "__main__":
    main()
