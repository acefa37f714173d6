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
from collections.abc import Collection, Iterable, Mapping, Sequence
from dataclasses import dataclass

import pyoxigraph as ox

from cbrs.kb.errors import KnowledgeBaseError, UndeclaredSuperclassError
from cbrs.kb.namespaces import OWL, PREFIXES, RDF, RDFS, GraphName
from cbrs.kb.shapes import did_you_mean, line_of, nearest_term
from cbrs.kb.sparql_lexemes import HIDING, closing_brace
from cbrs.kb.store import Store, Term
from cbrs.kb.update_delta import DataOperation

OWN_NAMESPACES = tuple(PREFIXES[name] for name in ("home", "cbrs", "act"))
"""The namespaces whose every term the bundled ontologies (or a load) declare; each ontology's IRI is its
namespace without the ``#``."""

_SUBCLASS = RDFS + "subClassOf"


def check_superclasses(
    store: Store,
    sources: Iterable[tuple[str, Sequence[ox.Quad]]],
    undone: str = "nothing was loaded",
    removed: Collection[ox.Quad] = (),
) -> None:
    """Raise :class:`UndeclaredSuperclassError` for the first ``rdfs:subClassOf`` of the load (``sources``:
    each file's name and quads; or an update's inserted quads, ``undone`` then saying what became of it)
    whose superclass is of :data:`OWN_NAMESPACES` and declared nowhere; ``removed``: quads of the store
    that go as the load comes in (a graph it replaces), which declare nothing then."""
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
    added = [quad for _, quads in files for quad in quads]
    declared_here = {q.subject.value for q in added if isinstance(q.subject, ox.NamedNode)}
    for source, quad in candidates:
        superclass = quad.object
        assert isinstance(superclass, ox.NamedNode)
        if superclass.value in declared_here or _stays(store.quads(superclass), removed):
            continue
        if not _holds_vocabulary(store, _namespace(superclass), removed, added):
            continue
        near = did_you_mean(store, superclass.value, declared_here)
        subclass = quad.subject.value if isinstance(quad.subject, ox.NamedNode) else str(quad.subject)
        raise UndeclaredSuperclassError(source, subclass, superclass.value, near, undone, line_of(source, subclass))


def _holds_vocabulary(
    store: Store, namespace: str, removed: Collection[ox.Quad] = (), added: Sequence[ox.Quad] = ()
) -> bool:
    """Whether the store holds the bundled ontology of ``namespace`` (its header), once ``removed`` went
    and ``added`` came."""
    header, kind, ontology = (
        ox.NamedNode(namespace.rstrip("#")),
        ox.NamedNode(RDF + "type"),
        ox.NamedNode(OWL + "Ontology"),
    )
    if any((quad.subject, quad.predicate, quad.object) == (header, kind, ontology) for quad in added):
        return True
    return _stays(store.quads(header, kind, ontology), removed)


def _stays(found: Iterable[ox.Quad], removed: Collection[ox.Quad]) -> bool:
    """Whether any of the quads ``found`` is not among ``removed``."""
    return any(quad not in removed for quad in found)


def _namespace(term: ox.NamedNode) -> str:
    return next(ns for ns in OWN_NAMESPACES if term.value.startswith(ns))


def _ours(term: object) -> bool:
    return isinstance(term, ox.NamedNode) and term.value.startswith(OWN_NAMESPACES)


# -- removing a declaration ------------------------------------------------------------------------
#
# The other way to the same state: ``home:Fruit`` declared by a lab, ``lab9:Banana rdfs:subClassOf
# home:Fruit`` loaded, then every statement about home:Fruit deleted. The store then holds what an
# INSERT of the banana's axiom would have been refused for, so the delete is refused the same way, unless
# it also takes away (or re-points) every subclass under the term. Declared means the same as above: the
# subject of a statement, in any graph; and only while the store holds the term's vocabulary (a DROP of
# the ontology graph leaves a store without it, of which no term counts as undeclared).


class RemovedDeclarationError(UndeclaredSuperclassError):
    """A write would remove the last statement about a term of cbrs's own vocabularies that a class which
    stays is under (``subclass rdfs:subClassOf superclass``), leaving the store as an insert of that axiom
    would have been refused for; nothing was written. ``source``: the update or the request's body."""

    def __init__(self, source: str, subclass: str, superclass: str, undone: str = "nothing was written") -> None:
        from cbrs.kb.namespaces import shorten

        self.source, self.subclass, self.superclass = source, subclass, superclass
        self.suggestion, self.line = None, None
        sub, sup = shorten(subclass), shorten(superclass)
        KnowledgeBaseError.__init__(
            self,
            f"{source}: it removes the last statement about {sup}, and {sub} rdfs:subClassOf {sup} stays: {sup} "
            f"would be declared nowhere, so {sub} would be below no class the components know and no step would "
            f"take a thing of it; keep a statement about {sup} (its rdf:type or rdfs:subClassOf), or delete or "
            f"re-point every class under it first or in the same update (cbrs query 'SELECT ?c WHERE {{ ?c "
            f"rdfs:subClassOf {sup} }}' lists them); {undone}",
        )


