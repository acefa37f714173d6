"""A class a load declares under a term of cbrs's own vocabularies hangs from a declared class.

``lab8:Apple rdfs:subClassOf home:Fruit``, where the home ontology has no ``home:Fruit``, loaded: the apple
was below nothing the components know, a task to move it had no plan, and the refusal said only that no
component provides the goal (docs/tasks.md, "An eighth round"). The vocabularies cbrs ships (home:,
cbrs:, act:) are its own: a lab adds terms to them only by declaring them (the tests' home:GlueStick is
declared where it is used), so a superclass there that is the subject of nothing, in the store or in the
load, is a slip or a guess, once the store holds that vocabulary (a store seeded without it, as some tests'
are, declares none of its terms). A lab's own namespace is left alone: its terms may come in a later file."""

from __future__ import annotations

import re
from collections.abc import Iterable, Sequence

import pyoxigraph as ox

from cbrs.kb.errors import UndeclaredSuperclassError
from cbrs.kb.namespaces import OWL, PREFIXES, RDF, RDFS
from cbrs.kb.shapes import did_you_mean, line_of
from cbrs.kb.sparql_lexemes import HIDING, closing_brace
from cbrs.kb.store import Store

OWN_NAMESPACES = tuple(PREFIXES[name] for name in ("home", "cbrs", "act"))
"""The namespaces whose every term the bundled ontologies (or a load) declare; each ontology's IRI is its
namespace without the ``#``."""

_SUBCLASS = RDFS + "subClassOf"


def check_superclasses(
    store: Store, sources: Iterable[tuple[str, Sequence[ox.Quad]]], undone: str = "nothing was loaded"
) -> None:
    """Raise :class:`UndeclaredSuperclassError` for the first ``rdfs:subClassOf`` of the load (``sources``:
    each file's name and quads; or an update's inserted quads, ``undone`` then saying what became of it)
    whose superclass is of :data:`OWN_NAMESPACES` and declared nowhere."""
    files = list(sources)
    candidates = [  # one pass, and nothing more for a load that puts no class under a term of ours
        (source, quad)
        for source, quads in files
        for quad in quads
        if quad.predicate.value == _SUBCLASS
        and isinstance(quad.object, ox.NamedNode)
        and quad.object.value.startswith(OWN_NAMESPACES)
    ]
    if not candidates:
        return
    declared_here = {q.subject.value for _, quads in files for q in quads if isinstance(q.subject, ox.NamedNode)}
    for source, quad in candidates:
        superclass = quad.object
        assert isinstance(superclass, ox.NamedNode)
        if superclass.value in declared_here or next(iter(store.quads(superclass)), None) is not None:
            continue
        namespace = next(ns for ns in OWN_NAMESPACES if superclass.value.startswith(ns))
        if not _holds_vocabulary(store, namespace):
            continue
        near = did_you_mean(store, superclass.value, declared_here)
        subclass = quad.subject.value if isinstance(quad.subject, ox.NamedNode) else str(quad.subject)
        raise UndeclaredSuperclassError(source, subclass, superclass.value, near, undone, line_of(source, subclass))


def _holds_vocabulary(store: Store, namespace: str) -> bool:
    """Whether the store holds the bundled ontology of ``namespace`` (its header)."""
    header = ox.NamedNode(namespace.rstrip("#"))
    return next(iter(store.quads(header, ox.NamedNode(RDF + "type"), ox.NamedNode(OWL + "Ontology"))), None) is not None


# -- updates that are not data ---------------------------------------------------------------------
#
# An INSERT ... WHERE cannot be read before it runs (pyoxigraph has no update parser, and what it adds
# depends on the store), so it is checked after it ran, and undone whole if refused (KnowledgeBase keeps
# the store to put it back). That costs a copy of the store, so only an update that may add a subclass
# axiom pays it: one that spells rdfs:subClassOf, may spell it otherwise, copies graphs, loads a file, or
# inserts a triple whose predicate is a variable (copied or computed: the one way a text that never
# names the property can write it).

