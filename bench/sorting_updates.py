"""Benchmark: what evaluating an update that sorts in a child process costs (:mod:`kb.sorting_updates`).

Run: python bench/sorting_updates.py [--repeat N]

On the bundled store, on disk and in memory, the same update whose ``WHERE`` sorts (a subquery with
``ORDER BY ... LIMIT``) is run turn about by :meth:`KnowledgeBase.update` as it is now (a copy of the store,
a child process, the delta written here) and as before (the store's own update in this process: the
anchor, ``kb.engine_faults.sorts`` made to say no), and the median wall time of each and their ratio are
printed; then the same split without the knowledge base's checks: ``sorting_updates.update`` against
``EmbeddedStore.update``, and the copy alone (the store's N-Quads dump, which the child loads). The update adds the same
two statements each time (the second time it writes nothing), so every run sees the same store.
"""

from __future__ import annotations

import argparse
import platform
import shutil
import statistics
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from unittest import mock

import pyoxigraph as ox

import cbrs.kb.knowledge_base as knowledge_base
from cbrs.kb import KnowledgeBase, sorting_updates
from cbrs.kb.store import EmbeddedStore

SORTING = (
    "INSERT { <http://example.org/first> rdfs:label ?label } WHERE {"
    " { SELECT ?label { GRAPH ?g { ?c a owl:Class ; rdfs:label ?label } } ORDER BY DESC(?label) LIMIT 2 } }"
)


def timed(run: Callable[[], object]) -> float:
    start = time.perf_counter()
    run()
    return time.perf_counter() - start


def in_process(kb: KnowledgeBase) -> None:
    with mock.patch.object(knowledge_base, "sorts", lambda text: False):
        kb.update(SORTING)


def measure(location: str, repeat: int, scratch: Path) -> None:
    kb = KnowledgeBase.open(location)
    store = kb.store
    assert isinstance(store, EmbeddedStore)
    kb.update(SORTING)  # the statements in, the checkers started, the caches warm
    quads = sum(1 for _ in store.quads())
    pairs: dict[str, list[float]] = {"kb_new": [], "kb_old": [], "raw_new": [], "raw_old": [], "copy": []}
    for n in range(repeat):
        pairs["kb_new"].append(timed(lambda: kb.update(SORTING)))
        pairs["kb_old"].append(timed(lambda: in_process(kb)))
        pairs["raw_new"].append(timed(lambda: sorting_updates.update(store, SORTING)))
        pairs["raw_old"].append(timed(lambda: store.update(SORTING)))
        target = scratch / f"copy-{n}.nq"
        pairs["copy"].append(timed(lambda: store._backend.dump(str(target), format=ox.RdfFormat.N_QUADS)))  # noqa: B023
        target.unlink()
    med = {key: statistics.median(values) for key, values in pairs.items()}
    name = "memory" if store.in_memory else "disk"
    print(f"{name}: {quads} quads, median of {repeat}")
    print(
        f"  KnowledgeBase.update: child {med['kb_new']:.3f} s, in process {med['kb_old']:.3f} s,"
        f" x{med['kb_new'] / med['kb_old']:.2f}, +{med['kb_new'] - med['kb_old']:.3f} s"
    )
    print(
        f"  store only: sorting_updates.update {med['raw_new']:.3f} s, EmbeddedStore.update {med['raw_old']:.3f} s,"
        f" x{med['raw_new'] / med['raw_old']:.2f}; the dump alone {med['copy']:.3f} s"
    )
    kb.close()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=7)
    args = parser.parse_args()
    print(f"python {platform.python_version()}, pyoxigraph {ox.__version__}, {platform.machine()}")
    scratch = Path(tempfile.mkdtemp(prefix="cbrs-bench-sorting-updates-"))
    try:
        measure(str(scratch / "store"), args.repeat, scratch)
        measure(":memory:", args.repeat, scratch)
    finally:
        shutil.rmtree(scratch, ignore_errors=True)


if __name__ == "__main__":
    main()
