"""Short prefixes for the namespaces a store uses that cbrs's prefix table does not declare.

OWLS-TC's IRIs (``http://127.0.0.1/ontology/books.owl#Novel``) have no prefix. One prefix is derived per
such namespace from its last path segment that has a letter, without its file extension: ``books:Novel``.
The browser shows names so and the CLI prints and takes them so (docs/web.md, "Names, pictures,
keyboard", and "Names in the CLI" there). The rule:

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

Reading the table means reading every term of the store (0.75 s on OWLS-TC), so :func:`for_store`
keeps it: in the process per store generation, and for an on-disk store also in a file of the store's
folder (:data:`CACHE_FILE`), keyed by the store's data files, so that one CLI command after another
reads it once until the store is written.
"""

from __future__ import annotations

import hashlib
import json
import os
import re
import threading
import weakref
from collections import defaultdict
from collections.abc import Callable, Iterable, Mapping
from pathlib import Path
from typing import TYPE_CHECKING

import pyoxigraph as ox

from cbrs.kb.namespaces import PREFIXES

if TYPE_CHECKING:
    from cbrs.kb import KnowledgeBase
    from cbrs.kb.store import Store

__all__ = ["CACHE_FILE", "StoreNames", "derive", "for_store", "name_for", "namespace", "namespaces_in", "read"]

# Every term the store holds, in any position (graph names are the cbrs graph: prefixes). The IRIs are
# picked out here: with FILTER(isIRI(?t)) the query took 2.9 s on OWLS-TC, without it 1.2 s.
_TERMS = "SELECT DISTINCT ?t WHERE { { ?t ?p ?o } UNION { ?s ?t ?o } UNION { ?s ?p ?t } }"
# IRIs that name documents, not terms: an ontology (and a module it imports), its version IRI and those of
# its other versions. Protégé gives an ontology <http://lab/kit> the version IRI <http://lab/kit/1.0>, whose
# namespace http://lab/kit/ derives "kit" as the terms' http://lab/kit# does: neither got it, and the lab's
# terms were shown as kit1:MeasuringBeaker. A namespace that terms use is still read from the terms.
_DOCUMENTS = """PREFIX owl: <http://www.w3.org/2002/07/owl#>
SELECT DISTINCT ?d WHERE {
  { ?d a owl:Ontology } UNION { ?o owl:versionIRI|owl:imports|owl:priorVersion ?d }
  UNION { ?o owl:backwardCompatibleWith|owl:incompatibleWith ?d }
}"""
_EXTENSION = re.compile(r"\.[A-Za-z][A-Za-z0-9]*$")
_NOT_IN_PREFIX = re.compile(r"[^A-Za-z0-9_-]")

CACHE_FILE = "cbrs-derived-prefixes.json"
"""The table of an on-disk store, kept in its folder with the key of the data files it was read from."""
_RULE = "2"  # bumped when the rule changes, so that a kept table of the old rule is not taken


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
    """The derived prefixes of the namespaces of every IRI in ``kb``'s store, read now."""
    return derive(namespaces_in(kb.store))


def namespaces_in(store: Store) -> set[str]:
    """The namespaces of every IRI ``store`` holds (each term read: :func:`for_store` keeps the table), but
    for the IRIs that only name ontologies (:data:`_DOCUMENTS`)."""
    found = set()
    solutions = store.query(_TERMS)
    if not isinstance(solutions, ox.QuerySolutions):  # a SELECT's answer always is
        return set()
    documents = _documents(store)
    for row in solutions:
        term = row[0]
        if isinstance(term, ox.NamedNode) and term.value not in documents:
            ns = namespace(term.value)
            if ns is not None:
                found.add(ns)
    return found


def _documents(store: Store) -> set[str]:
    """The IRIs of the store that name ontologies, their versions and what they import, and nothing else."""
    solutions = store.query(_DOCUMENTS)
    if not isinstance(solutions, ox.QuerySolutions):
        return set()
    return {row[0].value for row in solutions if isinstance(row[0], ox.NamedNode)}


_kept: weakref.WeakKeyDictionary[Store, tuple[int, dict[str, str]]] = weakref.WeakKeyDictionary()
_kept_guard = threading.Lock()