def check_change(
    store: Store,
    removed: Iterable[ox.Quad],
    added: Sequence[ox.Quad],
    source: str = "the update",
    undone: str = "nothing was written",
) -> None:
    """Refuse a change ``store`` is about to take (``removed`` taken out, then ``added`` put in: a data
    update's net change, a Graph Store ``PUT``, ``POST`` or ``DELETE``) that leaves a class under a term
    of ours declared nowhere: one it adds (:class:`UndeclaredSuperclassError`, the declarations read as
    the change leaves them) or one that stays under a term whose last statement it removes
    (:class:`RemovedDeclarationError`). A change that removes no statement about a term of ours costs
    one pass over its quads."""
    gone = removed if isinstance(removed, set | frozenset) else set(removed)
    check_superclasses(store, [(source, added)], undone, gone)
    staying = {quad.subject for quad in added}
    candidates = sorted({q.subject for q in gone if _ours(q.subject) and q.subject not in staying}, key=str)
    if not candidates:
        return
    held: dict[str, bool] = {}
    users = _users(store, [term for term in candidates if isinstance(term, ox.NamedNode)], gone, added)
    for superclass, user in users.items():
        said = _declarations(store, superclass)
        if not said or _stays(said, gone):  # declared nowhere before (not this change's doing), or still
            continue
        namespace = _namespace(superclass)
        if namespace not in held:
            held[namespace] = _holds_vocabulary(store, namespace, gone, added)
        if held[namespace]:
            raise RemovedDeclarationError(source, user, superclass.value, undone)


def check_data_update(store: Store, operations: Iterable[DataOperation], undone: str = "nothing was written") -> None:
    """:func:`check_change` of a data update's ``operations`` about to run on ``store``: each quad as the
    last operation naming it leaves it (removed or added)."""
    last: dict[ox.Quad, bool] = {}
    for operation in operations:
        for quad in operation.quads:
            last[quad] = operation.insert
    removed = {quad for quad, inserted in last.items() if not inserted}
    check_change(store, removed, [quad for quad, inserted in last.items() if inserted], "the update", undone)


def check_whole(
    store: Store | None, quads: Iterable[ox.Quad], source: str, undone: str = "nothing was written"
) -> None:
    """Refuse ``quads`` as the whole of ``store`` (a restore that replaces everything) when they hold a
    class under a term of ours that none of them declares, while they hold the term's vocabulary: read
    from ``quads`` alone, since none of the store stays. Declared means the subject of a statement in any
    graph, graph:entailed too, as for an insert: an export of a store these checks kept passes. The store is
    asked only about a term found so: if it declares it now, the restore removes its last statement
    (:class:`RemovedDeclarationError`); else (or with no store yet, None) the quads put their class under a
    term declared nowhere (:class:`UndeclaredSuperclassError`). One pass over ``quads``."""
    subclass, kind, ontology = ox.NamedNode(_SUBCLASS), ox.NamedNode(RDF + "type"), ox.NamedNode(OWL + "Ontology")
    declared: set[ox.NamedNode | ox.BlankNode | ox.Triple] = set()
    headers: set[str] = set()
    users: dict[ox.NamedNode, str] = {}
    for quad in quads:
        declared.add(quad.subject)
        if quad.predicate == subclass and _ours(quad.object):
            assert isinstance(quad.object, ox.NamedNode)
            name = _name(quad.subject)
            users[quad.object] = min(users.get(quad.object, name), name)  # the same class whatever the order
        elif quad.predicate == kind and quad.object == ontology and isinstance(quad.subject, ox.NamedNode):
            headers.add(quad.subject.value)
    for term in sorted(users, key=str):
        if term in declared or _namespace(term).rstrip("#") not in headers:
            continue
        if store is not None and _declarations(store, term):
            raise RemovedDeclarationError(source, users[term], term.value, undone)
        near = nearest_term(term.value, [t.value for t in declared if isinstance(t, ox.NamedNode)])
        raise UndeclaredSuperclassError(source, users[term], term.value, near, undone)


