"""The one prefix table that Turtle output, SPARQL queries and the browser share.

Every IRI cbrs mints lives under ``BASE``.
"""

from __future__ import annotations

import difflib
import re
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from contextvars import ContextVar
from enum import StrEnum
from typing import Protocol

from pyoxigraph import NamedNode

BASE = "https://w3id.org/cbrs/"

CBRS = BASE + "core#"
HOME = BASE + "home#"
ACT = BASE + "action#"
SVC = BASE + "service#"
REQ = BASE + "requirement#"
WORLD = BASE + "world#"
GRAPH = BASE + "graph/"
GENID = BASE + ".well-known/genid/"
DUL = "http://www.ontologydesignpatterns.org/ont/dul/DUL.owl#"

RDF = "http://www.w3.org/1999/02/22-rdf-syntax-ns#"
RDFS = "http://www.w3.org/2000/01/rdf-schema#"
OWL = "http://www.w3.org/2002/07/owl#"
XSD = "http://www.w3.org/2001/XMLSchema#"

PREFIXES: dict[str, str] = {
    "cbrs": CBRS,
    "home": HOME,
    "act": ACT,
    "svc": SVC,
    "req": REQ,
    "world": WORLD,
    "graph": GRAPH,
    "genid": GENID,
    "dul": DUL,
    "rdf": RDF,
    "rdfs": RDFS,
    "owl": OWL,
    "xsd": XSD,
    "skos": "http://www.w3.org/2004/02/skos/core#",
    "dcterms": "http://purl.org/dc/terms/",
    # the standard vocabularies cbrs is aligned with (ontologies/alignments.ttl, docs/vocabularies.md)
    "align": BASE + "align#",
    "sosa": "http://www.w3.org/ns/sosa/",
    "profile": "http://www.daml.org/services/owl-s/1.1/Profile.owl#",
    "process": "http://www.daml.org/services/owl-s/1.1/Process.owl#",
    "service": "http://www.daml.org/services/owl-s/1.1/Service.owl#",
    "expr": "http://www.daml.org/services/owl-s/1.1/generic/Expression.owl#",
    "qudt": "http://qudt.org/schema/qudt/",
    "unit": "http://qudt.org/vocab/unit/",
    "quantitykind": "http://qudt.org/vocab/quantitykind/",
    "soma": "http://www.ease-crc.org/ont/SOMA.owl#",
}


_SCHEME = re.compile(r"[A-Za-z][A-Za-z0-9+.-]*")
_PREFIX_LIKE = re.compile(r"[A-Za-z][A-Za-z0-9_+.-]*")
"""What a person typing a prefix (or a scheme) types before the colon: ``lab_4``, ``hom``."""

BARE_SCHEMES = frozenset({"http", "https", "urn", "tag", "mailto", "file", "data", "did", "geo", "tel", "info"})
"""The IRI schemes a name is read as an absolute IRI of without ``//`` after the colon (``urn:uuid:...``,
``tag:lab.example,2026:cup``, ``mailto:``): those RDF data writes so. Any other ``x:local`` whose ``x`` is
no declared prefix is a mistyped prefix (``hom:Cup``), refused, not an IRI of scheme ``x`` that names
nothing; an IRI of another scheme is written in ``<>`` or with its authority (``ftp://...``)."""


class GraphName(StrEnum):
    """The named graphs of a cbrs store, each holding one kind of knowledge."""

    ONTOLOGY = "ontology"
    SERVICES = "services"
    REQUIREMENTS = "requirements"
    MAP = "map"
    WORLD = "world"
    PLANS = "plans"
    LIVENESS = "liveness"
    ENTAILED = "entailed"
    """What the alignments entail in standard vocabularies, derived from the other graphs and rewritten
    whenever they change (kb/standard_terms.py); not to be written by hand."""

    @property
    def iri(self) -> str:
        return GRAPH + self.value

    @property
    def node(self) -> NamedNode:
        return NamedNode(self.iri)


class StoreNames(Protocol):
    """A store's own prefixes for the namespaces the table leaves out (:mod:`cbrs.kb.derived_prefixes`)."""

    @property
    def prefixes(self) -> Mapping[str, str]: ...

    def shorten(self, iri: str) -> str | None: ...

    def namespace_of(self, prefix: str) -> str | None: ...


