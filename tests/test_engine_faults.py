"""A query that crashes Oxigraph itself (a Rust panic, which aborts the process) is told as the engine's fault.

The query guard's checker and the endpoint's query workers run such a text in processes of their own; when
one dies, what it wrote to its standard error says why (``kb.engine_faults``). The real crash used here is
``tests/data/engine_faults/ordering_panic.rq``: ``ORDER BY`` over dateTimes some with a time zone and some
without, which pyoxigraph 0.5.13 cannot sort. Where a later pyoxigraph sorts them, those tests skip saying so.
"""

from __future__ import annotations

import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from cbrs.kb import KnowledgeBase
from cbrs.kb.engine_faults import read_death
from cbrs.kb.errors import EngineFaultError
from cbrs.kb.store import EmbeddedStore
from cbrs.sparql_service import EndpointConfig, SparqlService

ORDERING_PANIC = (Path(__file__).parent / "data" / "engine_faults" / "ordering_panic.rq").read_text(encoding="utf-8")
JSON = "application/sparql-results+json"
PANIC_OUTPUT = (
    "\nthread '<unnamed>' (4806) panicked at /rustc/58cf8f9c/library/core/src/slice/sort/shared/smallsort.rs:854:5:\n"
    "user-provided comparison function does not correctly implement a total order\n"
    "note: run with `RUST_BACKTRACE=1` environment variable to display a backtrace\n"
)


def test_a_panic_is_read_with_its_message_and_a_failed_allocation_as_memory() -> None:
    death = read_death("some earlier line\n" + PANIC_OUTPUT)
    assert death.panic == "user-provided comparison function does not correctly implement a total order"
    assert death.ordering_panic and not death.out_of_memory
    assert "give every one a time zone" in death.explain() and "STR(" in death.explain()
    oom = read_death("memory allocation of 1073741824 bytes failed\n")
    assert oom.panic is None and oom.out_of_memory and "memory" in oom.explain()
    other = read_death("thread 'main' panicked at src/lib.rs:10:3:\nindex out of bounds\n")
    assert other.panic == "index out of bounds" and not other.ordering_panic
    assert "time zone" not in other.explain()
    assert read_death("") == read_death("Segmentation fault\n") and read_death("").panic is None


@pytest.fixture(scope="module")
def engine_panics() -> None:
    """Skip unless this pyoxigraph still aborts on the text (run in a process of its own, which dies)."""
    code = "import pyoxigraph, sys; list(pyoxigraph.Store().query(sys.stdin.read()))"
    done = subprocess.run(
        [sys.executable, "-c", code], input=ORDERING_PANIC, text=True, capture_output=True, timeout=60
    )
    if done.returncode == 0:
        pytest.skip("this pyoxigraph sorts dateTimes with and without a time zone without panicking")
    assert "total order" in done.stderr


@pytest.fixture(scope="module")
def disk_kb(tmp_path_factory: pytest.TempPathFactory) -> Iterator[KnowledgeBase]:
    kb = KnowledgeBase.open(tmp_path_factory.mktemp("engine-faults") / "store")
    yield kb
    kb.close()


def test_the_guard_refuses_a_text_that_panics_the_engine_naming_the_panic(
    engine_panics: None, disk_kb: KnowledgeBase
) -> None:
    crashes = EmbeddedStore.guard.crashes
    with pytest.raises(EngineFaultError, match="panicked: 'user-provided comparison") as refused:
        disk_kb.store.query(ORDERING_PANIC)
    assert refused.value.query == ORDERING_PANIC and refused.value.http_status == 500
    assert "time zone" in str(refused.value) and "nested too deeply" not in str(refused.value)
    assert EmbeddedStore.guard.crashes == crashes + 1
    assert disk_kb.store.query("ASK { ?s ?p ?o }")  # this process never ran it


def test_a_worker_the_engine_aborts_in_is_its_fault_not_the_memory_cap(
    engine_panics: None, disk_kb: KnowledgeBase, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The guard let through (as it does a short text that panics only on the store's data): the worker dies."""
    monkeypatch.setattr(EmbeddedStore.guard, "direct_chars", len(ORDERING_PANIC) + 1)
    service = SparqlService(disk_kb, EndpointConfig(workers=1, timeout=30.0))
    try:
        assert service.processes is not None and service.processes.memory > 0
        with pytest.raises(EngineFaultError, match="total order") as failed:
            service.query(ORDERING_PANIC, JSON, None, "127.0.0.1")
        assert failed.value.query == ORDERING_PANIC
        answer = service.query("ASK { ?s ?p ?o }", JSON, None, "127.0.0.1")
        assert answer is not None and b'"boolean":true' in answer.body
    finally:
        service.close()
