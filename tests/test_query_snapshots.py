"""The query workers' snapshots (cbrs.query_workers): a snapshot stays while a request that chose it starts
its worker, even when a write meanwhile makes the next request take a newer one."""

from __future__ import annotations

import json
from pathlib import Path

import pyoxigraph as ox
import pytest

from cbrs.kb import Store
from cbrs.kb.store import EmbeddedStore
from cbrs.query_workers import QueryProcesses, Request

COUNT = "SELECT (COUNT(*) AS ?n) WHERE { GRAPH ?g { ?s ?p ?o } }"


def _request() -> Request:
    json_type = "application/sparql-results+json"
    return Request(COUNT, json_type, None, json_type, "application/n-triples", 1 << 20, 30.0)


def _quad(n: int) -> ox.Quad:
    return ox.Quad(ox.NamedNode(f"urn:s{n}"), ox.NamedNode("urn:p"), ox.Literal(str(n)), ox.NamedNode("urn:g"))


def _count(body: bytes) -> int:
    return int(json.loads(body)["results"]["bindings"][0]["n"]["value"])


def test_a_write_while_a_request_starts_its_worker_leaves_that_requests_snapshot(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    store = Store.open(str(tmp_path / "store"))
    assert isinstance(store, EmbeddedStore)
    store.add([_quad(0)])
    processes = QueryProcesses(store, size=2, memory=0)
    take = processes._take
    inner: list[int] = []
    started: list[bool] = []

    def take_after_another_request() -> object:
        if not started:  # the first request, between choosing its snapshot and starting its worker:
            started.append(True)
            store.add([_quad(1)])  # a write, then another request, which takes a newer snapshot
            inner.append(_count(processes.run(_request())[0]))
        return take()

    monkeypatch.setattr(processes, "_take", take_after_another_request)
    try:
        body, media_type = processes.run(_request())
        assert media_type == "application/sparql-results+json"
        assert _count(body) == 1  # the store as it was when the request came, not an error
        assert inner == [2]  # the other request read the store after the write
    finally:
        processes.close()
        store.close()
