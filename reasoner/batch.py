"""Score a whole pool of advertisements against one requirement with numpy.

Same numbers as ``Matchmaker.score`` (tests compare them on every pool they use), computed once
per distinct concept, parameter tree and statement rather than once per advertisement. The
explanation (pairs, lacks) is left to the scalar path, for the candidates a person looks at.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import overload

import numpy as np
import numpy.typing as npt

from cbrs.kb import Advertisement, EffectiveArea, PartNode, QoSValue, Requirement, Statement
from cbrs.reasoner.antonyms import table as antonym_table
from cbrs.reasoner.config import MatchConfig
from cbrs.reasoner.similarity import EntityMeasure, SemStr
from cbrs.reasoner.spans import span
from cbrs.reasoner.steps import unmet_conditions
from cbrs.reasoner.vectors import ARRAY_CACHE_BYTES, FloatArray, IntArray, VectorSpace, _Lru, _nbytes

PARTS = ("outputs", "inputs", "effects", "deletes", "preconditions")
RESULTS = ("outputs", "effects", "deletes")  # what a service brings about, as opposed to what it needs
_PADDED = 8  # _Segments: the longest segment reduced by padded rows (numpy sums 8 items or fewer in order)


class _Segments:
    """Per-advertisement lists of indices (CSR), with max and mean reductions over them."""

    def __init__(self, lists: Sequence[Sequence[int]]) -> None:
        self.counts = np.array([len(items) for items in lists], dtype=np.int64)
        self.flat = np.array([i for items in lists for i in items] + [0], dtype=np.int64)  # +sentinel
        self.starts = np.concatenate(([0], np.cumsum(self.counts)[:-1])).astype(np.int64)
        self.present = self.counts > 0
        # reduceat over the flat values of the segments that have any (an empty one reads its neighbour)
        self._owners = np.flatnonzero(self.present)
        self._starts = self.starts[self._owners]
        self._body = self.flat[:-1]
        self._full = len(self._owners) == len(self.counts) > 0  # every segment has items
        # Segments of up to _PADDED items: one row of indices per position, so that max and mean are a
        # few gathers instead of a reduceat (several times faster on 100,000 advertisements). Past a
        # segment's end a max row repeats its first item and a sum row reads an appended 0 (index -1);
        # the sum adds the first item to the sum of the rest, as reduceat does, so the means are the same.
        self._max_rows: npt.NDArray[np.intp] | None = None
        self._sum_rows: npt.NDArray[np.intp] | None = None
        longest = int(self.counts.max(initial=0))
        if 0 < longest <= _PADDED:
            first = np.where(self.present, self.flat[np.minimum(self.starts, len(self._body))], 0)
            self._max_rows = np.empty((longest, len(self.counts)), dtype=np.intp)
            self._sum_rows = np.empty((longest, len(self.counts)), dtype=np.intp)
            for j in range(longest):
                has = self.counts > j
                at = self.flat[np.where(has, self.starts + j, 0)]
                self._max_rows[j] = np.where(has, at, first)
                self._sum_rows[j] = np.where(has, at, -1)

    def max(self, values: FloatArray) -> FloatArray:
        if self._max_rows is not None:
            found = np.take(values, self._max_rows[0])
            for row in self._max_rows[1:]:
                np.maximum(found, np.take(values, row), out=found)
            if not self._full:
                found[~self.present] = 0.0
            return np.asarray(found, dtype=np.float64)
        if self._full:
            return np.asarray(np.maximum.reduceat(values[self._body], self._starts), dtype=np.float64)
        result = np.zeros(len(self.counts), dtype=np.float64)
        if len(self._owners):
            result[self._owners] = np.maximum.reduceat(values[self._body], self._starts)
        return result

    def min(self, values: FloatArray) -> FloatArray:
        """The lowest value of each segment (0 for an empty one)."""
        return np.asarray(-self.max(-values), dtype=np.float64) + 0.0  # + 0.0: no -0.0 for empty segments

    def mean(self, values: FloatArray) -> FloatArray:
        if self._sum_rows is not None:
            padded = np.append(values, 0.0)
            total = np.take(padded, self._sum_rows[0])
            if len(self._sum_rows) > 1:
                rest = np.take(padded, self._sum_rows[1])
                for row in self._sum_rows[2:]:
                    rest += np.take(padded, row)
                total += rest
            result = np.zeros(len(self.counts), dtype=np.float64)
            np.divide(total, self.counts, out=result, where=self.present)
            return result
        if self._full:
            return np.asarray(np.add.reduceat(values[self._body], self._starts) / self.counts, dtype=np.float64)
        result = np.zeros(len(self.counts), dtype=np.float64)
        if len(self._owners):
            sums = np.add.reduceat(values[self._body], self._starts)
            result[self._owners] = sums / self.counts[self._owners]
        return result


class _Reasons(Sequence[tuple[str, ...]]):
    """Each advertisement's filter reasons, read through its (SEA, QoS) number: no list of a whole pool."""

    def __init__(self, keys: IntArray, reasons: list[tuple[str, ...]]) -> None:
        self._keys = keys
        self._reasons = reasons
        self._extra: dict[int, tuple[str, ...]] = {}

    def __len__(self) -> int:
        return len(self._keys)

    @overload
    def __getitem__(self, i: int) -> tuple[str, ...]: ...

    @overload
    def __getitem__(self, i: slice) -> list[tuple[str, ...]]: ...

    def __getitem__(self, i: int | slice) -> tuple[str, ...] | list[tuple[str, ...]]:
        if isinstance(i, slice):
            return [self[j] for j in range(*i.indices(len(self)))]
        return self._extra.get(i) or self._reasons[int(self._keys[i])]

    def add(self, i: int, reason: str) -> None:
        """One more reason for advertisement i (strict logic's failed output or effect)."""
        self._extra[i] = (*self[i], reason)


