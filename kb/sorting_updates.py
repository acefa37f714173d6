"""A SPARQL update that may sort, evaluated on a copy of the store in a child process and its effect then
written here as data, so that a crash of the engine costs the child and not the process holding the store.

pyoxigraph 0.5.13 aborts the process when ``ORDER BY`` sorts values it cannot compare consistently
(dateTimes some with a time zone and some without, :mod:`kb.engine_faults`), and an update's ``WHERE`` may
sort them: a subquery with ``ORDER BY ... LIMIT 1`` over a lab's readings. Run in the process that holds
the store, such an update killed ``cbrs serve`` (any token holder's mistake), ``cbrs update`` and a library
user's program. So :meth:`kb.knowledge_base.KnowledgeBase.update` hands an update text that sorts
(:func:`kb.engine_faults.sorts`) to :func:`update` instead of the store's own update:

1. the same checks first (nesting, remote access, the query guard's checker for a long text);
2. a copy of the store: its N-Quads dump (Oxigraph's serialiser, blank nodes' labels kept), which the
   child parses into an in-memory store (``Store.load`` would give every blank node a new label). A
   RocksDB checkpoint of an on-disk store, which the child may open and write (Oxigraph documents it as
   a database that "operates independently from the original", and so it proved), took longer on the
   bundled store (docs/security.md), since the child then read its quads twice from disk;
3. a child process (``_sorting_update_child.py``) runs the update on the copy and prints what it removed
   and added, as N-Quads lines (blank nodes keep their labels);
4. here, in one transaction, those quads are removed and added: one update whose ``VALUES`` rows a custom
   function turns into the quads' terms, since a ``DATA`` block cannot name a blank node; nothing in it
   sorts.

A child that dies wrote nothing here: a panic is an :class:`~kb.errors.EngineFaultError` naming it. The
caller holds the writer's lock, as for any update, so nothing is written between the copy and the delta.
An update that does not sort runs as before. The cost (docs/security.md, "When the engine itself crashes")
is a dump of the store, a Python process start, loading the dump there and dumping it twice; it grows
with the store.
"""

from __future__ import annotations

import json
import shutil
import signal
import struct
import subprocess
import sys
import tempfile
from collections.abc import Callable, Sequence
from pathlib import Path

import pyoxigraph as ox

from cbrs.kb.engine_faults import ErrorLog
from cbrs.kb.errors import EngineFaultError, QuerySyntaxError, StoreError, StoreEvaluationError
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.remote_access import loads, refuse_remote_access
from cbrs.kb.store import EmbeddedStore, refuse_deep_nesting

__all__ = ["update"]

_CHILD = Path(__file__).with_name("_sorting_update_child.py")
_LENGTH = struct.Struct(">Q")
_REMOVED = ox.NamedNode("urn:cbrs:sorting-update:removed")
_ADDED = ox.NamedNode("urn:cbrs:sorting-update:added")
_APPLY = """{operation} {{ GRAPH ?g {{ ?s ?p ?o }} ?ds ?dp ?do }} WHERE {{
  VALUES ?row {{ {rows} }}
  BIND (<{f}>(?row, 0) AS ?s) BIND (<{f}>(?row, 1) AS ?p) BIND (<{f}>(?row, 2) AS ?o) BIND (<{f}>(?row, 3) AS ?g)
  BIND (<{f}>(?row, 4) AS ?ds) BIND (<{f}>(?row, 5) AS ?dp) BIND (<{f}>(?row, 6) AS ?do)
}}"""
"""One operation writing the quads of a list: row ``?row`` is the list's quad, terms 0 to 3 bound for a quad
of a named graph, 4 to 6 for one of the default graph (a template triple with an unbound variable is left
out). Only row numbers are written into the text; the terms come from the custom function ``f``."""


def update(store: EmbeddedStore, text: str) -> None:
    """Run the update ``text`` on ``store`` as :meth:`EmbeddedStore.update` does, evaluated in a child process."""
    refuse_deep_nesting(text)
    refuse_remote_access(text, store.remote_access)
    store.guard.admit("update", text)
    removed, added = _evaluate(store, text)
    if removed or added:
        _apply(store, removed, added)


