"""Why a process running the store's SPARQL engine died: a Rust panic, an allocation that failed, or neither.

cbrs runs texts it cannot vouch for in processes of their own (:mod:`kb.query_guard`'s checkers, the
endpoint's query workers, and ``cbrs query``'s for a text that sorts, :mod:`cbrs.isolated_queries`), so a
crash of the engine costs that process only. A dead process's exit
signal alone does not say why: Oxigraph is built to abort on a panic, and an allocation past the worker's
address-space cap aborts too, both with SIGABRT. What the process wrote to its standard error as it died
does say: a panic prints ``thread '...' panicked at FILE:LINE:COL:`` and then its message; a failed
allocation prints ``memory allocation of N bytes failed``. Each such process writes its standard error to
an :class:`ErrorLog` (an unnamed temporary file, so a chatty process can never block on a full pipe) that
the parent reads once the process is gone.

One panic is known to be reachable from a query (pyoxigraph 0.5.13): ``ORDER BY`` over values the engine
cannot order against each other, dateTimes some with a time zone and some without, can make Rust's sort
find that the comparison is no total order, and panic. Twenty-one values in a ``VALUES`` block suffice: the
text alone crashes the engine, on any store, and a text short enough to skip the guard's checker can make
them (278 characters); so can a store's own data, readings written with and without a time zone. An update
whose ``WHERE`` sorts is therefore evaluated on a copy of the store in a child process too, its effect then
written as data (:mod:`kb.sorting_updates`; docs/security.md, "When the engine itself crashes").
"""

from __future__ import annotations

import re
import tempfile
from dataclasses import dataclass

__all__ = ["Death", "ErrorLog", "read_death", "sorts"]

_TAIL = 8192  # bytes of a dead process's standard error read: the panic's message is at its end
_PANIC = re.compile(r"panicked at [^\n]*:\d+:\d+:\n(?P<message>[^\n]+)")
_ALLOCATION = re.compile(r"memory allocation of \d+ bytes failed")
_TOTAL_ORDER = "total order"
_SORTS = re.compile(r"ORDER(?:\s|#[^\n]*)+BY", re.IGNORECASE)
"""``ORDER BY`` with anything between its two words that may stand there (white space and comments). Read
on the raw text, strings, IRIs and comments included: a word there costs a worker needlessly, while a lexer
that took an operator ``<`` for an IRI's start could hide a real ``ORDER BY`` and let the engine abort."""


def sorts(text: str) -> bool:
    """Whether the query or update ``text`` may sort solutions (``ORDER BY`` in it or in a subquery of it): the
    one way known to reach the panic above (no ``MIN``, ``MAX``, ``GROUP BY``, ``DISTINCT`` or comparison did,
    ``bench/isolated_queries.py``), so what a caller evaluates where an abort costs a child process only."""
    return _SORTS.search(text) is not None


@dataclass(frozen=True)
class Death:
    """What a dead engine process said: ``panic`` is the panic's message, if it panicked."""

    panic: str | None = None
    out_of_memory: bool = False

    @property
    def ordering_panic(self) -> bool:
        """Whether the panic is Rust's sort refusing a comparison that is no total order (ORDER BY)."""
        return self.panic is not None and _TOTAL_ORDER in self.panic

    def explain(self) -> str:
        """The engine's own words and, for the known ORDER BY panic, what to do instead."""
        if self.panic is None:
            return "the SPARQL engine ran out of memory" if self.out_of_memory else "the SPARQL engine died"
        said = f"the SPARQL engine (Oxigraph) panicked: {self.panic!r}"
        if self.ordering_panic:
            return (
                f"{said}; it happens when ORDER BY sorts values it cannot compare with each other, such as "
                "dateTimes some with a time zone and some without: give every one a time zone, or order by "
                "STR(...) of the value"
            )
        return said


def read_death(text: str) -> Death:
    """The :class:`Death` that the standard error ``text`` of a dead engine process tells of."""
    panics = list(_PANIC.finditer(text))
    panic = panics[-1].group("message").strip() if panics else None
    return Death(panic=panic, out_of_memory=_ALLOCATION.search(text) is not None)


class ErrorLog:
    """A child process's standard error, kept in an unnamed temporary file until the process is gone."""

    def __init__(self) -> None:
        self.file = tempfile.TemporaryFile()  # noqa: SIM115 - held for the process's life, closed by close()

    def death(self) -> Death:
        """What the process wrote last, read as a :class:`Death`."""
        try:
            size = self.file.seek(0, 2)
            self.file.seek(max(0, size - _TAIL))
            return read_death(self.file.read().decode("utf-8", "replace"))
        except (OSError, ValueError):  # closed already: nothing to tell
            return Death()

    def close(self) -> None:
        self.file.close()
