"""One entity against every concept at once: the similarity vectors behind batch scoring.

``VectorSpace`` numbers the concepts (taxonomy nodes, then concepts known only by name).
``vector(measure, x)`` gives measure(x, c) for every concept c as a numpy array. It is exact for
Sem-Str, and tests check it against the scalar measure. Other measures fall back to one scalar call
per concept.
"""

from __future__ import annotations

from collections import OrderedDict, deque
from collections.abc import Callable, Hashable, Iterable
from dataclasses import dataclass
from typing import Any, Generic, TypeVar

import jellyfish
import numpy as np
import numpy.typing as npt

from cbrs.reasoner import antonyms
from cbrs.reasoner.names import core_split, local_name
from cbrs.reasoner.similarity import EntityMeasure, SemStr
from cbrs.reasoner.taxonomy import ROOT, TaxonomyIndex

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]

ARRAY_CACHE_BYTES = 32 * 2**20
"""The most each cache of whole-taxonomy arrays (similarity vectors, common superclasses, output
floors) keeps, least recently used first out: 32 MB, so 64 arrays over a 64,000-class taxonomy and
thousands over the bundled ontologies. The arrays of the pool's own concepts are rebuilt when needed
again; the per-node descendant arrays are not bounded (one per taxonomy node at most)."""


K = TypeVar("K", bound=Hashable)
V = TypeVar("V")

_STACKED_MASKS = 64  # implied(): up to this many distinct superclasses, their parts masks are stacked
_SUM_BITS = 20  # link sums and name ranks stay far below 2**20
_DEPTH_SHIFT = 2 * _SUM_BITS


class _Lru(Generic[K, V]):
    """A mapping that drops its least recently used items once their total weight passes ``limit``
    (the newest item always stays)."""

    def __init__(self, limit: int, weigh: Callable[[V], int]) -> None:
        self.limit = limit
        self._weigh = weigh
        self._items: OrderedDict[K, V] = OrderedDict()
        self.weight = 0

    def get(self, key: K) -> V | None:
        found = self._items.get(key)
        if found is not None:
            self._items.move_to_end(key)
        return found

    def __setitem__(self, key: K, value: V) -> None:
        old = self._items.pop(key, None)
        if old is not None:
            self.weight -= self._weigh(old)
        self._items[key] = value
        self.weight += self._weigh(value)
        while self.weight > self.limit and len(self._items) > 1:
            _, dropped = self._items.popitem(last=False)
            self.weight -= self._weigh(dropped)

    def __len__(self) -> int:
        return len(self._items)

    def clear(self) -> None:
        self._items.clear()
        self.weight = 0


def _nbytes(array: npt.NDArray[Any]) -> int:
    return array.nbytes


@dataclass(frozen=True)
class _Groups:
    """Read ids with complementary words (``ids``), the number of each one's distinct list of them
    (``group``), and those lists as word numbers into ``vocabulary`` (CSR: ``flat``, ``starts``, ``counts``)."""

    read: int
    ids: IntArray
    group: IntArray
    vocabulary: list[str]
    flat: IntArray
    starts: IntArray
    counts: IntArray


@dataclass(frozen=True)
class _Tree:
    """The is-a tree: which taxonomy ids are in it, and each one's pre-order range [start, end)."""

    pure: npt.NDArray[np.bool_]
    start: IntArray
    end: IntArray


@dataclass(frozen=True)
class _ReadSplit:
    """The read taxonomy nodes (positions in ``_read_taxonomy``'s order, and ids): those of the is-a tree
    in pre-order with their entries, the others with each id's position among them (-1: not one)."""

    tree: IntArray
    tree_ids: IntArray
    tree_entry: IntArray
    tree_depth: FloatArray
    general: IntArray
    general_ids: IntArray
    general_position: IntArray