# What may spell rdfs:subClassOf without writing the word: an escape, or a prefix or base IRI ending
# inside the local name (rdf-schema#sub + ClassOf).
_SPELLS = re.compile(r"subclassof|rdf-schema#s|\\[uU]", re.IGNORECASE)
_TOKEN = re.compile(HIDING + r"|\s+|\^\^|[{}\[\]();,]|[^\s{}\[\]();,<>\"'#^]+|.", re.DOTALL)
_COPIES = frozenset({"ADD", "COPY", "MOVE", "LOAD"})
_ADDS = re.compile(r"\b(?:INSERT|ADD|COPY|MOVE|LOAD)\b", re.IGNORECASE)


def may_add_subclasses(text: str) -> bool:
    """Whether the SPARQL update ``text`` might add an ``rdfs:subClassOf`` statement. Deliberately loose
    (a wrong yes costs a copy of the store, a wrong no lets a class under an undeclared term in): yes for
    anything it cannot read as an INSERT template with fixed predicates none of which is that one."""
    if _SPELLS.search(text):
        return True
    if not _ADDS.search(text):  # only deletes, clears, drops: nothing to read further
        return False
    tokens = _tokens(text)
    words = [token.upper() for token in tokens]
    if _COPIES.intersection(words) or any("\\" in token for token in tokens if not token.startswith(("'", '"'))):
        return True  # a graph copied or a file loaded; an escape in a name, which hides what follows it
    for position, word in enumerate(words):
        if word == "INSERT" and words[position + 1 : position + 2] == ["{"]:
            end = closing_brace(tokens, position + 1)
            if end is None or _variable_predicate(tokens[position + 2 : end]):
                return True
    return False


def subclass_axioms(store: Store) -> set[ox.Quad]:
    """The store's ``rdfs:subClassOf`` quads, every graph's (read by the property: an index lookup)."""
    return set(store.quads(predicate=ox.NamedNode(_SUBCLASS)))


def check_added_superclasses(store: Store, before: set[ox.Quad], undone: str = "nothing was written") -> None:
    """:func:`check_superclasses` of the ``rdfs:subClassOf`` quads an update just added to ``store``
    (``before``: :func:`subclass_axioms` before it ran); the store, holding the update's other statements
    too, says what is declared."""
    added = subclass_axioms(store) - before
    if added:
        check_superclasses(store, [("the update", sorted(added, key=str))], undone)


def _tokens(text: str) -> list[str]:
    """The tokens of ``text`` that give an update its shape: strings and IRIs whole, no comments or blanks,
    a '.' that ends a word split off (SPARQL names and numbers do not end in one)."""
    found: list[str] = []
    for match in _TOKEN.finditer(text):
        token = match.group()
        if token.isspace() or token.startswith("#"):
            continue
        word = token if token.startswith(('"', "'", "<")) else token.rstrip(".")
        if word:
            found.append(word)
        if len(word) < len(token):
            found.append(".")
    return found


def _variable_predicate(template: Sequence[str]) -> bool:
    """Whether an INSERT template's tokens (inside its braces) put a variable in a predicate's place, or
    cannot be read for certain. Read as Turtle is: subject, predicate, object, with ',' ';' '.', GRAPH
    blocks and the brackets of blank nodes and collections; a literal's datatype or language tag follows
    it. States: S a subject, P a predicate, E a predicate or the end (after ``[ ... ]`` as a subject), O an
    object, A after an object, C inside a collection."""
    state, back = "S", list[str]()  # back: the state to return to after each open bracket
    tokens = iter(template)
    for token in tokens:
        if token == "^^" or token.upper() == "GRAPH":
            next(tokens, None)  # the datatype, or the graph's name (its '{' follows)
            continue
        if token.startswith("@"):  # a language tag
            continue
        if token in ("{", "}"):
            state = "S"
            continue
        if state in ("P", "E"):
            if token.startswith(("?", "$")):
                return True
            if token == ";":
                continue
            state = "S" if token == "." else (back.pop() if back else "?") if token == "]" else "O"
        elif token in ("[", "("):
            back.append(_AFTER[token].get(state, "?"))
            state = "P" if token == "[" else "C"
        elif token in ("]", ")"):
            state = back.pop() if back else "?"
        elif state == "A":
            state = {",": "O", ";": "P", ".": "S"}.get(token, "?")
        elif state == "S" and token != ".":
            state = "P"
        elif state == "O":
            state = "A"
        if state == "?":
            return True
    return False


# The state after a closing bracket, by the state its opening one was met in.
_AFTER = {"[": {"S": "E", "O": "A", "C": "C"}, "(": {"S": "P", "O": "A", "C": "C"}}
