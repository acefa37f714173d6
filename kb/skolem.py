"""Skolemised nodes (blank nodes the loader named under ``GENID``) and what hangs off a resource through them.

A description, an action model or a restriction is a named resource plus the nodes it reaches through
skolem IRIs; the registry reads one that way from the store, the shapes check one that way in new
input, and the store upgrade replaces one that way. This is that one walk.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable

import pyoxigraph as ox

from cbrs.kb.namespaces import GENID

__all__ = ["closure", "is_skolem", "quads_by_subject"]

Node = ox.NamedNode | ox.BlankNode | ox.Triple


def is_skolem(term: object) -> bool:
    """Whether ``term`` is a node the loader made from a blank node."""
    return isinstance(term, ox.NamedNode) and term.value.startswith(GENID)


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
) -> list[ox.Quad]:
    """The quads about ``roots`` and, recursively, about the ``inner`` nodes they reach (each node once)."""
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
            if inner(quad.object):
                pending.append(quad.object)  # type: ignore[arg-type]
    return found
