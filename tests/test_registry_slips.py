"""A misspelt required part of a description (a parameter's type, a condition's predicate or object) is
refused with a did-you-mean naming the property the node has instead (kb/registry.py): it was reported
as missing only, while a misspelt optional one got its did-you-mean from the shapes."""

from __future__ import annotations

from pathlib import Path

import pytest

from cbrs.kb import KnowledgeBase
from cbrs.kb.errors import InvalidDescriptionError

DOOR = Path(__file__).parent.parent / "docs" / "examples" / "lab_open_door.ttl"


@pytest.mark.parametrize(
    ("right", "slip"),
    [
        ("cbrs:parameterType", "cbrs:parameterTyp"),
        ("cbrs:conditionPredicate", "cbrs:conditionPredicat"),
        ("cbrs:conditionObject", "cbrs:conditionObjekt"),
    ],
)
def test_a_misspelt_required_part_gets_a_did_you_mean(right: str, slip: str) -> None:
    kb = KnowledgeBase.open(":memory:")
    text = DOOR.read_text(encoding="utf-8")
    assert right in text
    before = kb.store.count()
    with pytest.raises(InvalidDescriptionError) as refused:
        kb.registry.register(text.replace(right, slip, 1))
    assert f"it has {slip}: did you mean {right}?" in str(refused.value)
    assert kb.store.count() == before  # nothing of it written


def test_a_part_the_node_has_is_not_offered_for_one_it_lacks() -> None:
    """conditionSubject is as near conditionObject as a misspelling, but it is there in its own right."""
    kb = KnowledgeBase.open(":memory:")
    text = DOOR.read_text(encoding="utf-8")
    lacking = text.replace("cbrs:conditionObject", "cbrs:conditionQuality", 1)
    with pytest.raises(InvalidDescriptionError) as refused:
        kb.registry.register(lacking)
    assert "lacks cbrs:conditionObject" in str(refused.value)
    assert "did you mean" not in str(refused.value).split("lacks cbrs:conditionObject", 1)[1][:80]
