"""Skolemised nodes (blank nodes the loader named under ``GENID``) and what hangs off a resource through them.

A description, an action model or a restriction is a named resource plus the nodes it reaches through
skolem IRIs; the registry reads one that way from the store, the shapes check one that way in new
input, and the store upgrade replaces one that way. This is that one walk.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable

import pyoxigraph as ox

from cbrs.kb.namespaces import GENID
from cbrs.kb.vocab import CBRS

__all__ = ["DESCRIPTION_PARTS", "closure", "is_skolem", "quads_by_subject", "skolem_digest"]

Node = ox.NamedNode | ox.BlankNode | ox.Triple

DESCRIPTION_PARTS = frozenset(
    {
        CBRS.hasOWLSModel,
        CBRS.hasSEAModel,
        CBRS.hasQoSModel,
        CBRS.hasPort,
        CBRS.hasInput,
        CBRS.hasOutput,
        CBRS.hasPrecondition,
        CBRS.hasEffect,
        CBRS.hasDeleteEffect,
    }
)
"""The properties whose values are parts of a description (its models, parameters, conditions, ports),
whether blank, skolemised or given IRIs of their own (``<camera#output1>``, as an update must write them)."""


def is_skolem(term: object) -> bool:
    """Whether ``term`` is a node the loader made from a blank node."""
    return isinstance(term, ox.NamedNode) and term.value.startswith(GENID)


def skolem_digest(term: object) -> str | None:
    """The digest of the input a skolemised node was named in (``GENID<digest>-c14n3``): nodes of one
    loaded file share it, nodes of another file have another; None for other terms."""
    if not is_skolem(term):
        return None
    digest, separator, _ = term.value[len(GENID) :].partition("-")  # type: ignore[attr-defined]
    return digest if separator else None


def quads_by_subject(quads: Iterable[ox.Quad]) -> Callable[[Node], list[ox.Quad]]:
    """A lookup of ``quads`` by subject, for :func:`closure` over quads held in memory."""
    index: dict[Node, list[ox.Quad]] = {}
    for quad in quads:
        index.setdefault(quad.subject, []).append(quad)
    return lambda node: index.get(node, [])


def closure(
    roots: Iterable[Node],
    quads_of: Callable[[Node], Iterable[ox.Quad]],
    inner: Callable[[object], bool] = is_skolem,
    parts: bool = False,
) -> list[ox.Quad]:
    """The quads about ``roots`` and, recursively, about the ``inner`` nodes they reach (each node once);
    with ``parts``, also about the named values of :data:`DESCRIPTION_PARTS` (a description's parts)."""
    found: list[ox.Quad] = []
    pending: list[Node] = list(roots)
    seen: set[Node] = set()
    while pending:
        node = pending.pop()
        if node in seen:
            continue
        seen.add(node)
        for quad in quads_of(node):
            found.append(quad)
            if inner(quad.object) or (
                parts and quad.predicate.value in DESCRIPTION_PARTS and isinstance(quad.object, ox.NamedNode)
            ):
                pending.append(quad.object)  # type: ignore[arg-type]
    return found
