"""Reading a SELECT result lets go of it on the thread that read it, even when reading fails half way:
a pyoxigraph result dropped on another thread (by a later garbage collection) raises there."""

from __future__ import annotations

import gc
import weakref

import pyoxigraph as ox
import pytest

from cbrs.kb.queries import _read_rows


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
