"""The names a SPARQL query uses that the store mentions nowhere, each with the names likely meant.

A misspelt term matches nothing, and a query of one gives no rows and no word of why: the eighth round's
``?cup home:isLocatedIn world:Kitchen`` and the ninth's ``lab9:Notebook1 home:isLocatedOnn ?support`` each
gave "(0 rows)". ``cbrs query`` says on standard error which names of its text name nothing in the store,
and the browser's SPARQL editor shows the same under an empty result, as ``cbrs update`` does for an update
that changed nothing. The SPARQL endpoint answers as the protocol says, with nothing added.

A name counts as mentioned when some triple of any graph has it as subject, predicate or object, or it
names a graph. A datatype (after ``^^``) and a function (before ``(``) are no terms of the store's triples,
and are not asked about.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING

import pyoxigraph as ox

from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.sparql_hints import TOKENS

if TYPE_CHECKING:
    from cbrs.kb import KnowledgeBase
    from cbrs.kb.store import Term

__all__ = ["unmentioned_bindings", "unmentioned_names"]


def unmentioned_names(kb: KnowledgeBase, text: str, prefixes: Mapping[str, str] = {}) -> list[str]:
    """A note for each name of the query ``text`` that the store mentions nowhere, in the order the text
    uses them: "nothing in the store mentions home:isLocatedOnn; did you mean home:isLocatedOn?". Prefixed
    names are read with the text's own ``PREFIX`` declarations, then ``prefixes`` (the store's derived
    ones), then cbrs's; a name whose prefix none declares is the parser's to refuse."""
    tokens = list(TOKENS.finditer(text))
    declared: dict[str, str] = {}
    skip: set[int] = set()
    for index, token in enumerate(tokens[:-2]):
        word, name, iri = token.group("word"), tokens[index + 1].group("pname"), tokens[index + 2].group("iri")
        if word is not None and word.upper() == "PREFIX" and name is not None and iri is not None:
            declared[name.removesuffix(":")] = iri[1:-1]
            skip.update((index + 1, index + 2))
    table = {**PREFIXES, **prefixes, **declared}
    graphs = set(kb.store.graphs())
    notes: dict[str, str] = {}
    for index, token in enumerate(tokens):
        written, full = _name(token, table)
        if index in skip or full is None or written in notes or full in graphs:
            continue
        before, after = text[: token.start()].rstrip(), text[token.end() :].lstrip()
        if before.endswith("^^") or after.startswith("("):  # a datatype or a function: no term of a triple
            continue
        if not _mentions(kb, full):
            from cbrs.task_names import near_names  # the action model: only for a name that names nothing

            near = [_prefixed(name, declared) for name in near_names(kb, full)]
            notes[written] = f"nothing in the store mentions {written}" + (
                f"; did you mean {' or '.join(near)}?" if near else ""
            )
    return list(notes.values())


def unmentioned_bindings(kb: KnowledgeBase, name: str, values: Mapping[str, Term | str | int | float]) -> list[str]:
    """A note for each IRI bound to a parameter of the named query ``name`` that the store mentions nowhere,
    in the order of ``values``: "nothing in the store mentions <...#DynamicPerceptonComponent> (bound to
    kind); did you mean cbrs:DynamicPerceptionComponent?". A misspelt class bound so gave "(0 rows)" and
    no word of why; ``cbrs query --name`` prints these, and a program calls this as it does. The values are
    read as the query reads them (a bad one is the query's ``BindingError``)."""
    from cbrs.task_names import near_names  # the action model: only for a name that names nothing

    query = kb.queries.get(name)
    notes = []
    for parameter, term in query.bind(values).items():
        if query.parameters[parameter].kind != "iri" or not isinstance(term, ox.NamedNode):
            continue
        if _mentions(kb, term.value):
            continue
        near = near_names(kb, term.value) if "://" in term.value else []
        hint = f"; did you mean {' or '.join(near)}?" if near else ""
        notes.append(f"nothing in the store mentions <{term.value}> (bound to {parameter}){hint}")
    return notes


def _name(token: object, table: Mapping[str, str]) -> tuple[str, str | None]:
    """The token as written and the IRI it names, or None: not a name, a relative IRI, an unknown prefix."""
    assert hasattr(token, "group")
    iri, name = token.group("iri"), token.group("pname")
    if iri is not None:
        full = iri[1:-1]
        return iri, full if ":" in full else None
    if name is not None and ":" in name:
        prefix, local = name.split(":", 1)
        if prefix in table and local:
            return name, table[prefix] + local
    return "", None


def _prefixed(name: str, declared: Mapping[str, str]) -> str:
    """``name`` (as :func:`near_names` writes it: prefixed, or a whole ``<IRI>``) with a prefix the query
    declares itself, as the query would write it."""
    if name.startswith("<"):
        for prefix, namespace in declared.items():
            if name[1:-1].startswith(namespace) and len(name) - 2 > len(namespace):
                return f"{prefix}:{name[1 + len(namespace) : -1]}"
    return name


def _mentions(kb: KnowledgeBase, iri: str) -> bool:
    node = ox.NamedNode(iri)
    return any(
        True
        for pattern in ((node, None, None), (None, node, None), (None, None, node))
        for _ in kb.store.quads(*pattern)
    )
