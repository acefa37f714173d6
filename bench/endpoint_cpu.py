"""Profile: server CPU time per point lookup, cbrs serve against oxigraph serve and bare HTTP servers.

Run: python bench/endpoint_cpu.py [--requests 3000] [--triples 200000]

Where the time of a /sparql point lookup goes, as CPU seconds the server process spent (user + system,
all its threads, from /proc/PID/task/*/stat) divided by the requests it answered. Wall time on a shared
machine moves with the other load; CPU time per request much less. One client on one kept-alive
connection sends point lookups (after 300 unmeasured ones) to each server in turn:

- ``oxigraph serve --union-default-graph`` and ``cbrs serve`` over the same generated data
  (bench/store_limits.generate, loaded by each one's own loader);
- the HTTP front of cbrs serve (Granian embedded, ``cbrs.http_listener``) answering a fixed body of the
  same size from a bare ASGI function: the floor the HTTP front alone sets;
- waitress serving a WSGI function that returns that body, and the same behind a Flask route: the
  front cbrs serve had before.

Prints the machine, the inputs and, per server, CPU microseconds per request on the server and in the
client, and the wall time per request.
"""

from __future__ import annotations

import argparse
import http.client
import os
import platform
import random
import subprocess
import sys
import tempfile
import textwrap
import time
import urllib.parse
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from store_limits import GRAPH, NS, Served, _free_port, generate, serve_cbrs, serve_oxigraph

_GRANIAN = textwrap.dedent(
    """
    import sys, threading
    from cbrs.http_listener import HttpListener, ListenerConfig
    body = b"x" * int(sys.argv[2])
    headers = [(b"content-type", b"application/sparql-results+json"), (b"content-length", str(len(body)).encode())]
    async def bare(scope, receive, send):
        await send({"type": "http.response.start", "status": 200, "headers": headers})
        await send({"type": "http.response.body", "body": body})
    HttpListener(bare, ListenerConfig(port=int(sys.argv[1]))).start()
    threading.Event().wait()
    """
)
_BARE = textwrap.dedent(
    """
    import sys
    from flask import Flask, Response
    from waitress.server import create_server
    body = b"x" * int(sys.argv[3])
    def bare(environ, start_response):
        start_response("200 OK", [("Content-Type", "application/sparql-results+json"),
                                  ("Content-Length", str(len(body)))])
        return [body]
    app = Flask(__name__)
    @app.get("/sparql")
    def sparql():
        return Response(body, content_type="application/sparql-results+json")
    create_server(bare if sys.argv[1] == "bare" else app, host="127.0.0.1", port=int(sys.argv[2]), threads=4).run()
    """
)


def cpu_seconds(pid: int) -> float:
    """User and system CPU of the whole process: /proc/PID/stat counts every thread, also those that
    have ended (reading each thread's own stat lost an idle thread's time, or raced with its exit)."""
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def measure(served: Served, entities: int, requests: int) -> tuple[float, float, float]:
    """Server CPU, client CPU and wall time per request, in microseconds."""
    rng = random.Random(7)
    connection = http.client.HTTPConnection("127.0.0.1", served.port, timeout=30)

    def one() -> int:
        query = f"SELECT ?p ?o WHERE {{ <{NS}e{rng.randrange(entities)}> ?p ?o }}"
        connection.request("GET", f"{served.path}?{urllib.parse.urlencode({'query': query})}",
                           headers={"Accept": "application/sparql-results+json"})  # fmt: skip
        response = connection.getresponse()
        return len(response.read())

    for _ in range(300):
        one()
    server, client, start = cpu_seconds(served.process.pid), os.times(), time.perf_counter()
    for _ in range(requests):
        one()
    wall = time.perf_counter() - start
    after = os.times()
    own = (after.user + after.system) - (client.user + client.system)
    connection.close()
    return (
        (cpu_seconds(served.process.pid) - server) / requests * 1e6,
        own / requests * 1e6,
        wall / requests * 1e6,
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--requests", type=int, default=3000)
    parser.add_argument("--triples", type=int, default=200_000)
    parser.add_argument("--oxigraph", default=str(Path(sys.executable).parent / "oxigraph"))
    args = parser.parse_args()
    print(f"machine: {platform.platform()}, {os.cpu_count()} cores, python {platform.python_version()}, "
          f"load average {os.getloadavg()[0]:.2f}")  # fmt: skip
    print(f"inputs: {args.triples} generated triples, {args.requests} point lookups per server, one client")
    with tempfile.TemporaryDirectory(prefix="cbrs-endpoint-cpu-") as name:
        folder = Path(name)
        data = folder / "data.nt"
        entities = generate(data, args.triples)
        cbrs_store, ox_store = folder / "cbrs", folder / "oxigraph"
        python = [sys.executable, "-m", "cbrs", "--store", str(cbrs_store)]
        subprocess.run([*python, "load", str(data), "--graph", GRAPH], check=True, stdout=subprocess.DEVNULL)
        subprocess.run([args.oxigraph, "load", "--location", str(ox_store), "--file", str(data), "--graph", GRAPH],
                       check=True, capture_output=True)  # fmt: skip
        probe = serve_oxigraph(args.oxigraph, ox_store)
        connection = http.client.HTTPConnection("127.0.0.1", probe.port)
        query = f"SELECT ?p ?o WHERE {{ <{NS}e1> ?p ?o }}"
        connection.request("GET", f"/query?{urllib.parse.urlencode({'query': query})}",
                           headers={"Accept": "application/sparql-results+json"})  # fmt: skip
        size = len(connection.getresponse().read())
        probe.stop()
        servers = [
            ("oxigraph serve", lambda: serve_oxigraph(args.oxigraph, ox_store)),
            ("cbrs serve", lambda: serve_cbrs(cbrs_store)),
            ("Granian, bare ASGI", lambda: _granian(size)),
            ("waitress, bare WSGI", lambda: _bare("bare", size)),
            ("waitress + Flask route", lambda: _bare("flask", size)),
        ]
        print(f"\n{'server':<24} {'server CPU us/req':>17} {'client CPU us/req':>17} {'wall us/req':>12}")
        for label, start in servers:
            served = start()
            try:
                server, client, wall = measure(served, entities, args.requests)
            finally:
                served.stop()
            print(f"{label:<24} {server:>17.0f} {client:>17.0f} {wall:>12.0f}")


def _granian(size: int) -> Served:
    port = _free_port()
    return Served("granian bare", [sys.executable, "-c", _GRANIAN, str(port), str(size)], port, "/sparql")


def _bare(kind: str, size: int) -> Served:
    port = _free_port()
    return Served(f"waitress {kind}", [sys.executable, "-c", _BARE, kind, str(port), str(size)], port, "/sparql")


if __name__ == "__main__":
    main()
