"""A requirement that asks for something to stop being true (a delete effect) is matched on the
advertised delete effects, in the batch and the scalar scorer alike, and by strict logic too."""

from __future__ import annotations

from dataclasses import replace

import pytest

from cbrs.kb import KnowledgeBase, Requirement, Statement
from cbrs.reasoner.config import MatchConfig
from cbrs.reasoner.matchmaker import Matchmaker
from tests.test_batch import _assert_same

SVC = "https://w3id.org/cbrs/service#"
HOME = "https://w3id.org/cbrs/home#"
PICK_UP = SVC + "PickUpObject_CytonDualArm01"  # deletes (PhysicalObject, isLocated, Place)

OFF_ITS_PLACE = Requirement(
    iri="urn:test:TakeTheCupOffItsPlace",
    types=(),
    deletes=(Statement(HOME + "Cup", HOME + "isLocated", HOME + "Place"),),
)


@pytest.fixture(scope="module")
def matchers(bundled_kb: KnowledgeBase) -> dict[str, Matchmaker]:
    base = Matchmaker(bundled_kb)
    return {
        method: Matchmaker(bundled_kb, method, index=base.index, advertisements=base.advertisements)
        for method in ("sem-str", "logic", "wu-palmer")
    }


def test_the_service_that_deletes_the_statement_ranks_first(matchers: dict[str, Matchmaker]) -> None:
    for method, matcher in matchers.items():
        ranked = matcher.rank(OFF_ITS_PLACE).candidates
        assert ranked[0].advertisement == PICK_UP, method
        assert ranked[0].parts["deletes"] > 0.5, method
        assert all(c.parts["deletes"] == 0 for c in ranked if not _deletes(matcher, c.advertisement))


def test_the_explanation_names_the_delete_effect(matchers: dict[str, Matchmaker]) -> None:
    best = matchers["sem-str"].rank(OFF_ITS_PLACE, explain=1).candidates[0]
    pair = next(p for p in best.pairs if p.role == "delete effect")
    assert pair.requested == "(Cup, isLocated, Place)"
    assert pair.advertised == "(PhysicalObject, isLocated, Place)"


def test_strict_logic_rejects_a_service_that_deletes_nothing_asked(matchers: dict[str, Matchmaker]) -> None:
    ranked = matchers["logic"].rank(OFF_ITS_PLACE).candidates
    others = [c for c in ranked if c.advertisement != PICK_UP and not _deletes(matchers["logic"], c.advertisement)]
    assert others and all(any("delete effect (Cup, isLocated, Place)" in r for r in c.rejected_by) for c in others)


def test_batch_and_scalar_agree_with_delete_effects(matchers: dict[str, Matchmaker]) -> None:
    with_effect = replace(OFF_ITS_PLACE, effects=(Statement(HOME + "Cup", HOME + "isGraspedBy", HOME + "Gripper"),))
    for matcher in matchers.values():
        _assert_same(matcher, OFF_ITS_PLACE)
        _assert_same(matcher, with_effect)


def test_delete_weight_weighs_the_part(bundled_kb: KnowledgeBase, matchers: dict[str, Matchmaker]) -> None:
    effect = (Statement(HOME + "Cup", HOME + "isGraspedBy", HOME + "Gripper"),)
    both = replace(OFF_ITS_PLACE, effects=effect)
    effect_only = Requirement(iri="urn:test:HoldTheCup", types=(), effects=effect)
    base = matchers["sem-str"]
    weightless = Matchmaker(
        bundled_kb, "sem-str", MatchConfig(delete_weight=0.0), index=base.index, advertisements=base.advertisements
    )
    plain = {c.advertisement: c.score for c in base.rank(effect_only).candidates}
    weighed = {c.advertisement: c.score for c in base.rank(both).candidates}
    ignored = {c.advertisement: c.score for c in weightless.rank(both).candidates}
    assert ignored == pytest.approx(plain, abs=1e-6)
    assert weighed != pytest.approx(plain, abs=1e-3)


def test_advertised_delete_effects_cost_nothing_when_none_is_asked(matchers: dict[str, Matchmaker]) -> None:
    grasped = Requirement(
        iri="urn:test:HoldTheCup",
        types=(),
        effects=(Statement(HOME + "Cup", HOME + "isGraspedBy", HOME + "Gripper"),),
    )
    best = next(c for c in matchers["sem-str"].rank(grasped).candidates if c.advertisement == PICK_UP)
    assert "deletes" not in best.parts


def _deletes(matcher: Matchmaker, iri: str) -> bool:
    return bool(next(a for a in matcher.advertisements if a.iri == iri).deletes)