@dataclass(frozen=True)
class BatchScores:
    score: FloatArray
    parts: dict[str, FloatArray]  # each part's value, NaN where the part is left out
    rejected_by: Sequence[tuple[str, ...]]  # filter reasons per advertisement
    rejected: npt.NDArray[np.bool_]  # where they are not empty
    accepted_on: FloatArray | None = None  # the IO/PE score acceptability is judged on, when not ``score``
    tie: FloatArray | None = None  # what orders equal scores before the IRI (MatchConfig.tie_break_result)


class CompiledPool:
    """An advertisement pool laid out as arrays over distinct trees and statements."""

    def __init__(self, ads: Sequence[Advertisement], space: VectorSpace, use_parts: bool) -> None:
        self.ads = list(ads)
        self.space = space
        self.use_parts = use_parts
        trees: dict[str, PartNode] = {}
        statements: dict[Statement, int] = {}
        for ad in self.ads:
            for parameter in (*ad.inputs, *ad.outputs):
                trees.setdefault(parameter.type, parameter.tree or PartNode(parameter.type))
            for statement in (*ad.effects, *ad.deletes, *ad.preconditions):
                statements.setdefault(statement, len(statements))
        self.tree_ids = {concept: i for i, concept in enumerate(trees)}
        self.tree_concepts = list(trees)  # each tree's root concept, by tree id
        self._layout_trees(list(trees.values()))
        self.statements = list(statements)
        self._opposites: _Lru[Statement, npt.NDArray[np.bool_]] = _Lru(ARRAY_CACHE_BYTES, _nbytes)  # bounded
        if self.statements:
            antonym_table()  # read once per process here, in prepare(), rather than in the first ranking
        cid = space.add
        self.s_ids = np.array([cid(s.subject) for s in self.statements], dtype=np.int64)
        self.p_ids = np.array([cid(s.predicate) for s in self.statements], dtype=np.int64)
        self.o_ids = np.array([cid(s.object) for s in self.statements], dtype=np.int64)
        self.outputs = _Segments([[self.tree_ids[p.type] for p in ad.outputs] for ad in self.ads])
        self.inputs = _Segments([[self.tree_ids[p.type] for p in ad.inputs] for ad in self.ads])
        self.effects = _Segments([[statements[s] for s in ad.effects] for ad in self.ads])
        self.deletes = _Segments([[statements[s] for s in ad.deletes] for ad in self.ads])
        self.preconditions = _Segments([[statements[s] for s in ad.preconditions] for ad in self.ads])
        keys: dict[tuple[EffectiveArea | None, tuple[QoSValue, ...]], int] = {}
        self.filter_key = np.array([keys.setdefault((ad.area, ad.qos), len(keys)) for ad in self.ads], np.int64)
        self.filter_inputs = list(keys)  # the distinct (SEA, QoS) pairs the filters are asked about
        order = sorted(range(len(self.ads)), key=lambda i: self.ads[i].iri)
        self.iri_rank = np.empty(len(self.ads), dtype=np.int64)
        self.iri_rank[order] = np.arange(len(self.ads))

    def opposites(self, wanted: Statement) -> npt.NDArray[np.bool_]:
        """Per pool statement: is its subject or object named by an antonym of ``wanted``'s
        (antonyms.opposite)? Kept per requested statement: the pool's statements are few and fixed."""
        found = self._opposites.get(wanted)
        if found is None:
            found = self.space.opposites(wanted.subject)[self.s_ids] | self.space.opposites(wanted.object)[self.o_ids]
            self._opposites[wanted] = found
        return found

    def filtered(
        self,
        requirement: Requirement,
        filters: Callable[[Requirement, EffectiveArea | None, tuple[QoSValue, ...]], list[str]],
    ) -> tuple[_Reasons, npt.NDArray[np.bool_]]:
        """Each advertisement's filter reasons, asked once per distinct (SEA, QoS), and where there are any."""
        reasons = [tuple(filters(requirement, area, qos)) for area, qos in self.filter_inputs]
        rejected = np.array([bool(r) for r in reasons], dtype=bool)[self.filter_key]
        return _Reasons(self.filter_key, reasons), rejected

    def _layout_trees(self, trees: list[PartNode]) -> None:
        """Offered side: each tree's root and its parts (CSR). Wanted side: every node of every
        tree, flattened with its parent, level and span, for a level-by-level cover."""
        cid = self.space.add
        self.root_ids = np.array([cid(t.concept) for t in trees], dtype=np.int64)
        part_lists = [[cid(n.concept) for n in t.walk() if n is not t] if self.use_parts else [] for t in trees]
        self.part_segments = _Segments(part_lists)
        concept: list[int] = []
        tree_root: list[int] = []
        parent: list[int] = []
        level: list[int] = []
        width: list[int] = []
        leaf: list[bool] = []
        root_of: list[int] = []
        for tree in trees:
            root_of.append(len(concept))
            stack: list[tuple[PartNode, int, int]] = [(tree, -1, 0)]
            while stack:
                node, up, depth = stack.pop()
                position = len(concept)
                concept.append(cid(node.concept))
                tree_root.append(cid(tree.concept))
                parent.append(up)
                level.append(depth)
                width.append(span(node))
                leaf.append(node.is_leaf or not self.use_parts)
                if self.use_parts:
                    stack.extend((child, position, depth + 1) for child in node.children)
        self.node_concept = np.array(concept, dtype=np.int64)
        self.node_tree_root = np.array(tree_root, dtype=np.int64)
        self.node_parent = np.array(parent, dtype=np.int64)
        self.node_level = np.array(level, dtype=np.int64)
        self.node_span = np.array(width, dtype=np.float64)
        self.node_weight = np.array([self.space.index.part_weight(self.space.names[c]) for c in concept])
        self.node_leaf = np.array(leaf, dtype=bool)
        self.tree_root_node = np.array(root_of, dtype=np.int64)
        self.node_is_root = self.node_parent < 0
        # per level, deepest last: the inner nodes, the nodes with a parent, their parents and weights
        self.levels: list[tuple[IntArray, IntArray, IntArray, FloatArray]] = []
        for depth in range(int(self.node_level.max(initial=0)) + 1):
            at = np.flatnonzero(self.node_level == depth)
            below = at[self.node_parent[at] >= 0]
            strength = self.node_weight[below] * self.node_span[below]
            self.levels.append((at[~self.node_leaf[at]], below, self.node_parent[below], strength))


