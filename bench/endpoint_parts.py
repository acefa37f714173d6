"""Profile: where a point lookup's server CPU goes in cbrs serve, part by part, beside oxigraph serve.

Run: python bench/endpoint_parts.py [--triples 200000] [--clients 4] [--seconds 2.5] [--rounds 5]
[--memory] [--against DIR ...]

Five servers (more with the options) over the same generated data (10 triples per entity), each
its own process, up at once and measured in turns (the order reversed every other round), with point
lookups from C client processes (``store_limits.run_clients``, no warm-up): for each, the median over the
rounds of the queries per second and of the server's CPU per lookup (user + system of the whole
process, from /proc/PID/stat, around the turn, divided by the lookups answered in it):

- ``cbrs serve``, as the command line starts it;
- the same process (Granian embedded, the store open, the bridge up) with the HTTP front replaced by
  a bare ASGI function that unquotes the query and has pyoxigraph evaluate it and write its JSON into
  bytes: Granian and pyoxigraph without cbrs's checks, accounting and budget writer;
- the same written through the endpoint's budget writer (``_BudgetWriter``, which checks the byte
  limit and the deadline as pyoxigraph writes), as ``cbrs serve`` writes a lookup's result;
- the same answering a fixed body of a lookup's size: Granian alone, in the cbrs process;
- ``oxigraph serve --union-default-graph``;
- with ``--memory``, a cbrs server as ``cbrs serve`` makes it over an in-memory store holding the same
  data (a store ``cbrs serve --store :memory:`` cannot be loaded from outside before it serves);
- with ``--against DIR`` (repeatable), each cbrs server also run from the cbrs package in DIR (another
  version, such as ``git archive HEAD~1 | tar -x -C DIR``): a change measured beside what it changes,
  turn by turn in one run.

Each cbrs server has its own copy of the store (an on-disk store admits one process). The load
generator runs on the same cores as the servers. Prints the machine (with its load average), the
inputs and one line per server.
"""

from __future__ import annotations

import argparse
import functools
import os
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import textwrap
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from endpoint_cpu import cpu_seconds
from store_limits import GRAPH, PYTHON, Served, _free_port, generate, run_clients, serve_cbrs, serve_oxigraph

