"""A class a load declares under a term of cbrs's own vocabularies hangs from a declared class.

``lab8:Apple rdfs:subClassOf home:Fruit``, where the home ontology has no ``home:Fruit``, loaded: the apple
was below nothing the components know, a task to move it had no plan, and the refusal said only that no
component provides the goal (docs/tasks.md, "An eighth round"). The vocabularies cbrs ships (home:,
cbrs:, act:) are its own: a lab adds terms to them only by declaring them (the tests' home:GlueStick is
declared where it is used), so a superclass there that is the subject of nothing, in the store or in the
load, is a slip or a guess, once the store holds that vocabulary (a store seeded without it, as some tests'
are, declares none of its terms). A lab's own namespace is left alone: its terms may come in a later file."""

from __future__ import annotations

from collections.abc import Iterable, Sequence

import pyoxigraph as ox

from cbrs.kb.errors import UndeclaredSuperclassError
from cbrs.kb.namespaces import OWL, PREFIXES, RDF, RDFS
from cbrs.kb.shapes import did_you_mean, line_of
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
