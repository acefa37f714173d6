"""What makes ranking a large pool cheap keeps its answers: explanations made when read, and the common
superclasses of the is-a tree found by pre-order ranges (reasoner/vectors.py) next to the general walk."""

from __future__ import annotations

import random

import numpy as np
import pytest

from cbrs.kb import KnowledgeBase, Requirement, Store
from cbrs.reasoner.antonyms import opposite
from cbrs.reasoner.matchmaker import Candidate, Matchmaker
from cbrs.reasoner.similarity import SemStr
from cbrs.reasoner.synthetic import NS, build
from cbrs.reasoner.taxonomy import ROOT, Link, TaxonomyIndex
from cbrs.reasoner.vectors import VectorSpace


def _pool(seed: int = 4) -> tuple[Matchmaker, list[Requirement]]:
    index, pool, requirements = build(classes=300, ads=120, queries=3, seed=seed)
    return Matchmaker(KnowledgeBase(Store.open(":memory:")), index=index, advertisements=pool), requirements


def test_a_ranking_explains_a_candidate_when_it_is_read() -> None:
    matchmaker, requirements = _pool()
    calls: list[str] = []
    scalar = matchmaker.score

    def counted(requirement: Requirement, ad):  # type: ignore[no-untyped-def]
        calls.append(ad.iri)
        return scalar(requirement, ad)

    matchmaker.score = counted  # type: ignore[method-assign]
    result = matchmaker.rank(requirements[0], explain=5)
    assert calls == []  # ranking, and the status, explain nothing
    third = result.candidates[2]
    assert calls == [third.advertisement] and third.explained
    assert result.candidates[2] is third  # made once
    ad = next(a for a in matchmaker.advertisements if a.iri == third.advertisement)
    assert third == scalar(requirements[0], ad)
    assert not result.candidates[5].explained and calls == [third.advertisement]


def test_a_lazy_ranking_reads_as_an_eager_one() -> None:
    matchmaker, requirements = _pool(seed=6)
    by_iri = {ad.iri: ad for ad in matchmaker.advertisements}
    for requirement in requirements:
        result = matchmaker.rank(requirement, explain=4)
        candidates: list[Candidate] = list(result.candidates)
        plain = matchmaker.rank(requirement, explain=0).candidates
        assert [c.advertisement for c in candidates] == [c.advertisement for c in plain]
        assert candidates[:4] == [matchmaker.score(requirement, by_iri[c.advertisement]) for c in candidates[:4]]
        assert all(c.explained for c in candidates[:4]) and not any(c.explained for c in candidates[4:])
        assert result.status.value == ("matched" if candidates[0].acceptable else "no-acceptable-match")
        assert result.to_dict(4)["candidates"] == [c.to_dict() for c in candidates[:4]]