def _declarations(store: Store, term: ox.NamedNode) -> list[ox.Quad]:
    """The statements about ``term`` that declare it against a removal: not graph:entailed's, which are
    worked out from the other graphs after every write and go with what entailed them."""
    return [quad for quad in store.quads(term) if quad.graph_name != _ENTAILED]


_ENTAILED = GraphName.ENTAILED.node
_FEW = 16
"""Up to how many terms a change removes statements about their subclasses are looked up term by term
(a request each on a remote store); more, and every subclass axiom is read at once."""


def _users(
    store: Store, terms: Sequence[ox.NamedNode], removed: Collection[ox.Quad], added: Sequence[ox.Quad]
) -> dict[ox.NamedNode, str]:
    """Each of ``terms`` that a class is under once the change is made, in order, with the first such class."""
    wanted = set(terms)
    subclass = ox.NamedNode(_SUBCLASS)
    axioms: Iterable[ox.Quad]
    if len(wanted) > _FEW:
        axioms = store.quads(predicate=subclass)
    else:
        axioms = (quad for term in terms for quad in store.quads(None, subclass, term))
    found: dict[ox.NamedNode, str] = {}
    staying = [q for q in axioms if q.object in wanted and q not in removed]
    for quad in sorted(staying, key=str) + [q for q in added if q.predicate == subclass and q.object in wanted]:
        assert isinstance(quad.object, ox.NamedNode)
        found.setdefault(quad.object, _name(quad.subject))
    return {term: found[term] for term in terms if term in found}


def _name(term: ox.NamedNode | ox.BlankNode | ox.Triple) -> str:
    return term.value if isinstance(term, ox.NamedNode) else str(term)


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


# An update that is not data may remove a declaration only through a DELETE template (a DELETE WHERE's
# pattern is its template) or by emptying graphs (CLEAR, DROP, and MOVE and COPY, which empty their
# target). Its text says which statements it can reach: those whose predicate a template fixes, when the
# subject is a variable or may be a term of ours, and those of a graph it names. Whether the store holds
# such a statement about a term of ours a class is under is then asked, one query for all (one request on
# a remote store); only if it does is the store kept to undo the update (a copy of it), and the terms
# declared then looked up, to be looked up again once it ran.

_REMOVES = re.compile(r"\b(?:DELETE|CLEAR|DROP|MOVE|COPY)\b", re.IGNORECASE)
_ESCAPE = re.compile(r"\\[uU]")


@dataclass(frozen=True)
class Reach:
    """What statements an update's text may remove: any (``anything``), else those of these patterns
    (subject, predicate, graph; a subject or graph None: any), and every statement of these graphs."""

    anything: bool = False
    statements: frozenset[tuple[ox.NamedNode | None, ox.NamedNode, ox.NamedNode | None]] = frozenset()
    graphs: frozenset[ox.NamedNode] = frozenset()


_ANYTHING = Reach(anything=True)


def removal_reach(text: str) -> Reach | None:
    """What the SPARQL update ``text`` may remove of the statements about a term of ours; None: none.
    Deliberately loose, as :func:`may_add_subclasses` is: :data:`_ANYTHING` for what it cannot read (an
    escape, a blank node or collection in a template, a variable predicate, a graph it cannot name)."""
    if not _REMOVES.search(text):
        return None
    if _ESCAPE.search(text):
        return _ANYTHING
    tokens = _tokens(text)
    if any("\\" in token for token in tokens if not token.startswith(("'", '"'))):
        return _ANYTHING
    words = [token.upper() for token in tokens]
    names = _Names(tokens, words)
    statements: set[tuple[ox.NamedNode | None, ox.NamedNode, ox.NamedNode | None]] = set()
    graphs: set[ox.NamedNode] = set()
    for position, word in enumerate(words):
        if word == "DELETE":
            opening = position + 2 if words[position + 1 : position + 2] in (["DATA"], ["WHERE"]) else position + 1
            end = closing_brace(tokens, opening) if words[opening : opening + 1] == ["{"] else None
            triples = _triples(tokens[opening + 1 : end]) if end is not None else None
            if triples is None:
                return _ANYTHING
            within = tokens[position - 1] if words[position - 2 : position - 1] == ["WITH"] else None
            for subject, predicate, graph in triples:
                if names.may_be_ours(subject):
                    node = names.node(predicate)
                    if node is None:
                        return _ANYTHING
                    named = graph or within  # a GRAPH block's, else WITH's; else any (the default graph)
                    statements.add((names.node(subject), node, names.node(named) if named is not None else None))
        elif word in ("CLEAR", "DROP", "MOVE", "COPY"):
            emptied = _emptied(tokens[position:], words[position:], names)
            if emptied is None:
                return _ANYTHING
            graphs |= emptied
    if not statements and not graphs:
        return None
    return Reach(False, frozenset(statements), frozenset(graphs))