def for_store(kb: KnowledgeBase) -> dict[str, str]:
    """:func:`read`, kept per store generation in this process and, for an on-disk store, in its folder
    between processes; a remote store (which counts no generations) is read every time."""
    store = kb.store
    generation = getattr(store, "generation", None)
    if generation is None:
        return read(kb)
    with _kept_guard:
        kept = _kept.get(store)
    if kept is not None and kept[0] == generation:
        return kept[1]
    # the data files say what the store holds only before this process writes to it (its writes stay
    # in memory until it closes the store)
    folder = None if getattr(store, "in_memory", True) or generation else Path(store.location)
    key = _files_key(folder) if folder is not None else None
    table = _cached(folder, key) if folder is not None and key is not None else None
    if table is None:
        table = read(kb)
        if folder is not None and key is not None:
            _keep(folder, key, table)
    with _kept_guard:
        _kept[store] = (generation, table)
    return table


def _files_key(folder: Path) -> str | None:
    """A digest of the store's data files: RocksDB's tables (``*.sst``, never changed once written, a
    new number for every new one) and its non-empty write-ahead logs (``*.log``). A write adds to a log
    and then a new table, so the key changes with every write; an open that writes nothing keeps it."""
    try:
        files = sorted(
            (entry.name, entry.stat().st_size)
            for entry in os.scandir(folder)
            if entry.name.endswith(".sst") or (entry.name.endswith(".log") and entry.stat().st_size > 0)
        )
    except OSError:
        return None
    if not files:
        return None
    text = json.dumps([_RULE, sorted(PREFIXES.items()), files])
    return hashlib.sha256(text.encode()).hexdigest()


def _cached(folder: Path, key: str) -> dict[str, str] | None:
    try:
        kept = json.loads((folder / CACHE_FILE).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    if not isinstance(kept, dict) or kept.get("key") != key or not isinstance(kept.get("prefixes"), dict):
        return None
    table: dict[str, str] = {str(k): str(v) for k, v in kept["prefixes"].items()}
    return table


def _keep(folder: Path, key: str, table: dict[str, str]) -> None:
    """Write the table beside the store's files; a folder that cannot be written keeps none."""
    target = folder / CACHE_FILE
    partial = folder / f".{CACHE_FILE}.{os.getpid()}"
    try:
        partial.write_text(json.dumps({"key": key, "prefixes": table}), encoding="utf-8")
        os.replace(partial, target)
    except OSError:
        partial.unlink(missing_ok=True)


class StoreNames:
    """A store's derived prefixes in both directions, read on first use (:func:`for_store`): a command
    whose names all have declared prefixes never reads them. ``opened`` gives the knowledge base, or
    None while it is not open (then there are none: naming an IRI never opens a store). With
    ``shortens=False`` they are taken but never printed (JSON keeps whole IRIs, its text included)."""

    def __init__(self, opened: Callable[[], KnowledgeBase | None], shortens: bool = True) -> None:
        self._opened = opened
        self._shortens = shortens
        self._tables: tuple[dict[str, str], dict[str, str]] | None = None

    @property
    def prefixes(self) -> dict[str, str]:
        """Prefix → namespace."""
        return self._both()[0]

    def shorten(self, iri: str) -> str | None:
        """``prefix:local`` for ``iri`` when a derived prefix covers it and its local part is a name."""
        ns = namespace(iri) if self._shortens else None
        if ns is None:
            return None
        prefix = self._both()[1].get(ns)
        local = iri[len(ns) :]
        if prefix is None or not local or not all(ch.isalnum() or ch in "_-." for ch in local):
            return None
        return f"{prefix}:{local}"

    def namespace_of(self, prefix: str) -> str | None:
        return self._both()[0].get(prefix)

    def _both(self) -> tuple[dict[str, str], dict[str, str]]:
        kb = self._opened()
        if kb is None:
            return {}, {}
        if self._tables is not None and getattr(kb.store, "generation", None) is None:
            return self._tables  # a remote store: read once a command, as the browser reads it once a page
        table = for_store(kb)  # the same table until the store is written
        if self._tables is None or self._tables[0] is not table:
            self._tables = table, {ns: prefix for prefix, ns in table.items()}
        return self._tables
