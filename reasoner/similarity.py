"""Similarity of two entities (concepts or properties): Sem-Str and the baselines.

Every measure answers ``measure(e1, e2) -> Similarity`` with a value in [0, 1] and the reason.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Protocol

import jellyfish

from cbrs.reasoner.config import MatchConfig
from cbrs.reasoner.lexicon import Lexicon, bundled
from cbrs.reasoner.names import core_split, local_name, words
from cbrs.reasoner.taxonomy import ROOT, TaxonomyIndex


@dataclass(frozen=True)
class Similarity:
    """A similarity value and how it was reached.

    ``situation`` is "exact", "situation-1", "situation-2", "situation-3" for Sem-Str, or the
    baseline's name; ``common`` is the most specific common ancestor where the taxonomy was used.
    """

    value: float
    situation: str
    common: str | None = None
    links: tuple[int, int] | None = None
    qualified: float = 1.0  # the factor for differing complementary words (SemStr.qualifier_factor), applied

    def explain(self) -> str:
        text = self._explain()
        if self.qualified < 1:
            text += f"; complementary words differ: x{self.qualified:.2f}"
        return text

    def _explain(self) -> str:
        if self.situation == "exact":
            return "same concept"
        if self.situation == "situation-1":
            assert self.links is not None
            via = "the root" if self.common == ROOT else local_name(self.common or "")
            return f"1/(1+N), N={sum(self.links)} links via {via}"
        if self.situation == "situation-2":
            return f"Wu-Palmer via {local_name(self.common or '')}, links {self.links}"
        if self.situation == "outside":
            assert self.links is not None
            return f"not in the taxonomy: placed under the root, 1/(1+N), N={sum(self.links)} links via the root"
        if self.situation == "situation-3":
            return "no taxonomy: Jaro-Winkler or WordNet on core and complementary words"
        if self.situation == "cross-branch":
            return "related only through the root; core words the same or WordNet neighbours"
        if self.situation == "unrelated-predicates":
            return "predicates related only through the root: another relation (unrelated_predicate_factor)"
        if self.situation == "inherited":
            return "a part the advertised subclass inherits"
        if self.situation == "delivered":
            assert self.links is not None
            return f"delivered as a subclass, {self.links[0]} is-a links below: 1 - step x links"
        if self.situation == "narrower":
            assert self.links is not None
            return f"the advertised input is {self.links[0]} is-a links below the one offered: 1 - step x links"
        if self.situation == "plug-in":
            return "offered as the advertised input or a subclass of it: invocable"
        return self.situation


class EntityMeasure(Protocol):
    name: str

    def __call__(self, first: str, second: str) -> Similarity: ...


class SemStr:
    """The paper's Sem-Str similarity (Definition 1)."""

    name = "sem-str"

    def __init__(self, index: TaxonomyIndex, config: MatchConfig | None = None, lexicon: Lexicon | None = None) -> None:
        self.index = index
        self.config = config or MatchConfig()
        if lexicon is None:
            lexicon = bundled(self.config.lexical_links) if self.config.lexicon else Lexicon.empty()
        self.lexicon = lexicon
        self._cache: dict[tuple[str, str], Similarity] = {}
        self._words: dict[tuple[str, str], float] = {}
        self._factors: dict[tuple[str, str], float] = {}
        self._splits: dict[str, tuple[str, str]] = {}

    def __call__(self, first: str, second: str) -> Similarity:
        key = (first, second)
        found = self._cache.get(key)
        if found is None:
            found = self._compute(first, second)
            self._cache[key] = found
        return found

    def _compute(self, first: str, second: str) -> Similarity:
        index = self.index
        if first == second or (first in index and index.canonical(first) == index.canonical(second)):
            return Similarity(1.0, "exact", first, (0, 0))
        if first not in index or second not in index:
            return self.outside(first, second)
        common, n1, n2 = index.common_ancestor(first, second)
        if common != ROOT and 0 in (n1, n2):
            # One is a subclass of the other: Wu-Palmer is positive here (C is the upper one).
            nr = index.depth(common)
            return Similarity(2 * nr / (n1 + n2 + 2 * nr), "situation-2", common, (n1, n2))
        found = self._unrelated(first, second, common, n1, n2)
        factor = self.qualifier_factor(index.canonical(first), index.canonical(second))
        return replace(found, value=found.value * factor, qualified=factor) if factor < 1 else found

    def qualifier_factor(self, first: str, second: str) -> float:
        """(1 - w) + w Comp(complementary words) for two concepts that are not is-a related and both have
        complementary words, else 1 (w = MatchConfig.complement_weight). Their complementary words say
        what each is about: PersonLocation and RobotLocation are both Locations, of different things."""
        if not self.config.complement_weight:
            return 1.0
        return self.complement_factor(self._split(first)[1], self._split(second)[1])

    def complement_factor(self, first: str, second: str) -> float:
        """qualifier_factor from two names' complementary words (space-separated; cached by pair)."""
        weight = self.config.complement_weight
        if not weight or not first or not second:
            return 1.0
        key = (first, second)
        found = self._factors.get(key)
        if found is None:
            similarity = complement_similarity(first.split(), second.split(), self.word_similarity)
            found = self._factors[key] = 1 - weight + weight * similarity
        return found

    def _unrelated(self, first: str, second: str, common: str, n1: int, n2: int) -> Similarity:
        """Sem-Str of two taxonomy concepts neither of which is an is-a descendant of the other."""
        index = self.index
        # Situation 1, where Wu-Palmer would give zero or says nothing: one entity lies below the
        # other through a hasPart link (a part is a "leaf" of its whole), or their most specific
        # common superclass is the root.
        up = index.distance_down(first, second)
        if up is not None:
            return Similarity(1 / (1 + up), "situation-1", index.canonical(second), (up, 0))
        down = index.distance_down(second, first)
        if down is not None:
            return Similarity(1 / (1 + down), "situation-1", index.canonical(first), (0, down))
        if common == ROOT:
            through_root = Similarity(1 / (1 + n1 + n2), "situation-1", ROOT, (n1, n2))
            lexical = self.cross_branch(first, second)
            return lexical if lexical.value > through_root.value else through_root
        nr = index.depth(common)
        return Similarity(2 * nr / (n1 + n2 + 2 * nr), "situation-2", common, (n1, n2))

    def outside(self, first: str, second: str) -> Similarity:
        """Two entities, one or both outside the taxonomy: Situation 3 (their names). With unknown_under_root,
        one outside the taxonomy hangs from the root as a class without a declared parent does (section 1 of
        docs/matchmaking.md), so against a taxonomy node of depth d it scores at least Situation 1 through
        the root, 1 / (1 + 1 + d): an undeclared concept is no further from a declared one than two declared
        concepts that meet only at the root. Two entities outside it keep Situation 3: nothing places them."""
        found = self.situation_3(first, second)
        index = self.index
        if not self.config.unknown_under_root or (first in index) == (second in index):
            return found
        depth = index.depth(first if first in index else second)
        if 1 / (2 + depth) <= found.value:
            return found
        links = (depth, 1) if first in index else (1, depth)
        return Similarity(1 / (2 + depth), "outside", ROOT, links)

    def core_key(self, concept: str) -> str:
        """The lemma of a concept's core word: what cross-branch links are looked up by."""
        return self.lexicon.lemma(self._split(concept)[0])

    def predicate(self, first: str, second: str) -> Similarity:
        """Two predicates of RDF statements. Related by the property hierarchy (or not both in it): Sem-Str.
        Related only through the root: unrelated_predicate_factor times Sem-Str, or the cross-branch
        value of a namesake if higher. A property hierarchy is flat: Situation 1 gives two unrelated
        top-level properties 1/3, which says nothing about how alike two relations are."""
        found = self(first, second)
        factor = self.config.unrelated_predicate_factor
        if found.situation == "outside" and factor < 1:  # a predicate placed under the root: another relation
            named = self.situation_3(first, second)
            if named.value >= factor * found.value:
                return named
            return replace(found, value=factor * found.value, situation="unrelated-predicates")
        if factor >= 1 or not self.through_root_only(first, second):
            return found
        namesake = self.cross_branch(first, second)
        if namesake.value > 0 and namesake.value >= factor * found.value:
            return namesake
        return replace(found, value=factor * found.value, situation="unrelated-predicates")

    def through_root_only(self, first: str, second: str) -> bool:
        """Two different taxonomy nodes whose only relation is through the root (no is-a or has-part path)."""
        index = self.index
        if first not in index or second not in index or index.canonical(first) == index.canonical(second):
            return False
        if index.common_ancestor(first, second)[0] != ROOT:
            return False
        return index.distance_down(first, second) is None and index.distance_down(second, first) is None

    def cross_branch(self, first: str, second: str) -> Similarity:
        """Two concepts the taxonomy relates only through the root: Situation 3 times
        cross_branch_weight when their core words are the same lemma or WordNet neighbours, else 0."""
        a, b = self.core_key(first), self.core_key(second)
        if a != b and self.lexicon.similarity(a, b) <= 0:
            return Similarity(0.0, "cross-branch")
        value = self.config.cross_branch_weight * self.situation_3(first, second).value
        return Similarity(value, "cross-branch", ROOT)

    def word_similarity(self, first: str, second: str) -> float:
        """Two words: the larger of rescaled Jaro-Winkler and the lexicon's similarity."""
        key = (first, second)
        found = self._words.get(key)
        if found is None:
            found = rescaled_jaro_winkler(first, second, self.config.jaro_winkler_floor)
            if found < 1 and self.lexicon:
                found = max(found, self.lexicon.similarity(first, second))
            self._words[key] = found
        return found

    def situation_3(self, first: str, second: str) -> Similarity:
        """Core words and complementary words compared (word_similarity), weighted alpha > beta."""
        core1, rest1 = self._split(first)
        core2, rest2 = self._split(second)
        core = self.word_similarity(core1, core2)
        if not rest1 and not rest2:
            return Similarity(core, "situation-3")  # nothing else to compare: the core word says it all
        if not rest1 or not rest2:
            # One name is the other's core narrowed by k modifier words: a name k steps below, scored
            # as Situation 1 scores a concept k links below another, and only as far as the cores agree.
            extra = len((rest1 or rest2).split())
            value = core * (self.config.alpha + self.config.beta / (1 + extra))
        else:
            rest = complement_similarity(rest1.split(), rest2.split(), self.word_similarity)
            value = self.config.alpha * core + self.config.beta * rest
        return Similarity(min(1.0, max(0.0, value)), "situation-3")

    def _name(self, iri: str) -> str:
        return local_name(iri)

    def _split(self, iri: str) -> tuple[str, str]:
        """core_split of the IRI's local name (cached)."""
        found = self._splits.get(iri)
        if found is None:
            found = self._splits[iri] = core_split(self._name(iri))
        return found


