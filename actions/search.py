"""Bidirectional breadth-first search over the service resource graph (paper section 4).

* **Forward**, from SRI, by the qualified post-service / post-action criterion: layer k holds the
  vertices whose every input and precondition is met by SRI or by vertices of earlier layers (a
  component can run only when all it needs is there). The layer number is the vertex's *level*; the
  forward search also keeps, per vertex, the cheapest cost to reach it (its own response time plus
  the cheapest provider of each need: the additive estimate of planning heuristics).
* **Backward**, from SRO and SRE, by the qualified pre-service / pre-action criterion: reverse I-O
  edges reveal the pre-services, reverse P-E edges the pre-actions, layer by layer.

The two meet on the vertices both searches reached; plan extraction (``composer``) then walks back
from the goals through met vertices only, so every step it chooses can run.
"""

from __future__ import annotations

from dataclasses import dataclass

from cbrs.actions.graph import SRE, SRI, SRO, Edge, ServiceResourceGraph


@dataclass(frozen=True)
class SearchTrace:
    levels: dict[str, int]  # forward layer of every vertex the forward search enabled
    costs: dict[str, float]  # cheapest estimated cost to run each enabled vertex
    forward: tuple[Edge, ...]  # edges the forward search used (provider enabled before consumer)
    backward: tuple[Edge, ...]  # edges the backward search walked (from a goal towards SRI)
    meeting: frozenset[str]  # vertices both searches reached

    def enabled(self, iri: str) -> bool:
        return iri in self.levels


def bidirectional_search(graph: ServiceResourceGraph) -> SearchTrace:
    levels, costs, forward = _forward(graph)
    backward, reached = _backward(graph, levels)
    return SearchTrace(levels, costs, tuple(forward), tuple(backward), frozenset(reached & levels.keys()))


def _forward(graph: ServiceResourceGraph) -> tuple[dict[str, int], dict[str, float], list[Edge]]:
    levels = {SRI: 0}
    costs = {SRI: 0.0}
    used: list[Edge] = []
    pending = sorted(set(graph.vertices) - {SRI})
    layer = 0
    while pending:
        layer += 1
        enabled: list[tuple[str, float, list[Edge]]] = []
        for iri in pending:
            total, edges = 0.0, []
            for need in graph.needs(iri):
                ready = [e for e in graph.providers(iri, need) if e.source in levels]
                if not ready:
                    break
                total += min(costs[e.source] for e in ready)
                edges += ready
            else:
                enabled.append((iri, total, edges))
        if not enabled:
            break
        for iri, total, edges in enabled:
            levels[iri] = layer
            costs[iri] = graph.cost(iri) + total
            used += edges
        done = {iri for iri, _, _ in enabled}
        pending = [iri for iri in pending if iri not in done]
    return levels, costs, used


def _backward(graph: ServiceResourceGraph, levels: dict[str, int]) -> tuple[list[Edge], set[str]]:
    """Reverse breadth-first search from the goals; it stops at vertices the forward search never enabled."""
    walked: list[Edge] = []
    reached = {SRO, SRE}
    frontier = [SRO, SRE]
    while frontier:
        following: list[str] = []
        for iri in frontier:
            for need in graph.needs(iri):
                for edge in graph.providers(iri, need):
                    if edge.source not in levels or levels[edge.source] >= levels.get(iri, len(graph.vertices) + 1):
                        continue
                    walked.append(edge)
                    if edge.source not in reached:
                        reached.add(edge.source)
                        following.append(edge.source)
        frontier = following
    return walked, reached