class _Names:
    """The IRIs an update's tokens name, under its own ``PREFIX``es over cbrs's (which its store
    declares); with a ``BASE``, a relative IRI is read as any IRI."""

    def __init__(self, tokens: Sequence[str], words: Sequence[str]) -> None:
        self.prefixes = dict(PREFIXES)
        for position, word in enumerate(words[:-2]):
            if word == "PREFIX" and tokens[position + 2].startswith("<"):
                self.prefixes[tokens[position + 1].removesuffix(":")] = tokens[position + 2][1:-1]

    def iri(self, token: str) -> str | None:
        """The absolute IRI ``token`` names, or None (a variable, a relative IRI, an unknown prefix, a literal)."""
        if token.startswith("<") and token.endswith(">"):
            return token[1:-1] if ":" in token else None
        if token == "a":
            return RDF + "type"
        prefix, colon, local = token.partition(":")
        if not colon or token.startswith(("?", "$", "_:", '"', "'")) or prefix not in self.prefixes:
            return None
        return self.prefixes[prefix] + local

    def node(self, token: str) -> ox.NamedNode | None:
        iri = self.iri(token)
        try:
            return ox.NamedNode(iri) if iri is not None else None
        except ValueError:
            return None

    def may_be_ours(self, subject: str) -> bool:
        """Whether a template's subject may be a term of ours: a variable, a blank node, or a name that
        is one or cannot be read for certain."""
        if subject.startswith(('"', "'")) or subject[:1].isdigit() or subject[:1] in "+-.":
            return False  # a literal: no subject (the update is refused as it runs)
        iri = self.iri(subject)
        return iri is None or iri.startswith(OWN_NAMESPACES)


def _triples(template: Sequence[str]) -> list[tuple[str, str, str | None]] | None:
    """The (subject, predicate, the ``GRAPH`` block's name or None) of each triple of a template's tokens
    (inside its braces), read as Turtle is; None for what it does not read (brackets, quoted triples, a
    stray token). States: S a subject, P a predicate, O an object, A after an object."""
    found: list[tuple[str, str, str | None]] = []
    state, subject = "S", ""
    graph: str | None = None
    tokens = iter(template)
    for token in tokens:
        if token in ("[", "(", "<") or token.startswith("<<"):  # a blank node, a collection, a quoted triple
            return None
        if token.upper() == "GRAPH":
            graph = next(tokens, None)  # its '{' follows
        elif token == "^^":
            next(tokens, None)  # the datatype
        elif token.startswith("@") or (token == "." and state == "S"):
            continue  # a language tag; an empty statement
        elif token in ("{", "}"):
            state = "S"
            if token == "}":
                graph = None
        elif state == "S":
            subject, state = token, "P"
        elif state == "P":
            if token in (".", ";"):
                state = "S" if token == "." else "P"
                continue
            found.append((subject, token, graph))
            state = "O"
        elif state == "O":
            state = "A"
        else:
            state = {",": "O", ";": "P", ".": "S"}.get(token, "?")
            if state == "?":
                return None
    return found


def _emptied(tokens: Sequence[str], words: Sequence[str], names: _Names) -> set[ox.NamedNode] | None:
    """The graphs a ``CLEAR``/``DROP``/``MOVE``/``COPY`` at the start of ``tokens`` empties; None for the
    default graph, ``NAMED``, ``ALL`` or a name it cannot read."""
    operation, position = words[0], 1 + (words[1:2] == ["SILENT"])

    def graph(at: int) -> tuple[ox.NamedNode | None, int]:
        at += words[at : at + 1] == ["GRAPH"]
        return (names.node(tokens[at]) if at < len(tokens) else None), at + 1

    source, position = graph(position)
    if operation in ("CLEAR", "DROP"):
        return {source} if source is not None else None
    if words[position : position + 1] != ["TO"]:
        return None
    target, _ = graph(position + 1)
    if target is None or (operation == "MOVE" and source is None):
        return None
    return {target, source} if operation == "MOVE" and source is not None else {target}