def rescaled_jaro_winkler(first: str, second: str, floor: float) -> float:
    """Jaro-Winkler with chance agreement removed: values at or below ``floor`` (what different words
    reach by sharing letters) become 0, the rest is stretched linearly so that equal words keep 1."""
    if first == second:
        return 1.0
    value = jellyfish.jaro_winkler_similarity(first, second)
    return max(0.0, (value - floor) / (1.0 - floor))


def complement_similarity(first: list[str], second: list[str], word: Callable[[str, str], float] | float) -> float:
    """Complementary words compared word by word, in any order: each word's best ``word`` similarity (a
    function, or a Jaro-Winkler floor for rescaled_jaro_winkler) against the other side's words, averaged
    over the words of both sides (symmetric)."""
    if not first or not second:
        return 0.0
    if not callable(word):
        floor = word

        def word(a: str, b: str) -> float:
            return rescaled_jaro_winkler(a, b, floor)

    best_first = [max(word(a, b) for b in second) for a in first]
    best_second = [max(word(a, b) for a in first) for b in second]
    return (sum(best_first) + sum(best_second)) / (len(first) + len(second))


class WuPalmer:
    """Wu and Palmer alone: 2Nr/(N1+N2+2Nr); zero when the common ancestor is the root."""

    name = "wu-palmer"

    def __init__(self, index: TaxonomyIndex) -> None:
        self.index = index

    def __call__(self, first: str, second: str) -> Similarity:
        if first == second:
            return Similarity(1.0, "exact")
        if first not in self.index or second not in self.index:
            return Similarity(0.0, "wu-palmer: not in the taxonomy")
        common, n1, n2 = self.index.common_ancestor(first, second)
        nr = self.index.depth(common)
        if n1 + n2 + nr == 0:
            return Similarity(1.0, "exact")
        return Similarity(2 * nr / (n1 + n2 + 2 * nr), "wu-palmer", common, (n1, n2))


