"""Benchmark: queries per second of cbrs's /sparql against `oxigraph serve`, same data, same queries.

Run: python bench/sparql_endpoint.py [--seconds S] [--clients 1,4] [--oxigraph PATH]

Both servers hold the seeded bundled knowledge base on disk (a cbrs store in a temporary folder, and
its dump loaded into a fresh Oxigraph server directory) and answer the same query texts: the named
queries that take no required value, with the cbrs prefixes declared in each text, and one trivial
query that shows the HTTP overhead. First each query alone (median of sequential requests), then
C client threads (one pooled HTTP connection each, from an address of its own, JSON results asked
for) for S seconds, round-robin
over the queries; the load generator runs on the same machine, so both servers share the cores.
Prints the machine, the inputs, queries per second and latency percentiles of each server, and cbrs's
rate as a fraction of Oxigraph's.
"""

from __future__ import annotations

import argparse
import os
import platform
import shutil
import socket
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import httpx

from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import PREFIXES
from cbrs.server import ServeConfig, Server

PER_QUERY = 30
TRIVIAL = "SELECT ?s WHERE { ?s a <https://w3id.org/cbrs/core#Requirement> } LIMIT 1"  # mostly HTTP overhead
QUERIES = ["advertisements", "requirements", "graph_statistics", "taxonomy_links", "world_facts", "actions"]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=5.0)
    parser.add_argument("--clients", default="1,4")
    parser.add_argument("--oxigraph", default=shutil.which("oxigraph") or str(Path(sys.executable).parent / "oxigraph"))
    args = parser.parse_args()
    version = subprocess.run([args.oxigraph, "--version"], capture_output=True, text=True, check=True).stdout.strip()
    print(f"machine: {platform.platform()}, {os.cpu_count()} cores, python {platform.python_version()}")
    folder = tempfile.mkdtemp(prefix="cbrs-bench-")
    kb = KnowledgeBase.open(Path(folder) / "cbrs")  # on disk, like a deployed store and like the server's
    header = "".join(f"PREFIX {name}: <{iri}>\n" for name, iri in PREFIXES.items())
    texts = [header + kb.queries.get(name).text for name in QUERIES] + [TRIVIAL]
    names = [*QUERIES, "trivial"]
    rows = {name: len(list(kb.query(text))) for name, text in zip(names, texts, strict=True)}
    print(f"inputs: bundled knowledge base, {kb.store.count()} quads; {args.seconds:g} s per run; ", end="")
    print(f"clients {args.clients}")
    print("queries (rows): " + ", ".join(f"{name} ({n})" for name, n in rows.items()))
    print(f"servers: cbrs serve (waitress, embedded pyoxigraph on disk) vs {version} serve --union-default-graph\n")

    try:
        dump = Path(folder) / "kb.nq"
        dump.write_bytes(kb.store.dump())
        location = Path(folder) / "oxigraph"
        subprocess.run([args.oxigraph, "load", "--location", str(location), "--file", str(dump)], check=True,
                       capture_output=True)  # fmt: skip
        port = _free_port()
        bind = f"127.0.0.1:{port}"
        oxigraph = subprocess.Popen(
            [args.oxigraph, "serve", "--location", str(location), "--bind", bind, "--union-default-graph"],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        server = Server(kb, ServeConfig(port=0, bridge_port=0))
        server.start()
        try:
            oxigraph_url = f"http://127.0.0.1:{port}/query"
            _wait_for(oxigraph_url)
            cbrs_url = f"http://127.0.0.1:{server.http_port}/sparql"
            for url in (cbrs_url, oxigraph_url):  # the same answers, or the comparison means nothing
                for name, text in zip(names, texts, strict=True):
                    got = len(_ask(httpx.Client(), url, text).json()["results"]["bindings"])
                    assert got == rows[name], f"{url} gave {got} rows for {name}, expected {rows[name]}"
            print(f"{'query':<17} {'cbrs ms':>8} {'oxigraph ms':>12}   (median of {PER_QUERY} sequential requests)")
            with httpx.Client() as client:
                for name, text in zip(names, texts, strict=True):
                    medians = [_median_ms(client, url, text) for url in (cbrs_url, oxigraph_url)]
                    print(f"{name:<17} {medians[0]:>8.2f} {medians[1]:>12.2f}")
            print()
            print(f"{'clients':>7} {'server':<9} {'queries/s':>10} {'p50 ms':>8} {'p95 ms':>8}")
            for clients in (int(c) for c in args.clients.split(",")):
                rates = {}
                for label, url in (("cbrs", cbrs_url), ("oxigraph", oxigraph_url)):
                    rate, latencies = _load(url, texts, clients, args.seconds)
                    rates[label] = rate
                    p50 = statistics.median(latencies) * 1000
                    p95 = statistics.quantiles(latencies, n=20)[18] * 1000
                    print(f"{clients:>7} {label:<9} {rate:>10.0f} {p50:>8.2f} {p95:>8.2f}")
                print(f"{'':>7} cbrs/oxigraph = {rates['cbrs'] / rates['oxigraph']:.2f}")
        finally:
            server.stop()
            oxigraph.terminate()
            oxigraph.wait(10)
    finally:
        kb.close()
        shutil.rmtree(folder, ignore_errors=True)


def _median_ms(client: httpx.Client, url: str, text: str) -> float:
    samples = []
    for _ in range(PER_QUERY):
        start = time.perf_counter()
        _ask(client, url, text)
        samples.append(time.perf_counter() - start)
    return statistics.median(samples) * 1000


def _ask(client: httpx.Client, url: str, text: str) -> httpx.Response:
    response = client.post(
        url,
        content=text.encode("utf-8"),
        headers={"Content-Type": "application/sparql-query", "Accept": "application/sparql-results+json"},
        timeout=30,
    )
    response.raise_for_status()
    return response


def _load(url: str, texts: list[str], clients: int, seconds: float) -> tuple[float, list[float]]:
    latencies: list[list[float]] = [[] for _ in range(clients)]
    deadline = time.perf_counter() + seconds

    def work(index: int) -> None:
        # each client from an address of its own, as robots are: cbrs shares its query workers per address
        with httpx.Client(transport=httpx.HTTPTransport(local_address=f"127.0.0.{10 + index}")) as client:
            n = index
            while time.perf_counter() < deadline:
                start = time.perf_counter()
                _ask(client, url, texts[n % len(texts)])
                latencies[index].append(time.perf_counter() - start)
                n += 1

    started = time.perf_counter()
    threads = [threading.Thread(target=work, args=(i,)) for i in range(clients)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    elapsed = time.perf_counter() - started
    flat = [x for each in latencies for x in each]
    return len(flat) / elapsed, flat


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def _wait_for(url: str, timeout: float = 30.0) -> None:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        try:
            httpx.get(url, params={"query": "ASK {}"}, timeout=1)
            return
        except httpx.TransportError:
            time.sleep(0.1)
    raise SystemExit(f"oxigraph serve did not answer at {url} within {timeout} s")


if __name__ == "__main__":
    main()