def _tangled(seed: int) -> TaxonomyIndex:
    """A random is-a tree of 200 classes, then 40 more is-a links: classes with two or three ways up
    (and their descendants) sit outside the tree the ranges cover."""
    rng = random.Random(seed)
    names = [f"{NS}T{i}" for i in range(200)]
    links = [Link(names[0], ROOT, "is-a")]
    links += [Link(names[i], names[rng.randrange(max(0, i // 2 - 10), i)], "is-a") for i in range(1, 200)]
    for _ in range(40):
        child = rng.randrange(20, 200)
        links.append(Link(names[child], names[rng.randrange(0, child)], "is-a"))
    links += [Link(names[rng.randrange(100, 200)], names[rng.randrange(0, 100)], "has-part") for _ in range(20)]
    return TaxonomyIndex.from_links(links)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_wu_palmer_vectors_equal_the_scalar_measure_with_multiple_inheritance(seed: int) -> None:
    index = _tangled(seed)
    measure = SemStr(index)
    space = VectorSpace(index)
    rng = random.Random(seed)
    for name in rng.sample(index.nodes(), 120):  # vectors are exact where they are read
        space.add(name)
    split = space._read_split()
    assert len(split.tree) and len(split.general)  # both ways of finding the common superclass are used
    read = [space.names[i] for i in space._read_at()]
    for concept in rng.sample(read, 25):
        vector = space.vector(measure, concept)
        for other in read:
            assert vector[space.ids[other]] == pytest.approx(measure(concept, other).value), (concept, other)


def test_the_common_superclass_table_names_the_deepest_shared_superclass() -> None:
    index = _tangled(5)
    space = VectorSpace(index)
    for name in index.nodes():
        space.add(name)
    for concept in random.Random(5).sample(index.nodes(), 15):
        table = space.common_superclasses(concept)
        assert table is not None
        for other in index.nodes():
            found, _, _ = index.common_ancestor(concept, other)
            assert space.names[int(table[space.ids[other]])] == found, (concept, other)
    assert np.all(space._tree().pure[[space.ids[ROOT], space.ids[NS + "T0"]]])


def test_opposite_names_are_found_by_their_forms_as_pair_by_pair() -> None:
    words = ["Opened", "Open", "Closed", "Close", "Locked", "Unlocked", "DoorOpening", "On", "Off", "Full"]
    words += ["Empty", "LightOn", "X", "Stopped", "Started", "Door", "HasState"]
    index = TaxonomyIndex.from_links([Link(NS + w, ROOT, "is-a") for w in words[:12]])
    space = VectorSpace(index)
    for name in words:  # the last ones are outside the taxonomy
        space.add(NS + name)
    found_any = False
    for first in words:
        mask = space.opposites(NS + first)
        for second in words:
            expected = opposite(NS + first, NS + second)
            found_any |= expected
            assert bool(mask[space.ids[NS + second]]) == expected, (first, second)
    assert found_any


@pytest.mark.parametrize("seed", [1, 4])
def test_parts_worked_out_superclasses_first_are_the_inherited_ones(seed: int) -> None:
    index = _tangled(seed)
    expected = {
        node: frozenset(
            child
            for owner in index.ancestors(node, is_a_only=True)
            if owner != ROOT
            for child, kind in index.child_links(owner)
            if kind == "has-part"
        )
        for node in index.nodes()
    }
    assert any(expected.values())
    assert index._all_parts() == expected
    assert {node: index.parts_of(node) for node in index.nodes()} == expected


def test_implied_parts_answer_element_by_element_as_parts_of() -> None:
    index = _tangled(2)
    space = VectorSpace(index)
    nodes = index.nodes()
    rng = random.Random(2)
    wholes = np.array([space.ids[rng.choice(nodes)] for _ in range(500)], dtype=np.int64)
    parts = np.array([space.ids[rng.choice(nodes)] for _ in range(500)], dtype=np.int64)
    for few in (wholes, wholes % 7 + space.ids[nodes[0]]):  # many distinct superclasses, then a few
        found = space.implied(few, parts)
        expected = [space.names[p] in index.parts_of(space.names[w]) for w, p in zip(few, parts, strict=True)]
        assert found.tolist() == expected
    assert any(expected)


@pytest.mark.parametrize("longest", [1, 3, 8, 12])
def test_segment_reductions_by_padded_rows_equal_reduceat(longest: int) -> None:
    from cbrs.reasoner.batch import _Segments

    rng = np.random.default_rng(longest)
    values = rng.random(300) * rng.choice([1e-3, 1.0, 1e3], 300)
    for low in (0, 1):  # with empty segments, then without
        lists = [rng.integers(0, 300, int(rng.integers(low, longest + 1))).tolist() for _ in range(2000)]
        segments = _Segments(lists)
        present = [i for i, items in enumerate(lists) if items]
        starts = np.cumsum([0] + [len(items) for items in lists])[:-1][present]
        flat = np.array([i for items in lists for i in items], dtype=np.int64)
        maxima, means = np.zeros(len(lists)), np.zeros(len(lists))
        maxima[present] = np.maximum.reduceat(values[flat], starts)
        means[present] = np.add.reduceat(values[flat], starts) / np.array([len(lists[i]) for i in present])
        assert np.array_equal(segments.max(values), maxima)
        assert np.array_equal(segments.mean(values), means)  # the same sums, bit for bit


def test_an_unavailable_component_is_left_out_and_the_explained_head_is_of_those_available() -> None:
    kb = KnowledgeBase.open(":memory:")
    requirement = "https://w3id.org/cbrs/requirement#RobotSelfPosition"
    before = [c.advertisement for c in Matchmaker(kb).rank(requirement, explain=3).candidates]
    kb.liveness.renew(before[1], ttl=60)
    kb.liveness.expire(before[1], "its session closed")
    result = Matchmaker(kb).rank(requirement, explain=3)
    after = list(result.candidates)
    assert [c.advertisement for c in after] == [iri for iri in before if iri != before[1]]
    assert [c.explained for c in after[:4]] == [True, True, True, False]
    assert len(result.candidates) == len(before) - 1