class BatchScorer:
    def __init__(
        self,
        pool: CompiledPool,
        measure: EntityMeasure,
        config: MatchConfig,
        filters: Callable[[Requirement, EffectiveArea | None, tuple[QoSValue, ...]], list[str]],
        plugin_inputs: bool = False,
        plugin_outputs: bool = False,
    ) -> None:
        self.pool = pool
        self.measure = measure
        self.config = config
        self.filters = filters
        self.plugin_inputs = plugin_inputs
        self.plugin_outputs = plugin_outputs

    def _vector(self, concept: str) -> FloatArray:
        return self.pool.space.vector(self.measure, concept)

    def delivered(self, concept: str, below: bool) -> FloatArray | None:
        """The floor 1 - specialisation_step * k for every concept k is-a links below ``concept`` (or
        above it, ``below`` false), 0 elsewhere; None when the rule is off or ``concept`` is unknown."""
        if not self.plugin_outputs or concept not in self.pool.space.index:
            return None
        return self.pool.space.delivered(concept, below, self.config.specialisation_step)

    def _output_css(self, tree: PartNode) -> FloatArray:
        css = self.css_wanted(tree, self.delivered(tree.concept, below=True))
        if self.plugin_outputs and self.config.unrelated_output_factor < 1:
            css = css * self.relatedness(tree.concept)[self.pool.root_ids]
        return css

    def relatedness(self, concept: str) -> FloatArray:
        """1 for ``concept``, its is-a descendants and ancestors, unrelated_output_factor for every other
        concept (all 1 when the factor is 1 or the rule is off)."""
        space, index = self.pool.space, self.pool.space.index
        factor = self.config.unrelated_output_factor
        if not self.plugin_outputs or factor >= 1:
            return np.ones(len(space), dtype=np.float64)
        values = np.full(len(space), factor, dtype=np.float64)
        if concept in index:
            values[space.below_is_a(concept)[0]] = 1.0
            values[[space.ids[a] for a in index.is_a_ancestors(concept)]] = 1.0
        elif concept in space.ids:
            values[space.ids[concept]] = 1.0
        return values

    def css_wanted(self, tree: PartNode, floor: FloatArray | None = None) -> FloatArray:
        """CSS of a fixed requirement tree (wanted) against every pool tree (offered); ``floor``: a
        lowest value per offered root concept (MatchConfig.plugin_outputs)."""
        result = self._css_wanted(tree)
        return result if floor is None else np.maximum(result, floor[self.pool.root_ids])

    def _css_wanted(self, tree: PartNode) -> FloatArray:
        pool = self.pool

        superclasses = self._superclasses(tree.concept, pool.root_ids)
        inherited = self._inherited(tree.concept, superclasses)

        def cover(node: PartNode, is_root: bool) -> FloatArray:
            if is_root:
                own = self._vector(node.concept)[pool.root_ids]
            else:
                own = pool.part_segments.max(self._vector(node.concept))
            if node.is_leaf or not pool.use_parts:
                return own
            total = own.copy()
            weight = np.ones_like(own)
            for child in node.children:
                counted = np.ones_like(own)
                child_cover = cover(child, False)
                if is_root and superclasses is not None:
                    part = np.full(len(own), pool.space.id_of(child.concept), dtype=np.int64)
                    implied = (superclasses >= 0) & pool.space.implied(np.maximum(superclasses, 0), part)
                    counted = np.where(implied & ~inherited, 0.0, 1.0)
                    child_cover = np.where(implied & inherited, 1.0, child_cover)
                strength = counted * pool.space.index.part_weight(child.concept) * span(child)
                total += strength * child_cover
                weight += strength
            return np.maximum(own, total / weight)

        return cover(tree, True)

    def _inherited(self, concept: str, superclasses: IntArray | None) -> npt.NDArray[np.bool_]:
        """Where the other concept is a subclass of ``concept`` (their common superclass is
        ``concept`` itself), so that it inherits every part of it (MatchConfig.inherited_parts)."""
        space = self.pool.space
        if superclasses is None or not self.config.inherited_parts:
            return np.zeros(0 if superclasses is None else len(superclasses), dtype=bool)
        return np.asarray(superclasses == space.ids[space.index.canonical(concept)], dtype=bool)

    def plugin(self, concept: str) -> FloatArray:
        """1 for every pool tree whose root ``concept`` can be passed to as it is (the same concept or
        a superclass of it, by is-a links), else 0."""
        space, index = self.pool.space, self.pool.space.index
        if concept in index:
            above = [space.ids[a] for a in index.is_a_ancestors(concept)]
        else:
            above = [space.ids[concept]] if concept in space.ids else []
        return np.isin(self.pool.root_ids, np.array(above, dtype=np.int64)).astype(np.float64)

    def narrower(self, concept: str) -> FloatArray:
        """For every pool tree whose root is k is-a links below ``concept`` (a provided input), the floor
        1 - narrower_input_step * k of its "can it be invoked?" side (Matchmaker._trees); 0 elsewhere."""
        space, step = self.pool.space, self.config.narrower_input_step
        if step >= 1 or concept not in space.index:
            return np.zeros(len(self.pool.root_ids), dtype=np.float64)
        return space.delivered(concept, True, step)[self.pool.root_ids]

    def _superclasses(self, concept: str, others: IntArray) -> IntArray | None:
        """Most specific common superclass of ``concept`` with each of ``others`` (-1 where there is
        none: a concept outside the taxonomy), or None when ``concept`` is outside it."""
        space = self.pool.space
        table = space.common_superclasses(concept)
        if table is None:
            return None
        inside = others < space.taxonomy_size
        return np.where(inside, table[np.where(inside, others, 0)], -1)

    def css_offered(self, tree: PartNode) -> FloatArray:
        """CSS of every pool tree (wanted, e.g. an advertisement's input) against a fixed offered tree."""
        pool = self.pool
        root = self._vector(tree.concept)
        parts = [n for n in tree.walk() if n is not tree] if pool.use_parts else []
        best_part = np.zeros(len(pool.space), dtype=np.float64)
        for node in parts:
            best_part = np.maximum(best_part, self._vector(node.concept))
        own = np.where(pool.node_is_root, root[pool.node_concept], best_part[pool.node_concept])
        counted = np.ones_like(own)  # parts of a root implied by its common superclass with ours: 0
        forced = np.zeros(0, dtype=np.int64)  # ... or 1, covered, when ours is a subclass of that root
        superclasses = self._superclasses(tree.concept, pool.node_tree_root) if pool.use_parts else None
        if superclasses is not None:
            first = np.flatnonzero((pool.node_level == 1) & (superclasses >= 0))
            implied = pool.space.implied(superclasses[first], pool.node_concept[first])
            counted[first] = ~implied
            if self.config.inherited_parts:
                forced = first[implied & (superclasses[first] == pool.node_tree_root[first])]
                counted[forced] = 1.0
        cover = own.copy()
        child_sum = np.zeros_like(own)
        child_weight = np.zeros_like(own)
        for level in range(len(pool.levels) - 1, -1, -1):
            inner, below, parents, strength = pool.levels[level]
            cover[inner] = np.maximum(own[inner], (own[inner] + child_sum[inner]) / (1 + child_weight[inner]))
            if level == 1:
                cover[forced] = 1.0
            if not len(below):
                continue
            weights = counted[below] * strength
            child_sum += np.bincount(parents, weights * cover[below], minlength=len(child_sum))
            child_weight += np.bincount(parents, weights, minlength=len(child_weight))
        return cover[pool.tree_root_node]

    def observed(self, effects: tuple[Statement, ...]) -> FloatArray:
        """Per advertisement, the mean over ``effects`` of its outputs' best Sem-Str with the effect's
        object or subject, where the output is one of them or an is-a relative (Matchmaker._observed)."""
        pool = self.pool
        per = []
        for effect in effects:
            terms = np.zeros(len(pool.space), dtype=np.float64)
            if self.config.observed_state_kind:  # statements.reported: a strict superclass of the object
                kinds = self._kinds_of(effect.object)
                terms = np.where(kinds, self._vector(effect.object), 0.0)
            else:
                for term in (effect.object, effect.subject):
                    terms = np.maximum(terms, np.where(self._related_to(term), self._vector(term), 0.0))
            per.append(pool.outputs.max(terms[pool.root_ids]))
        return np.asarray(np.mean(per, axis=0), dtype=np.float64)

    def _achieving(self, requirement: Requirement, own: FloatArray) -> npt.NDArray[np.bool_]:
        """Per advertisement: does it achieve every requested effect (steps.achievers)?"""
        pool = self.pool
        achieving = pool.effects.present & (own >= self.config.pair_threshold)
        for wanted in requirement.effects:
            if not achieving.any():
                break
            achieving &= pool.effects.max(self._establishing(wanted).astype(np.float64)) > 0
        return achieving

    def _establishing(self, wanted: Statement) -> npt.NDArray[np.bool_]:
        """Per pool statement: each position ``wanted``'s concept or an is-a superclass (steps.establishes)."""
        pool = self.pool
        return (
            self._at_or_above(wanted.subject)[pool.s_ids]
            & self._at_or_above(wanted.predicate)[pool.p_ids]
            & self._at_or_above(wanted.object)[pool.o_ids]
        )

    def precondition_steps(self, requirement: Requirement, own: FloatArray) -> FloatArray:
        """Per advertisement, the best decomposition_weight x an achiever's effects part (``own``) where one
        of its effects brings about a precondition of that achiever the requester does not guarantee
        (precondition_steps; reasoner/steps.py); 0 where it is no such step."""
        pool, cfg, index = self.pool, self.config, self.pool.space.index
        found = np.zeros(len(pool.ads), dtype=np.float64)
        feeds: dict[Statement, FloatArray] = {}  # per unmet precondition: which advertisements bring it about
        for a in np.flatnonzero(self._achieving(requirement, own)):
            for condition in unmet_conditions(index, requirement, pool.ads[a]):
                feed = feeds.get(condition)
                if feed is None:
                    feed = feeds[condition] = pool.effects.max(self._establishing(condition).astype(np.float64))
                np.maximum(found, cfg.decomposition_weight * own[a] * feed, out=found)
        return found

    def steps(self, requirement: Requirement, own: FloatArray) -> FloatArray:
        """Per advertisement, the best decomposition_weight x an achiever's effects part (``own``) x the
        delivered floor of its output as an input the achiever needs and the requester does not provide,
        or x 1 where it takes that input and works towards the goal (consumer_steps; reasoner/steps.py);
        0 where it is no step."""
        pool, cfg = self.pool, self.config
        found = np.zeros(len(pool.ads), dtype=np.float64)
        achieving = self._achieving(requirement, own)
        if not achieving.any():
            return found
        given = np.zeros(len(pool.root_ids), dtype=bool)  # pool trees the requester provides as they are
        for provided in requirement.inputs:
            given |= self.plugin(provided.type) > 0
        after = np.ones(len(pool.ads), dtype=bool)  # consumers that need what the requester asks to get
        if cfg.consumer_steps:
            takes_result = np.zeros(len(pool.root_ids), dtype=bool)
            for wanted_output in requirement.outputs:
                takes_result |= self.plugin(wanted_output.type) > 0
            after = pool.inputs.max(takes_result.astype(np.float64)) > 0
        feeds: dict[int, FloatArray] = {}  # per missing input tree: how well each advertisement is a step
        for a in np.flatnonzero(achieving):
            start, count = pool.inputs.starts[a], pool.inputs.counts[a]
            for tree in dict.fromkeys(pool.inputs.flat[start : start + count].tolist()):
                if given[tree]:
                    continue
                feed = feeds.get(tree)
                if feed is None:
                    concept = pool.tree_concepts[tree]
                    feed = pool.outputs.max(self._floor_below(concept)[pool.root_ids])
                    if cfg.consumer_steps:  # steps.works_towards
                        feed = np.maximum(feed, np.where(after, 0.0, pool.inputs.max(self.plugin(concept))))
                    feeds[tree] = feed
                np.maximum(found, cfg.decomposition_weight * own[a] * feed, out=found)
        return found

    def _floor_below(self, concept: str) -> FloatArray:
        """1 - specialisation_step * k for every concept id k is-a links below ``concept`` (the concept
        itself only, 1, when it is outside the taxonomy), 0 elsewhere."""
        space = self.pool.space
        if concept in space.index:
            return space.delivered(concept, True, self.config.specialisation_step)
        floor = np.zeros(len(space), dtype=np.float64)
        if concept in space.ids:
            floor[space.ids[concept]] = 1.0
        return floor

    def _at_or_above(self, concept: str) -> npt.NDArray[np.bool_]:
        """For every concept id: is it ``concept`` or an is-a superclass of it (steps.at_or_above)?"""
        space = self.pool.space
        mask = np.zeros(len(space), dtype=bool)
        if concept in space.index:
            mask[[space.ids[a] for a in space.index.is_a_ancestors(concept)]] = True
        elif concept in space.ids:
            mask[space.ids[concept]] = True
        return mask

    def _kinds_of(self, concept: str) -> npt.NDArray[np.bool_]:
        """For every concept id: is it a strict is-a superclass of ``concept``?"""
        space = self.pool.space
        kinds = np.zeros(len(space), dtype=bool)
        if concept in space.index:
            above = [space.ids[a] for a, links in space.index.is_a_ancestors(concept).items() if links > 0]
            kinds[above] = True
        return kinds

    def _related_to(self, concept: str) -> npt.NDArray[np.bool_]:
        """For every concept id: is it ``concept``, an is-a descendant or an is-a ancestor of it?"""
        space = self.pool.space
        related = np.zeros(len(space), dtype=bool)
        if concept in space.index:
            related[space.below_is_a(concept)[0]] = True
            related[[space.ids[a] for a in space.index.is_a_ancestors(concept)]] = True
        elif concept in space.ids:
            related[space.ids[concept]] = True
        return related

    def statements(self, statement: Statement) -> FloatArray:
        cfg, pool = self.config, self.pool
        s = self._vector(statement.subject)[pool.s_ids]
        if isinstance(self.measure, SemStr):
            p = pool.space.predicate_vector(self.measure, statement.predicate)[pool.p_ids]
        else:
            p = self._vector(statement.predicate)[pool.p_ids]
        o = self._vector(statement.object)[pool.o_ids]
        if cfg.statement_mean == "geometric" and cfg.subject_weight == cfg.predicate_weight == cfg.object_weight:
            values = np.cbrt(s * p * o)  # the equal weights of 1/3, with one root instead of three powers
        elif cfg.statement_mean == "geometric":
            values = np.asarray(s**cfg.subject_weight * p**cfg.predicate_weight * o**cfg.object_weight, np.float64)
        else:
            values = cfg.subject_weight * s + cfg.predicate_weight * p + cfg.object_weight * o
        return np.where(self.contradicts(statement), 0.0, values)

    def contradicts(self, statement: Statement) -> npt.NDArray[np.bool_]:
        """Per pool statement: does it contradict ``statement`` (statements.contradiction)?"""
        cfg, pool = self.config, self.pool
        clash = np.zeros(len(pool.statements), dtype=bool)
        if not isinstance(self.measure, SemStr):
            return clash
        if not cfg.same_fact_contradictions:
            if cfg.disjoint_statements:
                space = pool.space
                clash |= space.disjoint(statement.subject)[pool.s_ids] | space.disjoint(statement.object)[pool.o_ids]
            if cfg.antonym_statements:
                clash |= pool.opposites(statement)
            return clash
        subject, predicate, obj = (
            self._related_to(t) for t in (statement.subject, statement.predicate, statement.object)
        )
        same_predicate = predicate[pool.p_ids]
        clash |= self._clashes(statement.subject)[pool.s_ids] & same_predicate & obj[pool.o_ids]
        clash |= self._clashes(statement.object)[pool.o_ids] & same_predicate & subject[pool.s_ids]
        return clash

    def _clashes(self, concept: str) -> npt.NDArray[np.bool_]:
        """For every concept id: declared disjoint with ``concept`` or named by its antonym (statements._clash)."""
        cfg, space = self.config, self.pool.space
        found = np.zeros(len(space), dtype=bool)
        if cfg.disjoint_statements:
            found |= space.disjoint(concept)
        if cfg.antonym_statements:
            found |= space.opposites(concept)
        return found

    def undoing(self, requirement: Requirement) -> npt.NDArray[np.bool_]:
        """Per pool statement: does it make a precondition the requirement guarantees false (the same fact,
        a contradicting object: statements.undoes) while stating no requested effect (Matchmaker._undone_state)?"""
        cfg, pool, space = self.config, self.pool, self.pool.space
        undone = np.zeros(len(pool.statements), dtype=bool)
        for held in requirement.preconditions:
            clash = np.zeros(len(space), dtype=bool)
            if cfg.disjoint_statements:
                clash |= space.disjoint(held.object)
            if cfg.antonym_statements:
                clash |= space.opposites(held.object)
            undone |= (
                self._related_to(held.subject)[pool.s_ids]
                & self._related_to(held.predicate)[pool.p_ids]
                & clash[pool.o_ids]
            )
        for wanted in requirement.effects:
            undone &= ~(
                self._at_or_above(wanted.subject)[pool.s_ids]
                & self._at_or_above(wanted.predicate)[pool.p_ids]
                & self._at_or_above(wanted.object)[pool.o_ids]
            )
        return undone

    def score(self, requirement: Requirement) -> BatchScores:
        pool, cfg = self.pool, self.config
        n = len(pool.ads)
        nan = np.full(n, np.nan)
        parts: dict[str, FloatArray] = {name: nan.copy() for name in PARTS}
        invocable = np.ones(n)
        if requirement.outputs:
            per = [pool.outputs.max(self._output_css(p.tree or PartNode(p.type))) for p in requirement.outputs]
            parts["outputs"] = np.mean(per, axis=0)
        if requirement.inputs or np.any(pool.inputs.present):
            needed = np.zeros(len(pool.root_ids))
            for provided in requirement.inputs:
                needed = np.maximum(needed, self.css_offered(provided.tree or PartNode(provided.type)))
                if self.plugin_inputs:
                    needed = np.maximum(needed, self.plugin(provided.type))
                    needed = np.maximum(needed, self.narrower(provided.type))
            needed_per_ad = pool.inputs.mean(needed)
            invocable = np.where(pool.inputs.present, needed_per_ad, 1.0)
            if requirement.inputs:
                used = np.mean(
                    [
                        pool.inputs.max(
                            self.css_wanted(p.tree or PartNode(p.type), self.delivered(p.type, below=False))
                        )
                        for p in requirement.inputs
                    ],
                    axis=0,
                )
                u = cfg.input_use_weight
                inputs = (1 - u) * invocable + u * used
                if not cfg.no_input_invocable:
                    inputs = np.where(pool.inputs.present, inputs, used)
            else:
                inputs = np.where(pool.inputs.present, needed_per_ad, np.nan)
            parts["inputs"] = inputs
        brings_about = np.zeros(n, dtype=bool)  # precondition steps: no offer that undoes the effect
        if requirement.effects:
            own = np.mean([pool.effects.max(self.statements(s)) for s in requirement.effects], axis=0)
            effects = own
            reports = pool.outputs.present & ~pool.effects.present
            if cfg.observed_state_weight > 0:  # Matchmaker._observed
                effects = np.where(reports, cfg.observed_state_weight * self.observed(requirement.effects), effects)
            if cfg.decomposition_weight > 0 and isinstance(self.measure, SemStr):  # Matchmaker._step
                effects = np.where(reports, np.maximum(effects, self.steps(requirement, own)), effects)
                if cfg.precondition_steps:  # Matchmaker._precondition_step
                    steps = np.where(pool.effects.present, self.precondition_steps(requirement, own), 0.0)
                    effects = np.maximum(effects, steps)
                    brings_about = steps > 0
            parts["effects"] = effects
        if requirement.deletes:
            parts["deletes"] = np.mean([pool.deletes.max(self.statements(s)) for s in requirement.deletes], axis=0)
        if requirement.preconditions:
            guaranteed = np.max([self.statements(s) for s in requirement.preconditions], axis=0)
            # all of an advertisement's preconditions must hold (precondition_conjunction): the worst decides
            combine = pool.preconditions.min if cfg.precondition_conjunction else pool.preconditions.mean
            parts["preconditions"] = np.where(pool.preconditions.present, combine(guaranteed), np.nan)
        weights = cfg.part_weights
        numerator = np.zeros(n)
        denominator = np.zeros(n)
        for name, values in parts.items():
            present = ~np.isnan(values)
            numerator += np.where(present, weights[name] * np.nan_to_num(values), 0.0)
            denominator += np.where(present, weights[name], 0.0)
        ratio = np.where(denominator > 0, numerator / np.maximum(denominator, 1e-300), 0.0)
        ratio = ratio * (1 - cfg.input_gate + cfg.input_gate * invocable)
        if requirement.effects and cfg.contradiction_factor < 1:  # statements.contradiction_factor
            clash = np.max([pool.effects.max(self.contradicts(s).astype(np.float64)) for s in requirement.effects], 0)
            ratio = np.where((clash > 0) & ~brings_about, cfg.contradiction_factor * ratio, ratio)
        if requirement.preconditions and cfg.undone_state_factor < 1 and isinstance(self.measure, SemStr):
            undone = pool.effects.max(self.undoing(requirement).astype(np.float64)) > 0
            ratio = np.where(undone, cfg.undone_state_factor * ratio, ratio)
        score = np.round(ratio.astype(np.float64), 6).astype(np.float64)
        tie = self._result(parts, weights) if cfg.tie_break_result else None
        return BatchScores(score, parts, *pool.filtered(requirement, self.filters), tie=tie)

    @staticmethod
    def _result(parts: dict[str, FloatArray], weights: dict[str, float]) -> FloatArray:
        """The result part of each score: outputs, effects and delete effects, weighted as in the score (0
        where none)."""
        numerator = np.zeros(len(parts["outputs"]))
        denominator = np.zeros(len(parts["outputs"]))
        for name in RESULTS:
            present = ~np.isnan(parts[name])
            numerator += np.where(present, weights[name] * np.nan_to_num(parts[name]), 0.0)
            denominator += np.where(present, weights[name], 0.0)
        return np.where(denominator > 0, numerator / np.maximum(denominator, 1e-300), 0.0)