# Whether the store holds a statement the update may remove about a term of ours that a class is under.
_SAID_WITH = (
    "SELECT ?c ?p ?ns0 ?ns1 ?ns2\n"
    "WHERE { ?x <http://www.w3.org/2000/01/rdf-schema#subClassOf> ?c . ?c ?p ?o .\n"
    "  FILTER (STRSTARTS(STR(?c), ?ns0) || STRSTARTS(STR(?c), ?ns1) || STRSTARTS(STR(?c), ?ns2)) } LIMIT 1"
)
_SAID_WITH_IN = (
    "SELECT ?c ?p ?g ?ns0 ?ns1 ?ns2\n"
    "WHERE { ?x <http://www.w3.org/2000/01/rdf-schema#subClassOf> ?c . GRAPH ?g { ?c ?p ?o }\n"
    "  FILTER (STRSTARTS(STR(?c), ?ns0) || STRSTARTS(STR(?c), ?ns1) || STRSTARTS(STR(?c), ?ns2)) } LIMIT 1"
)
_SAID_IN = (
    "SELECT ?c ?g ?ns0 ?ns1 ?ns2\n"
    "WHERE { ?x <http://www.w3.org/2000/01/rdf-schema#subClassOf> ?c . GRAPH ?g { ?c ?p ?o }\n"
    "  FILTER (STRSTARTS(STR(?c), ?ns0) || STRSTARTS(STR(?c), ?ns1) || STRSTARTS(STR(?c), ?ns2)) } LIMIT 1"
)


def may_remove_declarations(store: Store, text: str) -> bool:
    """Whether the SPARQL update ``text`` may remove the last statement about a term of ours that a class
    in ``store`` is under: its :func:`removal_reach`, then whether the store holds such a statement
    within that reach (one query for all, no copy)."""
    reach = removal_reach(text)
    if reach is None:
        return False
    if reach.anything:
        return True
    spaces = _spaces()
    asked: list[tuple[str, Mapping[str, Term]]] = []
    for subject, predicate, graph in sorted(reach.statements, key=str):
        about: dict[str, Term] = {"p": predicate, **spaces} | ({"c": subject} if subject is not None else {})
        asked.append((_SAID_WITH, about) if graph is None else (_SAID_WITH_IN, {"g": graph, **about}))
    asked += [(_SAID_IN, {"g": g, **spaces}) for g in sorted(reach.graphs, key=str)]
    return any(store.select_each(asked))


def says_used_terms(store: Store, graph: ox.NamedNode) -> bool:
    """Whether ``graph`` holds a statement about a term of ours that a class in ``store`` is under: else
    emptying it cannot leave one declared nowhere, and what it holds need not be read to check it."""
    return bool(store.select_each([(_SAID_IN, {"g": graph, **_spaces()})])[0])


def _spaces() -> dict[str, Term]:
    """The values of :data:`_SAID_WITH`'s and :data:`_SAID_IN`'s namespaces."""
    assert len(OWN_NAMESPACES) == 3
    return {f"ns{n}": ox.Literal(namespace) for n, namespace in enumerate(OWN_NAMESPACES)}


@dataclass(frozen=True)
class Watch:
    """What a non-data update is checked against once it ran (:func:`check_watched`): the subclass axioms
    before it, when it may add one; the terms of ours a class was under and the store declared, when it
    may remove a statement about one."""

    axioms: set[ox.Quad] | None
    declared: frozenset[ox.NamedNode]


def watch_update(store: Store, text: str) -> Watch | None:
    """What to check the update ``text`` against once it ran on ``store``; None: it can neither add a
    subclass axiom nor remove a term's last statement, and is not checked (nor the store kept for it)."""
    adds, removes = may_add_subclasses(text), may_remove_declarations(store, text)
    if not adds and not removes:
        return None
    axioms = subclass_axioms(store)
    declared: frozenset[ox.NamedNode] = frozenset()
    if removes:
        used = {quad.object for quad in axioms if _ours(quad.object)}
        declared = frozenset(t for t in used if isinstance(t, ox.NamedNode) and _declarations(store, t))
    return Watch(axioms if adds else None, declared)


def check_watched(store: Store, watch: Watch, undone: str = "nothing was written") -> None:
    """Raise :class:`UndeclaredSuperclassError` for a subclass axiom the update just run on ``store`` added
    under an undeclared term, or :class:`RemovedDeclarationError` for a term declared before that a class
    is still under and nothing now declares (while the store holds its vocabulary)."""
    if watch.axioms is not None:
        check_added_superclasses(store, watch.axioms, undone)
    if not watch.declared:
        return
    users: dict[ox.NamedNode, str] = {}
    for quad in sorted(subclass_axioms(store), key=str):
        if quad.object in watch.declared:
            assert isinstance(quad.object, ox.NamedNode)
            users.setdefault(quad.object, _name(quad.subject))
    for term in sorted(users, key=str):
        if not _declarations(store, term) and _holds_vocabulary(store, _namespace(term)):
            raise RemovedDeclarationError("the update", users[term], term.value, undone)


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
