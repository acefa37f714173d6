"""What a SPARQL update of ground data changes, read without a SPARQL parser of our own.

graph:entailed follows every update (:mod:`kb.standard_terms`). Working it out again from the whole store
costs tens of milliseconds on the bundled store and seconds on a large one, while the usual write of a
robot is an ``INSERT DATA`` or ``DELETE DATA`` of a few statements. pyoxigraph tells nothing of what an
update changed and has no update parser, so :func:`data_operations` reads such a text itself: it
recognises only data operations (and ``PREFIX`` declarations) and hands each data block to pyoxigraph's
own TriG parser, under the prefixes the store's update sees (:data:`kb.namespaces.PREFIXES`, then the
text's own, which override them and carry over to later operations, as in SPARQL). Any other text, or
one it cannot read for certain, gives None, and the caller works graph:entailed out from the whole store:
a text wrongly taken for a data update would leave a wrong graph, one wrongly refused only costs time.

Refused, so that SPARQL's reading and TriG's cannot differ: any other operation or keyword, ``BASE``
and relative IRIs (no base to resolve against), ``\\u``/``\\U`` escapes (SPARQL reads them before the
grammar does), backslashes outside strings, ``GRAPH`` blocks with braces inside, and blank nodes or
quoted triples in the data (an inserted blank node is a fresh node nobody can name). :class:`DataUpdate`
then checks the reading against the real one before the update runs: on a scratch store holding every
quad the text names, pyoxigraph's SPARQL update must leave exactly what the reading says (the text is flat,
braces two deep at most, so its parser needs no guard of :mod:`kb.query_guard` for it); and afterwards,
on the store itself, each quad named must be present or absent as the reading says.
"""

from __future__ import annotations

import re
from collections.abc import Iterable
from dataclasses import dataclass

import pyoxigraph as ox

from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.sparql_lexemes import HIDING, closing_brace
from cbrs.kb.store import Store

# Strings, IRIs and comments first (nothing inside them counts), then blanks, the brackets and separators
# that give the text its shape, and words: keywords, prefixed names, literals' tails, '.', ','.
_TOKEN = re.compile(HIDING + r"|\s+|[{};]|[^\s{};<>\"'#]+|.", re.DOTALL)
_ABSOLUTE_IRI = re.compile(r"<[A-Za-z][A-Za-z0-9+.-]*:[^>]*>")
_PREFIX_NAME = re.compile(r"(?:[A-Za-z][\w.-]*)?:")
_PREFIXED_NAME = re.compile(r"(?:[A-Za-z][\w.-]*)?:[\w.:%-]*")
_PROLOGUE = "".join(f"PREFIX {name}: <{namespace}>\n" for name, namespace in PREFIXES.items())


@dataclass(frozen=True)
class DataOperation:
    """One ``INSERT DATA`` (``insert``) or ``DELETE DATA`` operation and the quads it names."""

    insert: bool
    quads: tuple[ox.Quad, ...]


@dataclass(frozen=True)
class _Token:
    text: str
    start: int
    end: int


def data_operations(text: str) -> tuple[DataOperation, ...] | None:
    """The data operations of ``text`` in order, or None unless it is only those (see the module)."""
    if "\\u" in text or "\\U" in text:
        return None
    tokens = [
        _Token(match.group(), match.start(), match.end())
        for match in _TOKEN.finditer(text)
        if not match.group().isspace() and not match.group().startswith("#")
    ]
    if not all(_plain(token.text) for token in tokens):
        return None
    words = [token.text.upper() for token in tokens]
    declared: list[str] = []
    operations: list[DataOperation] = []
    position, separated = 0, True
    while position < len(tokens):
        if words[position] == ";" and not separated:
            separated, position = True, position + 1
        elif words[position] == "PREFIX" and separated and position + 2 < len(tokens):
            name, iri = tokens[position + 1].text, tokens[position + 2].text
            if not _PREFIX_NAME.fullmatch(name) or not _ABSOLUTE_IRI.fullmatch(iri):
                return None
            declared.append(f"PREFIX {name} {iri}\n")
            position += 3
        elif (
            words[position] in ("INSERT", "DELETE")
            and separated
            and words[position + 1 : position + 3] == ["DATA", "{"]
        ):
            end = closing_brace(words, position + 2)
            if end is None:
                return None
            quads = _block_quads(text, tokens[position + 3 : end], words[position + 3 : end], "".join(declared))
            if quads is None:
                return None
            operations.append(DataOperation(words[position] == "INSERT", quads))
            position, separated = end + 1, False
        else:
            return None
    return tuple(operations)


def _plain(token: str) -> bool:
    """Whether ``token`` is one whose reading SPARQL and TriG share: a string, an absolute IRI, a bracket or
    separator, or a word without a backslash (no escapes in prefixed names), brackets (blank nodes and
    collections, nested as deep as one likes) or the opening of a blank node or variable."""
    if token.startswith(('"', "'")):
        return len(token) > 1
    if token.startswith("<"):
        return _ABSOLUTE_IRI.fullmatch(token) is not None
    return not any(sign in token for sign in "\\[]()") and not token.startswith(("_:", "?", "$"))