def ranking_order(scores: BatchScores, pool: CompiledPool, accept_score: float) -> IntArray:
    """Those that pass the filters first, each group by score (so the ranking and the scores agree),
    then by IRI. ``accept_score`` does not reorder: acceptability is shown, not ranked on."""
    del accept_score
    return np.argsort(ranking_keys(scores, pool)).astype(np.int64)  # distinct keys: no ties to keep stable


def ranking_keys(scores: BatchScores, pool: CompiledPool) -> IntArray:
    """One integer per advertisement that sorts as the ranking does: whether a filter rejects it, then
    its score (six decimals, highest first), then its result part when ``scores.tie`` is given (three
    decimals, highest first), then its IRI's rank (so the keys are distinct)."""
    score = np.rint(scores.score * 1e6).astype(np.int64)
    tie = np.zeros(len(score), dtype=np.int64) if scores.tie is None else np.rint(scores.tie * 1e3).astype(np.int64)
    return np.asarray(
        (scores.rejected.astype(np.int64) << 62) | ((1_000_000 - score) << 42) | ((1000 - tie) << 32) | pool.iri_rank
    )


def first_ranked(keys: IntArray, count: int) -> IntArray:
    """The ``count`` best by ``keys``, in order, without sorting the rest."""
    count = min(count, len(keys))
    if count <= 0:
        return np.zeros(0, dtype=np.int64)
    chosen = np.argpartition(keys, count - 1)[:count] if count < len(keys) else np.arange(len(keys))
    return np.asarray(chosen[np.argsort(keys[chosen])], dtype=np.int64)
