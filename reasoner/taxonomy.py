"""The taxonomy index: one in-memory DAG of concepts, built once from the store.

Its links are the paper's (section 3.2): "is-a" links (rdfs:subClassOf, rdfs:subPropertyOf) and
"hasPart" links (a whole class to the class of its part, from restrictions on the dul:hasPart family).
Both point from a node up to its parent; above every node with no is-a parent sits one virtual root.
Equivalent classes, and classes in a subclass cycle, are merged into one node.

Superclasses and depth follow is-a links only (the most specific common *superclass*); whether one
entity lies below another follows both kinds. Depths and distances count links along shortest paths
(a class may have several parents).
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from cbrs.kb import KnowledgeBase

if TYPE_CHECKING:
    import networkx as nx  # imported where an index is built: cbrs serve starts without it

ROOT = "http://www.w3.org/2002/07/owl#Thing"  # the root: above every concept with no is-a parent


@dataclass(frozen=True)
class Link:
    child: str
    parent: str
    kind: str  # "is-a", "has-part" or "same"


@dataclass
class TaxonomyIndex:
    """Concept DAG with depth, ancestors and most specific common ancestor answered in memory."""

    _canonical: dict[str, str] = field(default_factory=dict)
    _parents: dict[str, dict[str, str]] = field(default_factory=dict)  # node -> {parent: link kind}
    _children: dict[str, set[str]] = field(default_factory=dict)
    _depth: dict[str, int] = field(default_factory=dict)
    _ancestors: dict[tuple[str, bool], dict[str, int]] = field(default_factory=dict)  # cache
    _is_a_up: dict[str, dict[str, int]] = field(default_factory=dict)  # cache of is_a_ancestors
    _parts: dict[str, frozenset[str]] = field(default_factory=dict)  # cache
    _part_weights: dict[str, float] | None = None
    _disjoint: dict[str, frozenset[str]] = field(default_factory=dict)  # declared, both ways, canonical
    _disjoint_closure: dict[str, frozenset[str]] = field(default_factory=dict)  # cache
    labels: dict[str, str] = field(default_factory=dict)
    frequency: dict[str, int] = field(default_factory=dict)  # uses by service descriptions

    # -- building ----------------------------------------------------------------------------

    @classmethod
    def from_kb(cls, kb: KnowledgeBase) -> TaxonomyIndex:
        """Read every term, link, use and disjointness with four named queries asked for at once (one
        request to a remote store), then build the DAG in memory."""
        link_rows, term_rows, usage_rows, disjoint_rows = kb.select_each(
            ("taxonomy_links", "taxonomy_terms", "concept_usage", "taxonomy_disjoint")
        )
        links = [Link(row["child"].value, row["parent"].value, row["link"].value) for row in link_rows]
        terms = {row["term"].value: row.get("label") for row in term_rows}
        usage = {row["concept"].value: int(row["uses"].value) for row in usage_rows}
        disjoint = [(row["first"].value, row["second"].value) for row in disjoint_rows]
        index = cls.from_links(links, terms=terms, disjoint=disjoint)
        index.labels = {term: label.value for term, label in terms.items() if label is not None}
        index.frequency = {index.canonical(c): n for c, n in usage.items() if c in index}
        return index

    @classmethod
    def from_links(
        cls, links: Iterable[Link], terms: Iterable[str] = (), disjoint: Iterable[tuple[str, str]] = ()
    ) -> TaxonomyIndex:
        """The index of these links; ``disjoint``: pairs of classes declared disjoint."""
        import networkx as nx

        links = list(links)
        graph: nx.DiGraph[str] = nx.DiGraph()
        graph.add_nodes_from(terms)
        for link in links:
            graph.add_node(link.child)
            graph.add_node(link.parent)
            if link.kind in ("is-a", "same"):
                graph.add_edge(link.child, link.parent)
            if link.kind == "same":
                graph.add_edge(link.parent, link.child)
        # Strongly connected components of is-a (cycles, equivalences) become one node, named by
        # the smallest IRI so that the choice is stable.
        graph.add_node(ROOT)
        canonical: dict[str, str] = {}
        for component in nx.strongly_connected_components(graph):
            name = ROOT if ROOT in component else min(component)
            canonical.update({member: name for member in component})
        index = cls(_canonical=canonical)
        for node in set(canonical.values()) | {ROOT}:
            index._parents[node] = {}
            index._children[node] = set()
        for link in links:
            child, parent = canonical[link.child], canonical[link.parent]
            if child == parent or link.kind == "same":
                continue
            kind = "is-a" if link.kind == "is-a" else "has-part"
            # an is-a link wins over a has-part link between the same pair
            if index._parents[child].get(parent) != "is-a":
                index._parents[child][parent] = kind
            index._children[parent].add(child)
        index._break_part_cycles()
        index._compute_depths()
        declared: dict[str, set[str]] = {}
        for first, second in disjoint:
            a, b = canonical.get(first), canonical.get(second)
            if a is not None and b is not None and a != b:  # a class "disjoint" with its equivalent: ignored
                declared.setdefault(a, set()).add(b)
                declared.setdefault(b, set()).add(a)
        index._disjoint = {node: frozenset(others) for node, others in declared.items()}
        return index

    def _break_part_cycles(self) -> None:
        """has-part links can close a cycle (A has part B, B is-a A); drop those links."""
        import networkx as nx

        whole: nx.DiGraph[str] = nx.DiGraph((c, p) for c, ps in self._parents.items() for p in ps)
        # A cycle lies within one strongly connected component: search only those of more than one node
        # (a few dozen in OWLS-TC's 9,000 terms), not the whole graph once per cycle broken.
        tangled = [node for part in nx.strongly_connected_components(whole) if len(part) > 1 for node in part]
        graph: nx.DiGraph[str] = nx.DiGraph(whole.subgraph(tangled))
        while True:
            try:
                cycle = nx.find_cycle(graph)
            except nx.NetworkXNoCycle:
                return
            child, parent = next(((c, p) for c, p, *_ in cycle if self._parents[c][p] == "has-part"), cycle[0][:2])
            del self._parents[child][parent]
            self._children[parent].discard(child)
            graph.remove_edge(child, parent)

    def _compute_depths(self) -> None:
        self._parents[ROOT] = {}
        for node, parents in self._parents.items():
            if node != ROOT and "is-a" not in parents.values():
                parents[ROOT] = "is-a"
                self._children[ROOT].add(node)
        self._depth = {node: links for node, links in self._down_from_root().items()}

    def _down_from_root(self) -> dict[str, int]:
        depth = {ROOT: 0}
        queue = deque([ROOT])
        while queue:
            node = queue.popleft()
            for child in self._children[node]:
                if child not in depth and self._parents[child].get(node) == "is-a":
                    depth[child] = depth[node] + 1
                    queue.append(child)
        return depth

    # -- questions ---------------------------------------------------------------------------

    def __contains__(self, concept: object) -> bool:
        return isinstance(concept, str) and concept in self._canonical

    def __len__(self) -> int:
        return len(self._depth) - 1

    def canonical(self, concept: str) -> str:
        """The node a concept is merged into (itself unless it has equivalents)."""
        return self._canonical.get(concept, concept)

    def depth(self, concept: str) -> int:
        """Links from the concept up to the root, along the shortest path."""
        return self._depth[self.canonical(concept)]

    def parents(self, concept: str) -> dict[str, str]:
        return dict(self._parents[self.canonical(concept)])

    def children(self, concept: str) -> set[str]:
        return set(self._children[self.canonical(concept)])

    def is_a_parent_count(self, concept: str) -> int:
        """How many direct superclasses ``concept`` has (the root counts for a class with none)."""
        return sum(kind == "is-a" for kind in self._parents[self.canonical(concept)].values())

    def child_links(self, concept: str) -> list[tuple[str, str]]:
        """(child, link kind) for each node directly below ``concept``."""
        node = self.canonical(concept)
        return [(child, self._parents[child][node]) for child in self._children[node]]

    def ancestors(self, concept: str, is_a_only: bool = False) -> dict[str, int]:
        """Every node above ``concept`` (itself included, and the root) with its distance in links,
        following is-a and has-part links, or is-a links only."""
        node = self.canonical(concept)
        key = (node, is_a_only)
        found = self._ancestors.get(key)
        if found is None:
            found = {node: 0}
            queue = deque([node])
            while queue:
                current = queue.popleft()
                for parent, kind in self._parents[current].items():
                    if parent not in found and (kind == "is-a" or not is_a_only):
                        found[parent] = found[current] + 1
                        queue.append(parent)
            self._ancestors[key] = found
        return found

    def is_a_ancestors(self, concept: str) -> dict[str, int]:
        """Superclasses (superproperties) with their distance, the concept itself included, no root
        (cached: do not modify the answer)."""
        node = self.canonical(concept)
        found = self._is_a_up.get(node)
        if found is None:
            found = self._is_a_up[node] = {a: d for a, d in self.ancestors(node, is_a_only=True).items() if a != ROOT}
        return found

    def parts_of(self, concept: str) -> frozenset[str]:
        """The parts a concept has by its own hasPart restrictions or inherits by is-a (the root has none)."""
        node = self.canonical(concept)
        found = self._parts.get(node)
        if found is None:
            found = frozenset(
                child
                for owner in self.ancestors(node, is_a_only=True)
                if owner != ROOT
                for child, kind in self.child_links(owner)
                if kind == "has-part"
            )
            self._parts[node] = found
        return found

    def part_weight(self, part: str) -> float:
        """How much a matched part says: log(M / m) / log(M), with M the concepts that have parts and
        m those that have this one (own or inherited). A part nearly everything has (a timestamp)
        says little; a part only a few wholes have says much. A part no whole has weighs 1."""
        if self._part_weights is None:
            owners: dict[str, int] = {}
            wholes = 0
            for parts in self._all_parts().values():
                if parts:
                    wholes += 1
                    for p in parts:
                        owners[p] = owners.get(p, 0) + 1
            scale = math.log(wholes) if wholes > 1 else 1.0
            self._part_weights = {p: math.log(wholes / m) / scale if wholes > 1 else 1.0 for p, m in owners.items()}
        return self._part_weights.get(self.canonical(part), 1.0)

    def _all_parts(self) -> dict[str, frozenset[str]]:
        """parts_of for every node at once, superclasses first (their parts are inherited): a class with
        no parts of its own and one superclass shares that superclass's set. Fills the parts_of cache."""
        waiting = {node: sum(kind == "is-a" for kind in parents.values()) for node, parents in self._parents.items()}
        queue = deque([ROOT])
        self._parts[ROOT] = frozenset()
        while queue:
            node = queue.popleft()
            for child, kind in self.child_links(node):
                if kind != "is-a":
                    continue
                waiting[child] -= 1
                if waiting[child]:
                    continue
                own = {part for part, link in self.child_links(child) if link == "has-part"}
                above = [self._parts[p] for p, link in self._parents[child].items() if link == "is-a"]
                if not own and len(above) == 1:
                    self._parts[child] = above[0]
                else:
                    self._parts[child] = frozenset(own.union(*above))
                queue.append(child)
        return {node: found for node, found in self._parts.items() if node != ROOT}

    def disjoint_with(self, concept: str) -> frozenset[str]:
        """Every node that shares no instance with ``concept``: the is-a descendants of each class declared
        disjoint with it or with one of its superclasses (disjointness is inherited downwards)."""
        if not self._disjoint or concept not in self:
            return frozenset()
        node = self.canonical(concept)
        found = self._disjoint_closure.get(node)
        if found is None:
            roots = {other for up in self.ancestors(node, is_a_only=True) for other in self._disjoint.get(up, ())}
            found = frozenset(self._is_a_descendants(roots))
            self._disjoint_closure[node] = found
        return found

    def disjoint(self, first: str, second: str) -> bool:
        """Are the two concepts declared (or, by their superclasses, implied) disjoint?"""
        return second in self and self.canonical(second) in self.disjoint_with(first)

    def _is_a_descendants(self, tops: Iterable[str]) -> set[str]:
        found = set(tops)
        queue = deque(found)
        while queue:
            current = queue.popleft()
            for child in self._children[current]:
                if child not in found and self._parents[child].get(current) == "is-a":
                    found.add(child)
                    queue.append(child)
        return found

    def common_ancestor(self, first: str, second: str) -> tuple[str, int, int]:
        """The most specific common superclass C (is-a links) and the link counts N1, N2 to it.

        Most specific means deepest; ties go to the one nearest both concepts, then by name.
        """
        up_first = self.ancestors(first, is_a_only=True)
        up_second = self.ancestors(second, is_a_only=True)
        small, large = (up_first, up_second) if len(up_first) <= len(up_second) else (up_second, up_first)
        common = [c for c in small if c in large]  # the root is above both: never empty
        best = max(common, key=lambda c: (self._depth[c], -(up_first[c] + up_second[c]), c))
        return best, up_first[best], up_second[best]

    def is_a(self, concept: str, ancestor: str) -> bool:
        """Whether ``concept`` is ``ancestor`` or below it by is-a links alone (not as a part of it)."""
        if concept == ancestor:
            return True
        return concept in self and ancestor in self and self.canonical(ancestor) in self.is_a_ancestors(concept)

    def distance_down(self, lower: str, upper: str) -> int | None:
        """Links (is-a or has-part) from ``lower`` up to ``upper`` when it is above, else None."""
        return self.ancestors(lower).get(self.canonical(upper))

    def nodes(self) -> list[str]:
        return [node for node in self._depth if node != ROOT]