class Lin:
    """Lin's information-theoretic similarity, 2 IC(C) / (IC(e1) + IC(e2)).

    Information content comes from the loaded knowledge, not from an external corpus: a concept's
    probability is (uses of it and of everything below it + nodes below it) / the same for the root,
    with uses counted over the service descriptions in the store.
    """

    name = "lin"

    def __init__(self, index: TaxonomyIndex) -> None:
        self.index = index
        # Each node adds its weight to itself and to every ancestor once, even with several parents.
        totals: dict[str, float] = {}
        for node in index.nodes():
            weight = 1 + index.frequency.get(node, 0)
            for ancestor in index.ancestors(node):
                totals[ancestor] = totals.get(ancestor, 0.0) + weight
        root_total = totals.get(ROOT, 1.0)
        self._ic = {node: -math.log(total / root_total) for node, total in totals.items()}

    def __call__(self, first: str, second: str) -> Similarity:
        if first == second:
            return Similarity(1.0, "exact")
        if first not in self.index or second not in self.index:
            return Similarity(0.0, "lin: not in the taxonomy")
        common, _, _ = self.index.common_ancestor(first, second)
        ic1 = self._ic[self.index.canonical(first)]
        ic2 = self._ic[self.index.canonical(second)]
        if ic1 + ic2 == 0:
            return Similarity(1.0, "exact")
        return Similarity(min(1.0, 2 * self._ic[common] / (ic1 + ic2)), "lin", common)


class StringMatch:
    """Pure string matching, the paper's baseline: two entities match when their names are the same
    string (case, and the separators of camelCase, snake_case and kebab-case, ignored), else not.
    (Position and Location "cannot be matched according to a pure string matching standard".)"""

    name = "string"

    def __call__(self, first: str, second: str) -> Similarity:
        same = words(local_name(first)) == words(local_name(second)) or first == second
        return Similarity(1.0 if same else 0.0, "string")