def _evaluate(store: EmbeddedStore, text: str) -> tuple[list[ox.Quad], list[ox.Quad]]:
    """The quads ``text`` removes from and adds to ``store``, found on a copy of it in a child process."""
    root = Path(tempfile.mkdtemp(prefix="cbrs-update-copy-"))
    errors = ErrorLog()
    try:
        copy = root / "store.nq"
        try:
            store._backend.dump(str(copy), format=ox.RdfFormat.N_QUADS)  # its own read, here
        except OSError as error:
            raise StoreError(store.location, f"a copy for the update failed: {error}") from error
        command = [sys.executable, str(_CHILD), str(copy), json.dumps(PREFIXES)]
        done = subprocess.run(
            command,
            input=text.encode("utf-8", "surrogatepass"),
            stdout=subprocess.PIPE,
            stderr=errors.file,
            start_new_session=True,  # a Ctrl-C that cbrs update holds until the update ends does not reach it
        )
        if done.returncode != 0 or not done.stdout:
            death = errors.death()
            if death.panic is not None:
                raise EngineFaultError(text, death.explain(), "update")
            code = done.returncode
            how = f"signal {signal.Signals(-code).name}" if code < 0 else f"exit status {code}"
            raise StoreEvaluationError(store.location, "update", f"the process evaluating it died ({how})")
    finally:
        errors.close()
        shutil.rmtree(root, ignore_errors=True)
    status, body = done.stdout[:1], done.stdout[1:]
    if status != b"K":
        message = body.decode("utf-8", "replace")
        if status == b"S":
            raise QuerySyntaxError(text, message)
        if status == b"O" and loads(text):  # an allowed LOAD that cannot read its file: the request's fault
            raise StoreEvaluationError(store.location, "update", f"LOAD failed: {message}")
        if status == b"O":
            raise StoreError(store.location, f"update failed: {message}")
        raise StoreEvaluationError(store.location, "update", message)
    (length,) = _LENGTH.unpack(body[: _LENGTH.size])
    first = _LENGTH.size + length
    return _quads(body[_LENGTH.size : first]), _quads(body[first:])


def _quads(data: bytes) -> list[ox.Quad]:
    return list(ox.parse(data, format=ox.RdfFormat.N_QUADS)) if data else []


def _apply(store: EmbeddedStore, removed: Sequence[ox.Quad], added: Sequence[ox.Quad]) -> None:
    """Remove ``removed`` and add ``added`` in one transaction, blank nodes as they are."""
    operations = []
    functions: dict[ox.NamedNode, Callable[[ox.Literal, ox.Literal], _Term | None]] = {}
    for operation, quads, name in (("DELETE", removed, _REMOVED), ("INSERT", added, _ADDED)):
        if quads:
            rows = " ".join(str(n) for n in range(len(quads)))
            operations.append(_APPLY.format(operation=operation, rows=rows, f=name.value))
            functions[name] = _terms(quads)
    store.generation += 1  # before as well as after: a snapshot taken meanwhile is never current
    try:
        store._backend.update(" ;\n".join(operations), custom_functions=functions)
    except OSError as error:
        raise StoreError(store.location, f"update failed: {error}") from error
    finally:
        store.generation += 1


_Term = ox.NamedNode | ox.BlankNode | ox.Literal | ox.Triple


def _terms(quads: Sequence[ox.Quad]) -> Callable[[ox.Literal, ox.Literal], _Term | None]:
    """The custom function of :data:`_APPLY` for ``quads``: term ``position`` of quad ``row``, or None (unbound)."""

    def term(row: ox.Literal, position: ox.Literal) -> _Term | None:
        quad, at = quads[int(row.value)], int(position.value)
        graph = quad.graph_name
        if isinstance(graph, ox.DefaultGraph) != (at >= 4):
            return None  # this template triple is not this quad's
        if at % 4 == 3:
            assert not isinstance(graph, ox.DefaultGraph)
            return graph
        return (quad.subject, quad.predicate, quad.object)[at % 4]

    return term