class VectorSpace:
    """Concept numbering plus the per-node arrays the vectorised Sem-Str needs."""

    def __init__(self, index: TaxonomyIndex, extra: Iterable[str] = ()) -> None:
        self.index = index
        nodes = sorted({*index.nodes(), ROOT})
        self.names: list[str] = list(nodes)
        self.ids: dict[str, int] = {name: i for i, name in enumerate(nodes)}
        self.taxonomy_size = len(nodes)
        self.depth = np.array([index.depth(n) for n in nodes], dtype=np.int64)
        self.name_rank = np.arange(len(nodes), dtype=np.int64)  # names are sorted: rank = id
        self._is_a_below: dict[int, tuple[IntArray, IntArray]] = {}
        self._all_below: dict[int, tuple[IntArray, IntArray]] = {}
        self._cache: _Lru[tuple[int, str], FloatArray] = _Lru(ARRAY_CACHE_BYTES, _nbytes)
        self._lcs: _Lru[int, IntArray] = _Lru(ARRAY_CACHE_BYTES, _nbytes)
        self._used: set[int] = set()  # ids handed out by add(): where vectors are read
        self._read: list[int] | None = None  # _used, sorted
        self._read_nodes: tuple[IntArray, IntArray] | None = None
        self._read_below: dict[int, tuple[IntArray, IntArray]] = {}
        self._is_a_tree: _Tree | None = None
        self._split: _ReadSplit | None = None
        self._parts_masks: _Lru[int, npt.NDArray[np.bool_]] = _Lru(ARRAY_CACHE_BYTES, _nbytes)
        self._no_parts: npt.NDArray[np.bool_] | None = None
        self._by_core: dict[int, tuple[int, dict[str, list[int]]]] = {}
        self._floors: _Lru[tuple[str, bool, float], FloatArray] = _Lru(ARRAY_CACHE_BYTES, _nbytes)
        self._disjoint: _Lru[str, npt.NDArray[np.bool_]] = _Lru(ARRAY_CACHE_BYTES, _nbytes)
        self._opposites: _Lru[str, npt.NDArray[np.bool_]] = _Lru(ARRAY_CACHE_BYTES, _nbytes)
        self._by_form: tuple[int, dict[str, list[int]]] | None = None
        self._complements: dict[int, str] = {}
        self._groups: _Groups | None = None
        self._word_rows: dict[tuple[int, str], FloatArray] = {}
        for concept in sorted(set(extra)):
            self.add(concept)

    def add(self, concept: str) -> int:
        """The id of ``concept``; a concept outside the taxonomy gets a new id past its nodes."""
        if concept in self.index:
            found = self.ids[self.index.canonical(concept)]
        else:
            found = self.ids.get(concept, -1)
            if found < 0:
                found = len(self.names)
                self.names.append(concept)
                self.ids[concept] = found
                self._cache.clear()  # vectors must cover the new concept
        if found not in self._used:
            self._used.add(found)
            self._read = None
            self._read_nodes = None
            self._split = None
            self._read_below.clear()
            self._cache.clear()  # vectors are exact where they are read: now here too
            self._lcs.clear()
            self._opposites.clear()
        return found

    def id_of(self, concept: str) -> int:
        """The id of ``concept`` without reading vectors at it (``add`` for a concept outside the taxonomy)."""
        if concept in self.index:
            return self.ids[self.index.canonical(concept)]
        return self.add(concept)

    def warm(self) -> None:
        """Build now the descendant arrays that vectors for the handed-out concepts will need (those of
        their superclasses only when some read node lies outside the is-a tree)."""
        import numpy.ma  # noqa: F401  (np.unique and np.isin import it on first use: some 20 ms of a first ranking)

        general = len(self._read_split().general) > 0
        for i in sorted(self._used):
            if i < self.taxonomy_size:
                self._below(i, is_a_only=False)
                self._below(i, is_a_only=True)
                self.index.ancestors(self.names[i])  # what the explanations' Sem-Str reads
                for ancestor in self.index.ancestors(self.names[i], is_a_only=True) if general else ():
                    self._below_general(self.ids[ancestor])

    def warm_lexical(self, measure: SemStr) -> None:
        """Build now the core-word indexes (cross-branch links, antonyms), the groups of complementary
        words and the lexicon's tables that the first vectors would otherwise build."""
        self._core_index(measure)
        self._forms_index()
        if measure.config.complement_weight:
            self._complement_groups()
        measure.lexicon.warm()

    def _read_at(self) -> list[int]:
        """The ids vectors are read at: those handed out, or all while none has been (kept sorted)."""
        if not self._used:
            return list(range(len(self.names)))
        if self._read is None:
            self._read = sorted(self._used)
        return self._read

    def __len__(self) -> int:
        return len(self.names)

    def vector(self, measure: EntityMeasure, concept: str) -> FloatArray:
        """measure(concept, c) for every concept id c (cached per measure and concept). Exact at the
        ids ``add`` handed out; a measure computed pair by pair (Situation 3, the baselines) is only
        computed there, so a large ontology's unread nodes cost nothing (they hold 0)."""
        key = (id(measure), concept)
        found = self._cache.get(key)
        if found is None:
            if isinstance(measure, SemStr):
                found = self._sem_str(measure, concept)
            else:
                found = np.zeros(len(self.names), dtype=np.float64)
                for i in self._read_at():
                    found[i] = measure(concept, self.names[i]).value
            self._cache[key] = found
        return found

    def cached_superclass(self, first: str, second: str) -> str | None:
        """The most specific common superclass of two taxonomy nodes (TaxonomyIndex.common_ancestor) read
        from the cached table of either, or None when neither is cached or the other is not read here."""
        for concept, other in ((first, second), (second, first)):
            table = self._lcs.get(self.ids[self.index.canonical(concept)])
            at = self.ids[self.index.canonical(other)]
            if table is not None and (at in self._used or not self._used):
                return self.names[int(table[at])]
        return None

    def cached_value(self, measure: EntityMeasure, first: str, second: str) -> float | None:
        """measure(first, second) read from a cached vector of either concept (the measures this is asked
        for are symmetric), or None when neither is cached or the other concept has no id here."""
        for concept, other in ((first, second), (second, first)):
            found = self._cache.get((id(measure), concept))
            if found is not None:
                at = self.ids.get(self.index.canonical(other) if other in self.index else other)
                if at is not None and at < len(found) and (at in self._used or not self._used):
                    return float(found[at])
        return None

    # -- Sem-Str, vectorised ------------------------------------------------------------------

    def _sem_str(self, measure: SemStr, concept: str) -> FloatArray:
        n = len(self.names)
        values = np.empty(n, dtype=np.float64)
        unknown = range(self.taxonomy_size, n)
        if concept not in self.index:  # SemStr.outside: Situation 3, at least 1 / (2 + depth) under the root
            values = self._named(measure, concept).copy()
            if measure.config.unknown_under_root:
                read = self._read_known()
                values[read] = np.maximum(values[read], 1.0 / (2.0 + self.depth[read]))
            return values
        for i in unknown:
            values[i] = measure.outside(concept, self.names[i]).value
        known = slice(0, self.taxonomy_size)
        x = self.ids[self.index.canonical(concept)]
        values[known], isa_related = self._wu_palmer_or_root(x)
        self._cross_branch(measure, x, values)
        # Situation 1 for what lies below or above x through a hasPart link (is-a relatives keep
        # their Wu-Palmer value), and through the root (already in the values above).
        ids, dist = self._below(x, is_a_only=False)
        keep = ~isa_related[ids]
        values[ids[keep]] = 1.0 / (1.0 + dist[keep])
        for ancestor, links in self.index.ancestors(self.names[x]).items():
            a = self.ids[ancestor]
            if not isa_related[a]:
                values[a] = 1.0 / (1.0 + links)
        values[x] = 1.0
        if measure.config.complement_weight:
            self._qualify(measure, x, values, isa_related)
        return values

    def _named(self, measure: SemStr, concept: str) -> FloatArray:
        """Situation 3 of a concept outside the taxonomy against every read id (1 at itself; cached)."""
        key = (id(measure), "named:" + concept)
        found = self._cache.get(key)
        if found is None:
            found = np.zeros(len(self.names), dtype=np.float64)
            for i in self._read_at():
                found[i] = measure.situation_3(concept, self.names[i]).value if self.names[i] != concept else 1.0
            self._cache[key] = found
        return found

    def _read_known(self) -> IntArray:
        """The read ids that are taxonomy nodes."""
        read = np.array(self._read_at(), dtype=np.int64)
        return read[read < self.taxonomy_size]

    def predicate_vector(self, measure: SemStr, concept: str) -> FloatArray:
        """SemStr.predicate(concept, c) for every concept id c (cached)."""
        factor = measure.config.unrelated_predicate_factor
        base = self.vector(measure, concept)
        if factor >= 1 or (concept not in self.index and not measure.config.unknown_under_root):
            return base
        key = (id(measure), "predicate:" + concept)
        found = self._cache.get(key)
        if found is None and concept not in self.index:  # under the root: factor x Situation 1, or the names
            found = self._named(measure, concept).copy()
            read = self._read_known()
            found[read] = np.maximum(found[read], factor / (2.0 + self.depth[read]))
            self._cache[key] = found
        if found is None:
            x = self.ids[self.index.canonical(concept)]
            lcs = self.common_superclasses(concept)
            assert lcs is not None  # concept is a taxonomy node
            through = np.zeros(len(self.names), dtype=bool)
            through[: self.taxonomy_size] = lcs == self.ids[ROOT]
            through[self._below(x, is_a_only=False)[0]] = False
            through[[self.ids[a] for a in self.index.ancestors(self.names[x])]] = False
            through[x] = False
            namesakes = np.zeros(len(self.names), dtype=np.float64)
            self._cross_branch(measure, x, namesakes)
            found = np.where(through, np.maximum(namesakes, factor * base), base)
            if measure.config.unknown_under_root:  # outside the taxonomy: SemStr.predicate, pair by pair
                for i in range(self.taxonomy_size, len(self.names)):
                    found[i] = measure.predicate(concept, self.names[i]).value
            self._cache[key] = found
        return found

    def _qualify(self, measure: SemStr, x: int, values: FloatArray, isa_related: npt.NDArray[np.bool_]) -> None:
        """SemStr.qualifier_factor at the read ids that are not is-a relatives of x, for every distinct list
        of complementary words at once: complement_similarity over a matrix of word similarities."""
        mine = self._complement(x).split()
        if not mine:
            return
        groups = self._complement_groups()
        if not len(groups.ids):
            return
        words = np.vstack([self._word_row(measure, word, groups.vocabulary) for word in mine])  # k x V
        first = np.maximum.reduceat(words[:, groups.flat], groups.starts, axis=1).sum(axis=0)
        second = np.add.reduceat(words.max(axis=0)[groups.flat], groups.starts)
        similarity = (first + second) / (len(mine) + groups.counts)
        weight = measure.config.complement_weight
        factors = 1 - weight + weight * similarity
        changing = factors != 1.0  # a factor of 1 leaves its group's values as they are
        if not changing.any():
            return
        at, group = groups.ids, groups.group
        if not changing.all():
            chosen = changing[group]
            at, group = at[chosen], group[chosen]
        keep = (at != x) & ~isa_related[at] & (values[at] > 0)
        values[at[keep]] *= factors[group[keep]]

    def _word_row(self, measure: SemStr, word: str, vocabulary: list[str]) -> FloatArray:
        """measure.word_similarity(word, v) for every v of ``vocabulary`` (cached while it stays the same)."""
        key = (id(measure), word)
        found = self._word_rows.get(key)
        if found is None or len(found) != len(vocabulary):
            if measure.lexicon:
                found = np.array([measure.word_similarity(word, other) for other in vocabulary], dtype=np.float64)
            else:  # rescaled_jaro_winkler, one call per word into jellyfish
                floor = measure.config.jaro_winkler_floor
                jw = jellyfish.jaro_winkler_similarity
                raw = np.fromiter((jw(word, other) for other in vocabulary), np.float64, len(vocabulary))
                found = np.maximum(0.0, (raw - floor) / (1.0 - floor))
                found[[i for i, other in enumerate(vocabulary) if other == word]] = 1.0
            self._word_rows[key] = found
        return found

    def _complement_groups(self) -> _Groups:
        """The read taxonomy ids whose names have complementary words, grouped by their distinct lists of
        them; rebuilt when ``add`` has handed out more ids."""
        at = self._read_at()
        if self._groups is None or self._groups.read != len(at):
            numbers: dict[str, int] = {}
            ids, group = [], []
            for i in at:
                if i < self.taxonomy_size:
                    rest = self._complement(i)
                    if rest:
                        ids.append(i)
                        group.append(numbers.setdefault(rest, len(numbers)))
            vocabulary: dict[str, int] = {}
            lists = [[vocabulary.setdefault(word, len(vocabulary)) for word in text.split()] for text in numbers]
            counts = np.array([len(words) for words in lists], dtype=np.int64)
            self._groups = _Groups(
                read=len(at),
                ids=np.array(ids, dtype=np.int64),
                group=np.array(group, dtype=np.int64),
                vocabulary=list(vocabulary),
                flat=np.array([w for words in lists for w in words], dtype=np.int64),
                starts=np.concatenate(([0], np.cumsum(counts)[:-1])).astype(np.int64),
                counts=counts,
            )
            self._word_rows.clear()
        return self._groups

    def _cross_branch(self, measure: SemStr, x: int, values: FloatArray) -> None:
        """Raise the nodes related to x only through the root whose core words are lexically related
        (SemStr.cross_branch); they are found by core word, not by scoring every node."""
        by_core = self._core_index(measure)
        key = measure.core_key(self.names[x])
        lemmas = [key, *measure.lexicon.related(key)] if measure.lexicon else [key]
        root = self.ids[ROOT]
        lcs = self.common_superclasses(self.names[x])
        assert lcs is not None  # x is a taxonomy node
        for lemma in lemmas:
            for i in by_core.get(lemma, ()):
                if lcs[i] == root and i != x:
                    values[i] = max(values[i], measure.cross_branch(self.names[x], self.names[i]).value)

    def _core_index(self, measure: SemStr) -> dict[str, list[int]]:
        """The taxonomy ids where vectors are read (``_read_at``), by the lemma of their core word; built
        again when ``add`` has handed out more ids since."""
        read = self._read_at()
        found = self._by_core.get(id(measure))
        if found is None or found[0] != len(read):
            table: dict[str, list[int]] = {}
            for i in read:
                if i < self.taxonomy_size and self.names[i] != ROOT:
                    table.setdefault(measure.core_key(self.names[i]), []).append(i)
            found = self._by_core[id(measure)] = (len(read), table)
        return found[1]

    def _complement(self, i: int) -> str:
        """The complementary words of concept i's name (cached)."""
        found = self._complements.get(i)
        if found is None:
            found = self._complements[i] = core_split(local_name(self.names[i]))[1]
        return found

    def _wu_palmer_or_root(self, x: int) -> tuple[FloatArray, npt.NDArray[np.bool_]]:
        """Situation 2 (or 1 through the root) for every taxonomy node against node x, and which
        nodes are is-a relatives of x under a common superclass other than the root. Computed at the
        ids vectors are read at (all while none is); elsewhere the values are 0, the common superclass
        the root: no reader sees them, and a large ontology's unread nodes cost nothing."""
        size = self.taxonomy_size
        ups = self.index.ancestors(self.names[x], is_a_only=True)
        split = self._read_split()
        root = self.ids[ROOT]
        values = np.zeros(size, dtype=np.float64)
        isa_related = np.zeros(size, dtype=bool)
        lcs = np.full(size, root, dtype=np.int64)
        self._tree_wu_palmer(x, ups, split, values, isa_related, lcs)
        if len(split.general):
            common, total = self._lcs_of_other_nodes(ups, split)
            ids = split.general_ids
            through_root = common == root
            nr = self.depth[common].astype(np.float64)
            with np.errstate(divide="ignore", invalid="ignore"):
                wu_palmer = 2 * nr / (total + 2 * nr)
            values[ids] = np.where(through_root, 1.0 / (1.0 + total), wu_palmer)
            isa_related[ids] = ~through_root & ((common == x) | (common == ids))
            lcs[ids] = common
        self._lcs[x] = lcs
        return values, isa_related

    def _tree_wu_palmer(
        self,
        x: int,
        ups: dict[str, int],
        split: _ReadSplit,
        values: FloatArray,
        isa_related: npt.NDArray[np.bool_],
        lcs: IntArray,
    ) -> None:
        """``_wu_palmer_or_root`` at the read nodes of the is-a tree (``_tree``). A tree node's common
        superclass with x is the deepest of its chain of superclasses that is above x too: each such
        ancestor a of x owns the slice of the read tree nodes (in pre-order) below it, filled shallowest
        first so that a deeper one overwrites its own slice. With N1 the links from x up to a, a node c
        of depth D gets 2 d(a) / (N1 + d(a) + D), or 1 / (1 + N1 + D) when a is the root."""
        tree = self._tree()
        above = sorted(((self.ids[a], dx) for a, dx in ups.items() if tree.pure[self.ids[a]]), key=self._depth_of)
        ids = np.array([a for a, _ in above], dtype=np.int64)
        links = np.array([dx for _, dx in above], dtype=np.float64)
        depth = self.depth[ids].astype(np.float64)
        top = depth == 0  # the root, whose slice is every read tree node
        numerator = np.where(top, 1.0, 2.0 * depth)
        offset = np.where(top, 1.0 + links, links + depth)
        low = np.searchsorted(split.tree_entry, tree.start[ids]).tolist()
        high = np.searchsorted(split.tree_entry, tree.end[ids]).tolist()
        slot = np.empty(len(split.tree), dtype=np.intp)
        for k, (lo, hi) in enumerate(zip(low, high, strict=True)):
            slot[lo:hi] = k
        at = split.tree_ids
        values[at] = numerator[slot] / (offset[slot] + split.tree_depth)
        lcs[at] = ids[slot]
        if tree.pure[x]:  # x is the last (deepest) of them: its slice is what lies below it
            isa_related[at[low[-1] : high[-1]]] = True
        read = self._used
        isa_related[[a for a in ids[~top].tolist() if a in read or not read]] = True

    def _depth_of(self, item: tuple[int, int]) -> int:
        return int(self.depth[item[0]])

    def _lcs_of_other_nodes(self, ups: dict[str, int], split: _ReadSplit) -> tuple[IntArray, IntArray]:
        """The common superclass with x of the read nodes with more than one way up (multiple
        inheritance): deeper ancestors of x first, each node settled by the first that has it; among
        ancestors of one depth the smallest N1 + N2, then the larger name rank, wins. Returns, for each of
        those nodes, the common superclass and N1 + N2 (the links from x and from the node up to it)."""
        read = split.general_ids
        position = split.general_position
        limit = (1 << _SUM_BITS) - 1
        root = self.ids[ROOT]
        best = (((limit - ups[ROOT]) << _SUM_BITS) | int(self.name_rank[root])) - (self.depth[read] << _SUM_BITS)
        by_depth: dict[int, list[tuple[int, int]]] = {}
        for ancestor, dx in ups.items():
            a = self.ids[ancestor]
            if a != root:
                by_depth.setdefault(int(self.depth[a]), []).append((a, dx))
        settled = np.zeros(len(read), dtype=bool)
        for level in sorted(by_depth, reverse=True):
            found = []
            for a, dx in by_depth[level]:
                ids, dc = self._below_general(a)
                at = position[ids]
                fresh = ~settled[at]
                head = (level << _DEPTH_SHIFT) | ((limit - dx) << _SUM_BITS) | int(self.name_rank[a])
                found.append((at[fresh], head - (dc[fresh] << _SUM_BITS)))
            if len(found) == 1:
                at, keys = found[0]
                best[at] = keys
            else:
                candidate = np.full(len(read), -1, dtype=np.int64)
                for at, keys in found:
                    candidate[at] = np.maximum(candidate[at], keys)  # positions distinct within one ancestor
                at = np.concatenate([at for at, _ in found])  # repeated positions get the same value
                best[at] = candidate[at]
            for at, _ in found:
                settled[at] = True
        return best & limit, limit - ((best >> _SUM_BITS) & limit)  # name rank is the node id

    def _tree(self) -> _Tree:
        """The is-a tree inside the taxonomy: the nodes with one way up (one is-a parent, itself in the
        tree; the root is), numbered in pre-order so that each one's tree descendants are a range."""
        if self._is_a_tree is None:
            size = self.taxonomy_size
            pure = np.zeros(size, dtype=bool)
            start = np.zeros(size, dtype=np.int64)
            end = np.zeros(size, dtype=np.int64)
            root = self.ids[ROOT]
            pure[root] = True
            clock = 0
            stack: list[tuple[int, bool]] = [(root, False)]
            while stack:
                node, done = stack.pop()
                if done:
                    end[node] = clock
                    continue
                start[node] = clock
                clock += 1
                stack.append((node, True))
                for child, kind in self.index.child_links(self.names[node]):
                    if kind == "is-a" and self.index.is_a_parent_count(child) == 1:
                        c = self.ids[child]
                        pure[c] = True
                        stack.append((c, False))
            self._is_a_tree = _Tree(pure, start, end)
        return self._is_a_tree

    def _read_split(self) -> _ReadSplit:
        """The read taxonomy nodes split into those of the is-a tree (in pre-order) and the others."""
        if self._split is None:
            read, _ = self._read_taxonomy()
            tree = self._tree()
            inside = tree.pure[read]
            at = np.flatnonzero(inside)
            at = at[np.argsort(tree.start[read[at]], kind="stable")]
            general = np.flatnonzero(~inside)
            position = np.full(self.taxonomy_size, -1, dtype=np.int64)
            position[read[general]] = np.arange(len(general))
            ids = read[at]
            depth = self.depth[ids].astype(np.float64)
            self._split = _ReadSplit(at, ids, tree.start[ids], depth, general, read[general], position)
        return self._split

    def _below_general(self, node: int) -> tuple[IntArray, IntArray]:
        """``_below(node, is_a_only=True)`` at the read nodes outside the is-a tree (``_read_split``)."""
        found = self._read_below.get(node)
        if found is None:
            ids, dc = self._below(node, is_a_only=True)
            keep = self._read_split().general_position[ids] >= 0
            found = self._read_below[node] = (ids[keep], dc[keep])
        return found

    def _read_taxonomy(self) -> tuple[IntArray, IntArray]:
        """The taxonomy ids vectors are read at (all while none is handed out), and each id's position
        among them (-1 when not read)."""
        if self._read_nodes is None:
            if self._used:
                read = np.array([i for i in self._read_at() if i < self.taxonomy_size], dtype=np.int64)
            else:
                read = np.arange(self.taxonomy_size, dtype=np.int64)
            position = np.full(self.taxonomy_size, -1, dtype=np.int64)
            position[read] = np.arange(len(read))
            self._read_nodes = (read, position)
        return self._read_nodes

    def common_superclasses(self, concept: str) -> IntArray | None:
        """For every taxonomy node, the id of its most specific common superclass with ``concept``
        (None when ``concept`` is outside the taxonomy)."""
        if concept not in self.index:
            return None
        x = self.ids[self.index.canonical(concept)]
        found = self._lcs.get(x)
        if found is None:
            self._wu_palmer_or_root(x)
            found = self._lcs.get(x)
        return found

    def disjoint(self, concept: str) -> npt.NDArray[np.bool_]:
        """For every concept id: is it declared (or by a superclass implied) disjoint with ``concept``?"""
        found = self._disjoint.get(concept)
        if found is None or len(found) != len(self.names):
            others = self.index.disjoint_with(concept)
            if not others:
                return self._none()
            found = self._mask([self.ids[other] for other in others])
            self._disjoint[concept] = found
        return found

    def opposites(self, concept: str) -> npt.NDArray[np.bool_]:
        """For every concept id: is it named by an antonym of ``concept``'s core word (antonyms.opposite)?
        Exact at the ids ``add`` handed out (all while none is); answered through an index of their core
        words' forms, so a requirement costs a look-up per antonym, not a call per concept."""
        found = self._opposites.get(concept)
        if found is None or len(found) != len(self.names):
            word = core_split(local_name(concept))[0]
            if len(word) < antonyms.MIN_LETTERS:
                return self._none()
            known = antonyms.table()
            by_form = self._forms_index()
            hits = {i for f in antonyms.forms(word) for t in known.get(f, ()) for i in by_form.get(t, ())}
            lower = word.lower()
            hits = {i for i in hits if self._core_word(i).lower() != lower}
            if not hits:
                return self._none()
            found = self._mask(list(hits))
            self._opposites[concept] = found
        return found

    def _forms_index(self) -> dict[str, list[int]]:
        """The read ids by each form of their core word (antonyms.forms), for words of MIN_LETTERS or more."""
        read = self._read_at()
        if self._by_form is None or self._by_form[0] != len(read):
            table: dict[str, list[int]] = {}
            for i in read:
                word = self._core_word(i)
                if len(word) >= antonyms.MIN_LETTERS:
                    for form in antonyms.forms(word):
                        table.setdefault(form, []).append(i)
            self._by_form = (len(read), table)
        return self._by_form[1]

    def _core_word(self, i: int) -> str:
        return core_split(local_name(self.names[i]))[0]

    def implied(self, superclass: IntArray, part: IntArray) -> npt.NDArray[np.bool_]:
        """Element-wise: is part[i] a part that superclass[i] has (its own or inherited)? Answered per
        distinct superclass (the common superclasses of one concept with a pool are few: its ancestors)."""
        result = np.zeros(len(part), dtype=bool)
        if not len(part):
            return result
        if superclass.min() >= 0:
            counts = np.bincount(superclass)
            distinct = np.flatnonzero(counts)
            if len(distinct) <= _STACKED_MASKS:  # one gather from the masks stacked
                table = np.stack([self.parts_mask(int(d)) for d in distinct.tolist()])
                row = np.zeros(len(counts), dtype=np.intp)
                row[distinct] = np.arange(len(distinct))
                return np.asarray(table[row[superclass], part], dtype=bool)
        order = np.argsort(superclass, kind="stable")
        ordered = superclass[order]
        starts = np.flatnonzero(np.concatenate(([True], ordered[1:] != ordered[:-1])))
        ends = np.append(starts[1:], len(ordered))
        for start, end in zip(starts.tolist(), ends.tolist(), strict=True):
            at = order[start:end]
            result[at] = self.parts_mask(int(ordered[start]))[part[at]]
        return result

    def parts_mask(self, whole: int) -> npt.NDArray[np.bool_]:
        """For every concept id: is it a part of concept ``whole``, its own or inherited (TaxonomyIndex.parts_of)?"""
        found = self._parts_masks.get(whole)
        if found is None or len(found) != len(self.names):
            parts = self.index.parts_of(self.names[whole]) if whole < self.taxonomy_size else frozenset()
            if not parts:
                return self._none()
            found = self._mask([self.ids[p] for p in parts])
            self._parts_masks[whole] = found
        return found

    def _mask(self, ids: list[int]) -> npt.NDArray[np.bool_]:
        """True at ``ids``, False at every other concept id."""
        found = np.zeros(len(self.names), dtype=bool)
        found[ids] = True
        return found

    def _none(self) -> npt.NDArray[np.bool_]:
        """False for every concept id: one shared, read-only array answers for the many concepts without
        parts, disjoint classes or antonyms (the caches then keep only the masks that say something)."""
        if self._no_parts is None or len(self._no_parts) != len(self.names):
            self._no_parts = np.zeros(len(self.names), dtype=bool)
            self._no_parts.flags.writeable = False
        return self._no_parts

    def delivered(self, concept: str, below: bool, step: float) -> FloatArray:
        """1 - step * k at every concept k is-a links below ``concept`` (a taxonomy node; above it when
        ``below`` is false), 0 elsewhere (cached)."""
        key = (concept, below, step)
        found = self._floors.get(key)
        if found is None or len(found) != len(self.names):
            found = np.zeros(len(self.names), dtype=np.float64)
            if below:
                ids, links = self.below_is_a(concept)
            else:
                up = self.index.is_a_ancestors(concept)
                ids = np.array([self.ids[a] for a in up], dtype=np.int64)
                links = np.array(list(up.values()), dtype=np.int64)
            found[ids] = np.maximum(0.0, 1.0 - step * links)
            self._floors[key] = found
        return found

    def below_is_a(self, concept: str) -> tuple[IntArray, IntArray]:
        """Ids of ``concept`` (a taxonomy node) and every is-a descendant, with their distances in links."""
        return self._below(self.ids[self.index.canonical(concept)], is_a_only=True)

    def _below(self, node: int, is_a_only: bool) -> tuple[IntArray, IntArray]:
        """Every node at or below ``node`` and its distance, by is-a links or by both kinds."""
        cache = self._is_a_below if is_a_only else self._all_below
        found = cache.get(node)
        if found is None:
            distance = {node: 0}
            queue = deque([node])
            while queue:
                current = queue.popleft()
                for child, kind in self.index.child_links(self.names[current]):
                    if is_a_only and kind != "is-a":
                        continue
                    c = self.ids[child]
                    if c not in distance:
                        distance[c] = distance[current] + 1
                        queue.append(c)
            found = (
                np.fromiter(distance.keys(), dtype=np.int64, count=len(distance)),
                np.fromiter(distance.values(), dtype=np.int64, count=len(distance)),
            )
            cache[node] = found
        return found