def _block_quads(text: str, tokens: list[_Token], words: list[str], declared: str) -> tuple[ox.Quad, ...] | None:
    """The quads of one data block's tokens, read as TriG from the text itself: each run of default-graph
    triples wrapped in braces (TriG's default graph block, where the last '.' may be left out as in
    SPARQL), ``GRAPH`` blocks as they are."""
    pieces: list[str] = []
    run: list[_Token] = []
    position = 0
    while position < len(tokens):
        if words[position] == "GRAPH":
            name = tokens[position + 1].text if position + 1 < len(tokens) else ""
            if not (_ABSOLUTE_IRI.fullmatch(name) or _PREFIXED_NAME.fullmatch(name)):
                return None
            if words[position + 2 : position + 3] != ["{"]:
                return None
            end = closing_brace(words, position + 2)
            if end is None or "{" in words[position + 3 : end] or "}" in words[position + 3 : end]:
                return None
            pieces.append(_wrapped(text, run))
            pieces.append(text[tokens[position].start : tokens[end].end] + "\n")
            run = []
            position = end + 1
            if words[position : position + 1] == ["."]:
                position += 1  # the '.' SPARQL allows after a GRAPH block
            continue
        if words[position] in ("{", "}"):
            return None
        run.append(tokens[position])
        position += 1
    pieces.append(_wrapped(text, run))
    try:
        found = tuple(ox.parse(_PROLOGUE + declared + "".join(pieces), format=ox.RdfFormat.TRIG))
    except (SyntaxError, ValueError):
        return None
    for quad in found:
        if not isinstance(quad.subject, ox.NamedNode) or not isinstance(quad.object, ox.NamedNode | ox.Literal):
            return None
        if not isinstance(quad.graph_name, ox.NamedNode | ox.DefaultGraph):
            return None
    return found


def _wrapped(text: str, run: list[_Token]) -> str:
    """A run of default-graph triples as a TriG default graph block, in the words of the text."""
    return "{ " + (text[run[0].start : run[-1].end] if run else "") + "\n}\n"


class DataUpdate:
    """A data update about to run on a store, read for certain: the quads it names and whether each is
    there before it runs. Make it (:meth:`read`) before the update runs, then ask :meth:`delta` afterwards.
    """

    def __init__(self, text: str, operations: tuple[DataOperation, ...], present: dict[ox.Quad, bool]) -> None:
        self.text = text
        self.operations = operations
        self._present = present

    @classmethod
    def read(cls, text: str, store: Store) -> DataUpdate | None:
        """The update ``text`` about to run on ``store``, or None if it is not only data operations or
        SPARQL would not read it as :func:`data_operations` does."""
        operations = data_operations(text)
        if operations is None or not _confirmed(text, operations):
            return None
        named = {quad for operation in operations for quad in operation.quads}
        return cls(text, operations, {quad: _holds(store, quad) for quad in named})

    def names_graph(self, graphs: Iterable[ox.NamedNode | ox.DefaultGraph]) -> bool:
        """Whether the text names a quad in one of ``graphs`` (if not, the update leaves them as they are)."""
        wanted = set(graphs)
        return any(quad.graph_name in wanted for quad in self._present)

    @property
    def named(self) -> frozenset[ox.Quad]:
        """Every quad the text names, whether or not the update changes it."""
        return frozenset(self._present)

    def delta(self, store: Store) -> tuple[frozenset[ox.Quad], frozenset[ox.Quad]] | None:
        """What the update added to and removed from ``store`` (it ran since :meth:`read`), or None when
        the store does not bear the reading out."""
        after = _expected(self.operations, self._present)
        if any(_holds(store, quad) != present for quad, present in after.items()):
            return None
        added = frozenset(q for q, present in after.items() if present and not self._present[q])
        removed = frozenset(q for q, present in after.items() if not present and self._present[q])
        return added, removed

    def undo(self, store: Store) -> None:
        """Put every quad the text names back as it was before the update ran, in one transaction: a
        refused update (kb/shapes.py puts back only the description graphs) leaves no other write behind."""
        removing = [quad for quad, before in self._present.items() if not before and _holds(store, quad)]
        adding = [quad for quad, before in self._present.items() if before and not _holds(store, quad)]
        if removing or adding:
            store.replace(removing, adding)


def _expected(operations: tuple[DataOperation, ...], start: dict[ox.Quad, bool]) -> dict[ox.Quad, bool]:
    """Which named quads ``operations`` leave present, from ``start``."""
    present = dict(start)
    for operation in operations:
        for quad in operation.quads:
            present[quad] = operation.insert
    return present


def _confirmed(text: str, operations: tuple[DataOperation, ...]) -> bool:
    """Whether SPARQL reads ``text`` as ``operations`` say: run on a store holding every quad they name, it
    must leave exactly the quads they leave (a quad read otherwise would be left behind, or be one too many)."""
    named = {quad for operation in operations for quad in operation.quads}
    scratch = ox.Store()
    scratch.extend(named)
    try:
        scratch.update(text, prefixes=PREFIXES)
    except (SyntaxError, OSError, RuntimeError, ValueError):
        return False
    left = {quad for quad, present in _expected(operations, dict.fromkeys(named, True)).items() if present}
    return len(scratch) == len(left) and all(quad in scratch for quad in left)


def _holds(store: Store, quad: ox.Quad) -> bool:
    graph = quad.graph_name
    assert isinstance(graph, ox.NamedNode | ox.DefaultGraph) and isinstance(quad.subject, ox.NamedNode)
    assert isinstance(quad.object, ox.NamedNode | ox.Literal)
    return next(store.quads(quad.subject, quad.predicate, quad.object, graph), None) is not None