_store_names: ContextVar[StoreNames | None] = ContextVar("cbrs_store_names", default=None)


@contextmanager
def store_names(names: StoreNames | None) -> Iterator[None]:
    """Within the block, :func:`expand` and :func:`shorten` also use ``names`` (a CLI command's store's
    derived prefixes, so that it prints and takes the names the browser shows); None: the table's alone."""
    token = _store_names.set(names)
    try:
        yield
    finally:
        _store_names.reset(token)


def active_store_names() -> StoreNames | None:
    """The names :func:`store_names` set for the current block (None: none set, the table's alone)."""
    return _store_names.get()


def expand(name: str) -> str:
    """Expand ``prefix:local`` with the prefix table (and the store's derived prefixes within
    :func:`store_names`); an IRI in ``<>``, one with an authority (``scheme://``) or one of
    :data:`BARE_SCHEMES` passes through unchanged.

    Raises :class:`~cbrs.kb.name_errors.UnknownPrefixError` (a ``ValueError``) for ``x:local`` with an
    ``x`` that is neither a prefix nor such a scheme, naming the prefixes nearest ``x``; a plain
    ``ValueError`` for a name with no colon.
    """
    if name.startswith("<") and name.endswith(">"):
        return name[1:-1]
    prefix, sep, local = name.partition(":")
    if sep and prefix in PREFIXES:
        return PREFIXES[prefix] + local
    names = _store_names.get()
    if sep and names is not None and not local.startswith("//"):  # http://... is an IRI, never a name
        found = names.namespace_of(prefix)
        if found is not None:
            return found + local
    if sep and is_absolute_iri(name):
        return name
    known = ", ".join(PREFIXES)
    if names is not None and names.prefixes:
        known += f", or one of the store's {len(names.prefixes)} derived prefixes"
    if sep and (not prefix or _PREFIX_LIKE.fullmatch(prefix) is not None):
        from cbrs.kb.name_errors import UnknownPrefixError  # kb.errors writes IRIs with this module

        raise UnknownPrefixError(name, prefix, near_prefixes(prefix) if prefix else [], known)
    near = near_prefixes(prefix) if sep else []
    hint = f"; did you mean {' or '.join(f'{p}:{local}' for p in near)}?" if near else ""
    raise ValueError(f"{name!r} is neither an absolute IRI nor a prefixed name with a known prefix ({known}){hint}")


def is_absolute_iri(name: str) -> bool:
    """Whether ``name``, written bare, is read as an absolute IRI rather than a prefixed name: its scheme
    is followed by an authority (``//``) or is one of :data:`BARE_SCHEMES` (any case, as schemes are)."""
    scheme, sep, rest = name.partition(":")
    if not sep or _SCHEME.fullmatch(scheme) is None:
        return False
    return rest.startswith("//") or scheme.lower() in BARE_SCHEMES


def near_prefixes(prefix: str) -> list[str]:
    """The declared prefixes (and, within :func:`store_names`, the store's derived ones) closest to
    ``prefix``, a mistyped one: the best three, case aside."""
    names = _store_names.get()
    known = [*PREFIXES, *(names.prefixes if names is not None else ())]
    by_folded = {name.casefold(): name for name in reversed(known)}
    return [by_folded[n] for n in difflib.get_close_matches(prefix.casefold(), list(by_folded), n=3)]


def shorten(iri: str) -> str:
    """The prefixed form of ``iri`` when a table prefix covers it (or, within :func:`store_names`, one
    of the store's derived prefixes), else the IRI itself."""
    best = ""
    for prefix, namespace in PREFIXES.items():
        if iri.startswith(namespace) and len(namespace) > len(PREFIXES.get(best, "")):
            best = prefix
    if best:
        local = iri[len(PREFIXES[best]) :]
        if local and all(ch.isalnum() or ch in "_-." for ch in local):
            return f"{best}:{local}"
        return iri
    names = _store_names.get()
    return (names.shorten(iri) or iri) if names is not None else iri


def written(iri: str) -> str:
    """``iri`` as Turtle writes it: its prefixed form when a table prefix covers it, else ``<iri>``."""
    short = shorten(iri)
    return short if short != iri else f"<{iri}>"
