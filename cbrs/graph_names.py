"""Graphs as a person types them after ``--graph``: a cbrs name (``map``), ``graph:map`` (where the command
takes it: ``cbrs export``) or an IRI.

A misspelt one (``graph:mapp``) was refused saying only that the store has no such graph; :func:`graph_hint`
gives the did-you-mean over the store's graphs, each written as the command takes it and as the person wrote
theirs (``cbrs export``, ``cbrs check``, ``cbrs load``).
"""

from __future__ import annotations

import difflib
from collections.abc import Collection, Iterable

from cbrs.kb.namespaces import PREFIXES, GraphName

_OWN = {graph.iri: graph.value for graph in GraphName}


def graph_iri(given: str, prefixed: bool = True) -> str | None:
    """The IRI ``given`` names: a cbrs graph's name, ``graph:NAME`` (with ``prefixed``, for a command that
    takes it) or an IRI with ``//`` or of ``urn:``, as :func:`cbrs.kb.loader.resolve_graph` reads them; None
    for anything else."""
    if given.startswith("graph:"):
        return PREFIXES["graph"] + given.removeprefix("graph:") if prefixed else None
    try:
        return GraphName(given).iri
    except ValueError:
        pass
    return given if "://" in given or given.startswith("urn:") else None


def near_graphs(given: str, held: Iterable[str], prefixed: bool = True) -> list[str]:
    """The graphs of ``held`` (IRIs) closest to ``given``, which names none of them, written as ``given``
    is: ``graph:NAME`` for that (a name where the command does not take it, not ``prefixed``), a name for a
    word, else the IRI."""
    as_prefixed = given.startswith("graph:") and prefixed
    key = given.removeprefix("graph:") if given.startswith("graph:") and not prefixed else given
    word = not as_prefixed and "://" not in key and not key.startswith("urn:")  # a name, or what may be one
    written: dict[str, str] = {}
    for iri in set(held):
        name = _OWN.get(iri)
        if name is not None and as_prefixed:
            written[f"graph:{name}"] = iri
        elif name is not None and word:
            written[name] = iri
        elif not as_prefixed and not word:
            written[iri] = iri
    scored = sorted(((difflib.SequenceMatcher(None, key, w).ratio(), w) for w in written), reverse=True)
    best = scored[0][0] if scored else 0.0  # long IRIs share most of their letters: the best alone, or ties
    return [w for score, w in scored[:3] if score >= max(0.75, best - 0.02)]


def graph_hint(
    given: Iterable[str], held: Collection[str], own_count: bool = False, prefixed: bool = True
) -> str | None:
    """``'graph:mapp': did you mean graph:map?`` for each of ``given`` that names no graph of ``held``
    (IRIs; with ``own_count`` cbrs's own graphs count as held while the store lists them not: ``cbrs check``
    reads them empty); ``prefixed``: whether the command takes ``graph:NAME``. None when each names one,
    or none is near."""
    have = {*held, *_OWN} if own_count else set(held)
    hints = []
    for graph in given:
        iri = graph_iri(graph, prefixed)
        if iri is not None and iri in have:
            continue
        near = near_graphs(graph, have, prefixed)
        if near:
            hints.append(f"{graph!r}: did you mean {' or '.join(near)}?")
    return "; ".join(hints) or None
