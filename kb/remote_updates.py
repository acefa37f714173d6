"""An update of a remote store, checked as the embedded store checks it before anything is sent.

On the embedded store :meth:`KnowledgeBase.update` runs an update and checks what it left (the semantic
map, the descriptions, superclasses), undoing it whole when refused. A remote store cannot be written
and taken back so: other clients read it meanwhile, and what an update that is not data wrote is not
known. So an update whose text the embedded store would check is carried out first on a copy of the
store in memory (:class:`CheckedCopy`, one request), through the embedded store's own checks; only if
they pass is the change it made there sent, as one ``DELETE DATA`` / ``INSERT DATA`` request, so that
what was checked is what is written. A refused update sends nothing.

By SPARQL 1.1 Update an ``INSERT``/``DELETE ... WHERE`` is its templates instantiated over the
solutions of its ``WHERE`` (the deletes before the inserts), and the operations of a request run in
turn, each on what the previous left: carried out in turn on the copy, they give the quads the request
adds and removes. One difference is made up for: Oxigraph server's default graph is the union of its
graphs (``--union-default-graph``; Virtuoso's too) and an embedded store's is not, so there each operation
with a ``WHERE`` and no ``WITH`` or ``USING`` of its own is run on the copy with ``USING`` every graph the
copy holds then (``USING NAMED`` the named ones): its pattern sees what it sees on the server. Another
server (a ``cbrs serve``, which runs updates on its embedded store) is taken to read its default graph. A ``LOAD`` or a
``SERVICE`` is then carried out by cbrs, under the same ``remote_access`` rule, not by the server.

What is guaranteed: the change written is exactly the one checked, worked out from the store as one
query read it. A write by another client between that read and this write is not seen by the check:
the change is made on top of it (a quad it already removed or added is a no-op), so no write is lost,
but their combination was not checked, and the ``WHERE`` may have had other solutions by then. Within
one process, ``cbrs serve`` runs updates one at a time (its lock), as on the embedded store.
"""

from __future__ import annotations

import contextlib
import re
import uuid
from dataclasses import dataclass

import pyoxigraph as ox

from cbrs.kb.errors import StoreError
from cbrs.kb.remote_store import RemoteStore
from cbrs.kb.sparql_lexemes import HIDING, closing_brace
from cbrs.kb.store import EmbeddedStore, Store
from cbrs.kb.update_delta import DataUpdate

_LEXEME = re.compile(HIDING + r"|\s+|[{};]|[^\s{};<\"'#]+|.", re.DOTALL)
_OUTSIDE = frozenset({"LOAD", "SERVICE"})
"""Keywords that make the copy reach out (a file, a URL, an endpoint): its text is not run first on an
empty store to read it."""


@dataclass(frozen=True)
class _Lexeme:
    text: str
    start: int
    end: int

    @property
    def word(self) -> str:
        return self.text.upper()


def _lexemes(text: str) -> list[_Lexeme]:
    """``text``'s lexemes without blanks and comments; strings and IRIs whole (nothing in them counts)."""
    return [
        _Lexeme(m.group(), m.start(), m.end())
        for m in _LEXEME.finditer(text)
        if not m.group().isspace() and not m.group().startswith("#")
    ]


def operations(text: str) -> list[tuple[str, str]]:
    """The operations of the update ``text`` in order, each as (the prologue it sees: every ``PREFIX``
    and ``BASE`` declared before it, its own operation text). Operations are split at a ``;`` outside
    braces, the one place SPARQL puts one there."""
    lexemes = _lexemes(text)
    pieces: list[list[_Lexeme]] = [[]]
    depth = 0
    for lexeme in lexemes:
        if lexeme.text == ";" and depth == 0:
            pieces.append([])
            continue
        depth += (lexeme.text == "{") - (lexeme.text == "}")
        pieces[-1].append(lexeme)
    found: list[tuple[str, str]] = []
    prologue = ""
    for piece in pieces:
        position = 0
        while position < len(piece) and piece[position].word in ("PREFIX", "BASE"):
            size = 3 if piece[position].word == "PREFIX" else 2
            declared = piece[position : position + size]
            prologue += text[declared[0].start : declared[-1].end] + "\n"
            position += size
        if position < len(piece):
            found.append((prologue, text[piece[position].start : piece[-1].end]))
    return found


def as_on_union(operation: str, using: str) -> str:
    """``operation`` with its ``WHERE`` reading the dataset ``using`` (``USING`` clauses), when it has a
    ``WHERE`` and no ``WITH`` or ``USING`` of its own: a ``DELETE WHERE { P }`` becomes the ``DELETE { P }
    ... WHERE { P }`` it stands for. Any other operation is returned as it is."""
    lexemes = _lexemes(operation)
    words = [lexeme.word for lexeme in lexemes]
    if len(words) < 3 or words[0] not in ("DELETE", "INSERT") or words[1] == "DATA":
        return operation
    if words[:3] == ["DELETE", "WHERE", "{"]:
        end = closing_brace(words, 2)
        if end is None:
            return operation
        pattern = operation[lexemes[2].end : lexemes[end].start]
        return f"DELETE {{{pattern}}}\n{using}\nWHERE {{{pattern}}}" + operation[lexemes[end].end :]
    depth = 0
    for lexeme in lexemes:
        if depth == 0 and lexeme.word == "USING":
            return operation
        if depth == 0 and lexeme.word == "WHERE":
            return operation[: lexeme.start] + using + "\n" + operation[lexeme.start :]
        depth += (lexeme.text == "{") - (lexeme.text == "}")
    return operation


