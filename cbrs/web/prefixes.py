"""Short prefixes for the namespaces a store uses that cbrs's prefix table does not declare.

OWLS-TC's IRIs (``http://127.0.0.1/ontology/books.owl#Novel``) have no prefix, so the pages showed them
whole or by a bare tail (``books.owl#Novel``). The browser derives one prefix per such namespace from
its last path segment that has a letter, without its file extension: ``books:Novel``. The rule
(docs/web.md, "Names, pictures, keyboard"):

- a namespace is an IRI up to its last ``#``, or up to its last ``/`` when it has no ``#``; one that a
  declared namespace (:data:`cbrs.kb.namespaces.PREFIXES`) starts is left to the declared prefix, and
  one that starts a declared namespace (``https://w3id.org/cbrs/``) gets none;
- the name is made a SPARQL prefix: characters other than ASCII letters, digits, ``_`` and ``-``
  become ``_``, leading ``_`` and ``-`` go, and a name that does not then start with a letter gets
  ``ns`` in front (``ns3wheeledcar_price_service``);
- a name that is declared, or that more than one namespace derives, is taken by none of them (names
  compared without case, so ``Service`` counts as the declared ``service``): those namespaces, in IRI
  order, get the name with a number (``protont1``, ``protont2``), skipping any number that is declared
  or some namespace's own name. So two namespaces never share a prefix, a derived prefix never shadows
  a declared one, and the same set of namespaces always gets the same prefixes.

The table is read from the store once per store generation (:func:`cbrs.web.context.per_generation`),
and once per request on a remote store.
"""

from __future__ import annotations

import re
from collections import defaultdict
from collections.abc import Iterable, Mapping

import pyoxigraph as ox
from flask import g, has_app_context

from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import PREFIXES
from cbrs.web import context

# Every term the store holds, in any position (graph names are the cbrs graph: prefixes). The IRIs are
# picked out here: with FILTER(isIRI(?t)) the query took 2.9 s on OWLS-TC, without it 1.2 s.
_TERMS = "SELECT DISTINCT ?t WHERE { { ?t ?p ?o } UNION { ?s ?t ?o } UNION { ?s ?p ?t } }"
_EXTENSION = re.compile(r"\.[A-Za-z][A-Za-z0-9]*$")
_NOT_IN_PREFIX = re.compile(r"[^A-Za-z0-9_-]")


def namespace(iri: str) -> str | None:
    """``iri`` up to its last ``#``, else up to its last ``/`` after the authority; ``None`` when it has no
    local name after that (a namespace itself, ``urn:`` IRIs)."""
    cut = iri.rfind("#")
    if cut < 0:
        _, scheme, rest = iri.partition("://")
        if not scheme or "/" not in rest:
            return None
        cut = iri.rfind("/")
    if cut == len(iri) - 1:
        return None
    return iri[: cut + 1]


def name_for(namespace: str) -> str:
    """The prefix ``namespace`` asks for, before collisions are settled: its last path segment with a
    letter in it (or its host's first such label), without extension, as a SPARQL prefix name."""
    _, _, rest = namespace.rstrip("#/").partition("://")
    host, _, path = rest.partition("/")
    segments = [s for s in reversed(path.split("/")) if any(c.isalpha() for c in s)]
    labels = [s for s in host.split(".") if any(c.isalpha() for c in s) and s != "www"]
    raw = _EXTENSION.sub("", segments[0]) if segments else (labels[0] if labels else "")
    name = _NOT_IN_PREFIX.sub("_", raw).lstrip("_-")
    return name if name[:1].isalpha() and name[:1].isascii() else "ns" + name


def derive(namespaces: Iterable[str], declared: Mapping[str, str] = PREFIXES) -> dict[str, str]:
    """Prefix → namespace for each of ``namespaces`` that no ``declared`` namespace covers (the rule in
    the module's docstring). Names are compared without case: ``Service`` would read as ``service``."""
    declared_namespaces = tuple(declared.values())
    wanted: dict[str, list[tuple[str, str]]] = defaultdict(list)  # folded name → (name, namespace)
    for ns in sorted(set(namespaces)):
        # under a declared namespace, or the start of one (https://w3id.org/cbrs/, home of cbrs's own)
        if not ns.startswith(declared_namespaces) and not any(d.startswith(ns) for d in declared_namespaces):
            name = name_for(ns)
            wanted[name.casefold()].append((name, ns))
    taken = {name.casefold() for name in declared}
    table: dict[str, str] = {}
    for folded, owners in wanted.items():
        if len(owners) == 1 and folded not in taken:
            table[owners[0][0]] = owners[0][1]
    taken |= set(wanted)
    for folded in sorted(wanted):
        owners = wanted[folded]
        if len(owners) == 1 and owners[0][0] in table:
            continue
        number = 1
        for name, ns in owners:
            while f"{folded}{number}" in taken:
                number += 1
            table[f"{name}{number}"] = ns
            taken.add(f"{folded}{number}")
            number += 1
    return table


def read(kb: KnowledgeBase) -> dict[str, str]:
    """The derived prefixes of the namespaces of every IRI in ``kb``'s store."""
    found = set()
    solutions = kb.query(_TERMS)
    if not isinstance(solutions, ox.QuerySolutions):  # a SELECT's answer always is
        return {}
    for row in solutions:
        term = row[0]
        if isinstance(term, ox.NamedNode):
            ns = namespace(term.value)
            if ns is not None:
                found.add(ns)
    return derive(found)


def derived() -> dict[str, str]:
    """The current store's derived prefixes (prefix → namespace); none outside an app context."""
    return _tables()[0]


def by_namespace() -> dict[str, str]:
    """Namespace → derived prefix, for shortening."""
    return _tables()[1]


def _tables() -> tuple[dict[str, str], dict[str, str]]:
    """Both directions of the table, kept per store generation and, for a remote store (which counts no
    generations), per request: a page shortens hundreds of IRIs."""
    if not has_app_context():
        return {}, {}
    if "cbrs_derived_prefixes" not in g:
        kb = context.kb()

        def compute() -> tuple[dict[str, str], dict[str, str]]:
            table = read(kb)
            return table, {ns: prefix for prefix, ns in table.items()}

        g.cbrs_derived_prefixes = context.per_generation("derived_prefixes", compute)
    tables: tuple[dict[str, str], dict[str, str]] = g.cbrs_derived_prefixes
    return tables
