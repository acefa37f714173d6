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
4. here, in one transaction, those quads are removed and added (:meth:`EmbeddedStore.exchange`: one
   update whose ``VALUES`` rows a custom function turns into the quads' terms, since a ``DATA`` block
   cannot name a blank node; nothing in it sorts).

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


def update(store: EmbeddedStore, text: str) -> None:
    """Run the update ``text`` on ``store`` as :meth:`EmbeddedStore.update` does, evaluated in a child process."""
    refuse_deep_nesting(text)
    refuse_remote_access(text, store.remote_access)
    store.guard.admit("update", text)
    removed, added = _evaluate(store, text)
    if removed or added:
        store.exchange(removed, added)


def _evaluate(store: EmbeddedStore, text: str) -> tuple[list[ox.Quad], list[ox.Quad]]:
    """The quads ``text`` removes from and adds to ``store``, found on a copy of it in a child process."""
    root = Path(tempfile.mkdtemp(prefix="cbrs-update-copy-"))
    errors = ErrorLog()
    try:
        copy = root / "store.nq"
        store.dump_to(copy)  # its own read, here
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
