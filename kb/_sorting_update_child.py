"""The child process of :mod:`kb.sorting_updates`: runs one SPARQL update on a copy of the store and prints
what it changed.

Run by path (``python .../_sorting_update_child.py COPY PREFIXES``, the update on stdin), so it imports
nothing but the standard library and pyoxigraph. ``COPY`` is the store's N-Quads dump, loaded into memory
here. It answers on stdout with one status byte:
``K`` then the quads removed and the quads added as N-Quads lines, the first part's length before it (8
bytes); or ``S``, ``E``, ``O`` (a syntax, evaluation or input/output error) then the engine's message. A
panic of the engine aborts it before it answers: the parent reads why from its standard error.
"""

from __future__ import annotations

import json
import struct
import sys

import pyoxigraph as ox

OK, SYNTAX, EVALUATION, INPUT_OUTPUT = b"K", b"S", b"E", b"O"
LENGTH = struct.Struct(">Q")


def lines(store: ox.Store) -> set[bytes]:
    """Every quad of ``store`` as its N-Quads line: one term has one serialisation, blank nodes' labels kept."""
    data = store.dump(format=ox.RdfFormat.N_QUADS)
    assert data is not None
    return set(data.splitlines())


def main() -> None:
    copy, prefixes = sys.argv[1], json.loads(sys.argv[2])
    text = sys.stdin.buffer.read().decode("utf-8", "surrogatepass")
    store = ox.Store()
    store.extend(ox.parse(path=copy, format=ox.RdfFormat.N_QUADS))  # Store.load would rename the blank nodes
    before = lines(store)
    try:
        store.update(text, prefixes=prefixes)
    except SyntaxError as error:
        answer = SYNTAX + str(error).encode("utf-8", "replace")
    except OSError as error:
        answer = INPUT_OUTPUT + str(error).encode("utf-8", "replace")
    except RuntimeError as error:
        answer = EVALUATION + str(error).encode("utf-8", "replace")
    else:
        after = lines(store)
        removed, added = sorted(before - after), sorted(after - before)
        first = b"".join(line + b"\n" for line in removed)
        answer = OK + LENGTH.pack(len(first)) + first + b"".join(line + b"\n" for line in added)
    sys.stdout.buffer.write(answer)
    sys.stdout.buffer.flush()


if __name__ == "__main__":
    main()