class CheckedCopy:
    """A copy, in memory, of a remote store as one query read it: an update is carried out on it as the
    server would carry it out (:meth:`run`), and the change it made there sent (:meth:`send`)."""

    def __init__(self, remote: Store) -> None:
        from cbrs.kb.backup import DEFAULT, store_graphs  # it imports the loader, which imports the store

        self._backend = ox.Store()
        if getattr(remote, "server", "oxigraph") == "oxigraph":  # every quad in one request
            graphs = remote.graphs()  # the empty ones too: CREATE GRAPH of one is refused there
            whole = remote.dataset_nquads() if isinstance(remote, RemoteStore) else None
            if whole is not None:
                self._backend.load(whole, format=ox.RdfFormat.N_QUADS)
            else:
                self._backend.extend(remote.quads())
        else:  # graph by graph, leaving out the server's own (Virtuoso's hold blank nodes no parser takes)
            graphs = [graph for graph in store_graphs(remote) if graph != DEFAULT]
            for graph in graphs:
                self._backend.extend(remote.quads(graph=ox.NamedNode(graph)))
        for graph in graphs:
            self._backend.add_graph(ox.NamedNode(graph))
        self.before = set(self._backend)
        self._graphs = {ox.NamedNode(graph) for graph in graphs}
        self.union = getattr(remote, "server", "other") in ("oxigraph", "virtuoso")
        """Whether an operation's ``WHERE`` reads the union (see the module): on the servers known to read
        it so; another (a ``cbrs serve``, whose updates run on an embedded store) reads the default graph."""
        self.store = EmbeddedStore(self._backend, remote.location)  # its errors name the store the user named
        self.store.remote_access = remote.remote_access

    def run(self, text: str) -> None:
        """Carry out the update ``text`` on the copy as the server would (see the module); read first on
        an empty store, whole, so a mistake in it is told in the words and lines the embedded store uses."""
        if not _OUTSIDE.intersection(lexeme.word for lexeme in _lexemes(text)):
            with contextlib.suppress(StoreError):  # what it does to an empty store (a DROP of a graph it lacks)
                EmbeddedStore(ox.Store(), self.store.location).update(text)
        for prologue, operation in operations(text):
            stand_in = ox.NamedNode(f"urn:uuid:{uuid.uuid4()}")  # the default graph's triples, while it runs
            default = list(self._backend.quads_for_pattern(None, None, None, ox.DefaultGraph()))
            graphs = [graph for graph in self._backend.named_graphs() if isinstance(graph, ox.NamedNode)]
            using = " ".join(
                [f"USING {graph}" for graph in (*graphs, *([stand_in] if default else []))]
                + [f"USING NAMED {graph}" for graph in graphs]
            )
            rewritten = as_on_union(operation, using) if self.union and (graphs or default) else operation
            if rewritten is not operation and default:
                self._backend.extend(ox.Quad(q.subject, q.predicate, q.object, stand_in) for q in default)
            try:
                self.store.update(prologue + rewritten)
            finally:
                if self._backend.contains_named_graph(stand_in):
                    self._backend.remove_graph(stand_in)

    def send(self, remote: RemoteStore, text: str, data: DataUpdate | None = None) -> None:
        """Write to ``remote`` what the update changed on the copy, in one request; when that names a blank
        node the store held (which no data block can name), the update's text instead, which the server
        carries out on the same data. ``data``: the update read as data on the copy before it ran, which
        says what it changed without comparing the copy whole."""
        before = self.before
        delta = data.delta(self.store) if data is not None else None
        if delta is None:
            after = set(self._backend)
            delta = frozenset(after - before), frozenset(before - after)
        added, removed = delta
        graphs = {graph for graph in self._backend.named_graphs() if isinstance(graph, ox.NamedNode)}
        dropped, created = sorted(self._graphs - graphs, key=str), sorted(graphs - self._graphs, key=str)
        new_nodes = {node for quad in added for node in _blank_nodes(quad)}
        if any(_blank_nodes(quad) for quad in removed) or (
            new_nodes and any(new_nodes.intersection(_blank_nodes(quad)) for quad in before)
        ):
            remote.update(text)
            return
        remote.write_change(removed, added, dropped, created)


def _blank_nodes(quad: ox.Quad | ox.Triple) -> set[ox.BlankNode]:
    found: set[ox.BlankNode] = set()
    for term in (quad.subject, quad.object):
        if isinstance(term, ox.BlankNode):
            found.add(term)
        elif isinstance(term, ox.Triple):
            found |= _blank_nodes(term)
    return found
