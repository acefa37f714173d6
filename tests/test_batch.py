"""The batch scorer gives the same scores as the scalar matchmaker, on every pool we have."""

from __future__ import annotations

import random
from pathlib import Path

import numpy as np
import pytest

from cbrs.kb import KnowledgeBase, Store
from cbrs.reasoner.matchmaker import Matchmaker
from cbrs.reasoner.methods import METHODS
from cbrs.reasoner.owlstc import load_collection
from cbrs.reasoner.similarity import SemStr
from cbrs.reasoner.synthetic import build
from cbrs.reasoner.vectors import VectorSpace
from tests.reasoner_examples import E, positions

ROBOT = Path(__file__).parent / "data" / "robot_services"


def _assert_same(matchmaker: Matchmaker, requirement) -> None:  # type: ignore[no-untyped-def]
    result = matchmaker.rank(requirement, explain=0)
    batch = {c.advertisement: c for c in result.candidates}
    for ad in matchmaker.advertisements:
        scalar = matchmaker.score(requirement, ad)
        fast = batch[ad.iri]
        assert fast.score == pytest.approx(scalar.score, abs=1e-6), ad.iri
        assert fast.parts.keys() == scalar.parts.keys(), ad.iri
        assert fast.rejected_by == scalar.rejected_by
        assert fast.acceptable == scalar.acceptable


@pytest.mark.parametrize("method", METHODS)
def test_batch_equals_scalar_on_the_bundled_home(bundled_kb: KnowledgeBase, method: str) -> None:
    base = Matchmaker(bundled_kb)
    matchmaker = Matchmaker(bundled_kb, method, index=base.index, advertisements=base.advertisements)
    for requirement in bundled_kb.requirements():
        _assert_same(matchmaker, requirement)


@pytest.mark.parametrize("method", ["sem-str", "logic"])
@pytest.mark.parametrize("seed", [1, 2, 3])
def test_batch_equals_scalar_on_random_pools(seed: int, method: str) -> None:
    index, pool, requirements = build(classes=300, ads=150, queries=4, seed=seed)
    matchmaker = Matchmaker(KnowledgeBase(Store.open(":memory:")), method, index=index, advertisements=pool)
    for requirement in requirements:
        _assert_same(matchmaker, requirement)


@pytest.fixture(scope="module")
def robot_kb() -> KnowledgeBase:
    """The robot collection, loaded once for both methods (they only read it)."""
    return load_collection(ROBOT).kb


@pytest.mark.parametrize("method", ["sem-str", "logic"])
def test_batch_equals_scalar_on_the_robot_collection(robot_kb: KnowledgeBase, method: str) -> None:
    # OWL-S services with effects, and requests with effects and inputs only
    kb = robot_kb
    matchmaker = Matchmaker(kb, method)
    for requirement in kb.requirements():
        _assert_same(matchmaker, requirement)


def test_sem_str_vector_equals_scalar() -> None:
    index = positions()
    measure = SemStr(index)
    space = VectorSpace(index, extra=[E + "RobotPlace", E + "Somewhere"])
    for name in list(space.names):  # vectors are exact where the space handed out ids
        space.add(name)
    rng = random.Random(0)
    for concept in [*space.names, E + "RobotPlace", E + "Elsewhere"]:
        vector = space.vector(measure, concept)
        for other in rng.sample(space.names, min(12, len(space.names))):
            assert vector[space.ids[other]] == pytest.approx(measure(concept, other).value), (concept, other)
    assert np.all((vector >= 0) & (vector <= 1))


def test_explained_candidates_come_first_and_the_rest_carry_scores(bundled_kb: KnowledgeBase) -> None:
    result = Matchmaker(bundled_kb).rank("https://w3id.org/cbrs/requirement#RobotSelfPosition", explain=3)
    assert [c.explained for c in result.candidates[:4]] == [True, True, True, False]
    assert result.candidates[0].pairs and not result.candidates[5].pairs
    scores = [c.score for c in result.candidates if c.acceptable]
    assert scores == sorted(scores, reverse=True)
