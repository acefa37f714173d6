"""Reading a SELECT result lets go of it on the thread that read it, even when reading fails half way:
a pyoxigraph result dropped on another thread (by a later garbage collection) raises there."""

from __future__ import annotations

import gc
import sys
import threading
import traceback
import weakref
from collections.abc import Callable

import pyoxigraph as ox
import pytest

from cbrs.kb.queries import _read_rows
from cbrs.kb.results import releases_results
from tests.helpers_unsendable import unsendable_kept_by


class _Solutions:
    """Stands in for pyoxigraph's unsendable result: rows, then a failure (a deadline, a dropped server)."""

    def __iter__(self):  # type: ignore[no-untyped-def]
        yield {"x": ox.Literal("1")}
        raise OSError("the query was stopped")


def test_a_failed_read_keeps_nothing_alive_in_its_exception() -> None:
    solutions = _Solutions()
    alive = weakref.ref(solutions)
    kept: list[BaseException] = []  # what a task runner or a server keeps of a failed request
    gc.disable()  # only reference counts may free it here: a collection could run on any thread
    try:
        with pytest.raises(OSError) as caught:
            _read_rows(["x"], solutions)
        kept.append(caught.value)
        del solutions, caught
        assert alive() is None
    finally:
        gc.enable()
    assert "stopped" in str(kept[0])


def test_rows_leave_out_unbound_variables() -> None:
    rows = _read_rows(["x", "y"], [{"x": ox.Literal("1"), "y": None}])
    assert rows == [{"x": ox.Literal("1")}]


def _read_then_refuse(store: ox.Store) -> None:
    result = store.query("SELECT ?x WHERE { VALUES ?x { 1 2 } }")
    rows = list(result)
    raise LookupError(f"{len(rows)} rows, none of them the one wanted")


def _unraisable_after_handing_over(read: Callable[[ox.Store], None]) -> list[str]:
    """Run ``read`` on a worker thread, hand its error to this thread as a server would, drop it here."""
    handed: list[BaseException] = []

    def work() -> None:
        try:
            read(ox.Store())
        except LookupError as error:
            handed.append(error)

    seen: list[str] = []
    hook = sys.unraisablehook
    sys.unraisablehook = lambda unraisable: seen.append(str(unraisable.exc_value))
    try:
        worker = threading.Thread(target=work)
        worker.start()
        worker.join(timeout=30)
        assert handed and not worker.is_alive()
        handed.clear()
        gc.collect()
    finally:
        sys.unraisablehook = hook
    return seen


def test_a_result_read_on_a_worker_is_dropped_there_when_its_error_goes_elsewhere() -> None:
    if not any("unsendable" in text for text in _unraisable_after_handing_over(_read_then_refuse)):
        pytest.skip("this pyoxigraph drops a result on any thread: nothing to let go of early")
    assert _unraisable_after_handing_over(releases_results(_read_then_refuse)) == []


def test_a_released_error_keeps_its_lines_but_no_result() -> None:
    with pytest.raises(LookupError) as caught:
        releases_results(_read_then_refuse)(ox.Store())
    assert unsendable_kept_by(caught.value) == []
    assert "_read_then_refuse" in "".join(traceback.format_tb(caught.value.__traceback__))