_PART = textwrap.dedent(
    """
    import sys, threading, time
    from urllib.parse import unquote_to_bytes
    import pyoxigraph as ox
    import cbrs.server as server_module
    from cbrs.http_listener import HttpListener
    from cbrs.kb import KnowledgeBase
    from cbrs.server import ServeConfig, Server
    from cbrs.sparql_service import EndpointConfig, _BudgetWriter
    store, port, part = sys.argv[1], int(sys.argv[2]), sys.argv[3]
    kb = KnowledgeBase.open(store)
    backend = kb.store._backend
    JSON = ox.QueryResultsFormat.JSON
    FIXED = b"x" * int(sys.argv[4])
    async def bare(scope, receive, send):
        if part == "pyoxigraph":
            text = unquote_to_bytes(scope["query_string"].partition(b"=")[2].replace(b"+", b" ")).decode()
            body = backend.query(text, use_default_graph_as_union=True).serialize(format=JSON)
        elif part == "writer":  # the same, written through the endpoint's budget writer
            text = unquote_to_bytes(scope["query_string"].partition(b"=")[2].replace(b"+", b" ")).decode()
            writer = _BudgetWriter(1 << 26, time.monotonic() + 30, 30)
            backend.query(text, use_default_graph_as_union=True).serialize(writer, JSON)
            body = writer.getvalue()
        else:
            body = FIXED
        headers = [(b"content-type", b"application/sparql-results+json"), (b"content-length", str(len(body)).encode())]
        await send({"type": "http.response.start", "status": 200, "headers": headers})
        await send({"type": "http.response.body", "body": body})
    server_module.HttpListener = lambda front, config: HttpListener(bare, config)
    config = ServeConfig(port=port, bridge_port=0, endpoint=EndpointConfig(isolate_memory=True))
    Server(kb, config).start()
    threading.Event().wait()
    """
)
_MEMORY = textwrap.dedent(
    """
    import sys, threading
    import pyoxigraph as ox
    from cbrs.kb import KnowledgeBase
    from cbrs.server import ServeConfig, Server
    from cbrs.sparql_service import EndpointConfig
    data, graph, port = sys.argv[1], sys.argv[2], int(sys.argv[3])
    kb = KnowledgeBase.open(":memory:")
    kb.store._backend.bulk_load(path=data, format=ox.RdfFormat.N_TRIPLES, to_graph=ox.NamedNode(graph))
    Server(kb, ServeConfig(port=port, bridge_port=0, endpoint=EndpointConfig(isolate_memory=True))).start()
    threading.Event().wait()
    """
)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--triples", type=int, default=200_000)
    parser.add_argument("--clients", type=int, default=4)
    parser.add_argument("--seconds", type=float, default=2.5)
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--oxigraph", default=str(Path(PYTHON).parent / "oxigraph"))
    parser.add_argument("--memory", action="store_true", help="also serve the data from an in-memory store")
    parser.add_argument("--against", type=Path, action="append",
                        help="a cbrs version (a directory holding cbrs/) to serve beside; may be repeated")  # fmt: skip
    args = parser.parse_args()
    print(f"machine: {platform.platform()}, {os.cpu_count()} cores, python {platform.python_version()}, "
          f"load average {os.getloadavg()[0]:.2f}")  # fmt: skip
    print(f"inputs: {args.triples} generated triples, {args.clients} client processes, "
          f"{args.rounds} turns of {args.seconds:g} s per server")  # fmt: skip
    with tempfile.TemporaryDirectory(prefix="cbrs-endpoint-parts-") as name:
        folder = Path(name)
        data = folder / "data.nt"
        entities = generate(data, args.triples)
        stores = [folder / f"cbrs{i}" for i in range(5)]
        subprocess.run([PYTHON, "-m", "cbrs", "--store", str(stores[0]), "load", str(data), "--graph", GRAPH],
                       check=True, stdout=subprocess.DEVNULL)  # fmt: skip
        for copy in stores[1:]:
            shutil.copytree(stores[0], copy)
        ox_store = folder / "oxigraph"
        subprocess.run([args.oxigraph, "load", "--location", str(ox_store), "--file", str(data), "--graph", GRAPH],
                       check=True, capture_output=True)  # fmt: skip
        size = 1200  # about a lookup's JSON (ten triples)
        starts = {
            "cbrs serve": lambda: serve_cbrs(stores[0]),
            "cbrs process, pyoxigraph only": lambda: _part(stores[1], "pyoxigraph", size),
            "cbrs process, fixed body": lambda: _part(stores[2], "fixed", size),
            "cbrs process, pyoxigraph, budget writer": lambda: _part(stores[4], "writer", size),
            "oxigraph serve": lambda: serve_oxigraph(args.oxigraph, ox_store),
        }
        if args.memory:
            starts["cbrs serve, in memory"] = lambda: _in_memory(data, None)
        for index, other in enumerate(args.against or ()):
            against = other.resolve()
            copy = stores[3] if index == 0 else folder / f"cbrs-against{index}"
            if index:
                shutil.copytree(stores[0], copy)
            starts[f"cbrs serve, {against.name}"] = functools.partial(serve_cbrs, copy, against)
            if args.memory:
                starts[f"cbrs serve, in memory, {against.name}"] = functools.partial(_in_memory, data, against)
        servers: dict[str, Served] = {}
        samples: dict[str, list[tuple[float, float]]] = {label: [] for label in starts}
        try:
            for label, start in starts.items():
                servers[label] = start()
            for turn in range(args.rounds):
                order = list(servers) if turn % 2 == 0 else list(reversed(servers))
                for label in order:
                    served = servers[label]
                    before = cpu_seconds(served.process.pid)
                    answered = lookups(served, entities, args.clients, args.seconds)
                    spent = cpu_seconds(served.process.pid) - before
                    samples[label].append((answered / args.seconds, spent / answered * 1e6))
        finally:
            for served in servers.values():
                served.stop()
    print(f"\n{'server':<40} {'queries/s':>10} {'server CPU us/lookup':>21}   (medians)")
    for label, taken in samples.items():
        rate = statistics.median(r for r, _ in taken)
        cpu = statistics.median(c for _, c in taken)
        print(f"{label:<40} {rate:>10.0f} {cpu:>21.0f}")
    print(f"load average at the end: {os.getloadavg()[0]:.2f}")


def lookups(served: Served, entities: int, clients: int, seconds: float) -> int:
    """The point lookups ``clients`` processes had answered in ``seconds``, none left out as warm-up:
    the server's CPU is read around the whole turn."""
    return len(run_clients(served, entities, clients, 0.0, seconds))


def _in_memory(data: Path, source: Path | None) -> Served:
    """A cbrs server over an in-memory store holding ``data``; with ``source``, cbrs from there."""
    port = _free_port()
    argv = [PYTHON, "-c", _MEMORY, str(data), GRAPH, str(port)]
    return Served("cbrs serve, in memory", argv, port, "/sparql", source)


def _part(store: Path, part: str, size: int) -> Served:
    port = _free_port()
    argv = [PYTHON, "-c", _PART, str(store), str(port), part, str(size)]
    return Served(f"cbrs process, {part}", argv, port, "/sparql")


if __name__ == "__main__":
    main()
