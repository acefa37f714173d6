"""The hybrid method sem-str-text: Sem-Str's IO/PE score with the TF-IDF cosine of names and descriptions."""

from __future__ import annotations

import json

import pytest
from click.testing import CliRunner
from hypothesis import given, settings
from hypothesis import strategies as st

from cbrs.cli import cli
from cbrs.kb import Advertisement, KnowledgeBase, Parameter, Requirement, Store
from cbrs.reasoner.config import MatchConfig
from cbrs.reasoner.matchmaker import Matchmaker
from cbrs.reasoner.text import TextIndex, description_text
from tests.reasoner_examples import E, positions


def _output(concept: str) -> Parameter:
    return Parameter(f"{E}out-{concept}", "output", E + concept)


# Same outputs, so Sem-Str ties them (and the IRI puts A_ first); only their texts differ.
POOL = [
    Advertisement(
        E + "A_ReadLight",
        (),
        label="ReadLight",
        comment="Reports the colour of the ceiling light.",
        outputs=(_output("Position"),),
    ),
    Advertisement(
        E + "B_LocateRobot",
        (),
        label="LocateRobot",
        comment="Reports where the mobile robot is.",
        outputs=(_output("Position"),),
    ),
    Advertisement(E + "C_NoText", (), outputs=(_output("Location"),)),
]
WITH_TEXT = Requirement(
    E + "Where", (), label="Locate the robot", comment="Where is the robot?", outputs=(_output("Position"),)
)
WITHOUT_TEXT = Requirement(E + "Silent", (), outputs=(_output("Position"),))


def _rank(method: str, requirement: Requirement, config: MatchConfig | None = None) -> list[str]:
    matcher = Matchmaker(KnowledgeBase(Store.open(":memory:")), method, config, index=positions(), advertisements=POOL)
    return [c.advertisement.removeprefix(E) for c in matcher.rank(requirement).candidates]


def test_text_ranks_a_service_whose_description_matches_up() -> None:
    assert _rank("sem-str", WITH_TEXT)[:2] == ["A_ReadLight", "B_LocateRobot"]  # a tie, broken by IRI
    assert _rank("sem-str-text", WITH_TEXT)[:2] == ["B_LocateRobot", "A_ReadLight"]
    # the weight is a setting: at 0 the hybrid is Sem-Str
    assert _rank("sem-str-text", WITH_TEXT, MatchConfig(text_weight=0.0))[:2] == ["A_ReadLight", "B_LocateRobot"]


def test_the_text_part_is_shown_and_does_not_decide_acceptability() -> None:
    kb = KnowledgeBase(Store.open(":memory:"))
    strict = MatchConfig(accept_score=0.95)
    hybrid = Matchmaker(kb, "sem-str-text", strict, index=positions(), advertisements=POOL).rank(WITH_TEXT)
    plain = Matchmaker(kb, "sem-str", strict, index=positions(), advertisements=POOL).rank(WITH_TEXT)
    by_iri = {c.advertisement: c for c in plain.candidates}
    for candidate in hybrid.candidates:
        assert 0.0 <= candidate.parts["text"] <= 1.0
        assert candidate.acceptable == by_iri[candidate.advertisement].acceptable  # IO/PE alone decides
    assert hybrid.candidates[0].parts["text"] > 0.3
    no_text = next(c for c in hybrid.candidates if c.advertisement == E + "C_NoText")
    assert no_text.parts["text"] == 0.0


def test_without_a_requirement_text_the_hybrid_is_sem_str() -> None:
    kb = KnowledgeBase(Store.open(":memory:"))
    hybrid = Matchmaker(kb, "sem-str-text", index=positions(), advertisements=POOL).rank(WITHOUT_TEXT)
    plain = Matchmaker(kb, "sem-str", index=positions(), advertisements=POOL).rank(WITHOUT_TEXT)
    assert [(c.advertisement, c.score) for c in hybrid.candidates] == [
        (c.advertisement, c.score) for c in plain.candidates
    ]
    assert all("text" not in c.parts for c in hybrid.candidates)


def test_description_text_and_a_pool_without_words() -> None:
    assert description_text(POOL[0]) == "ReadLight Reports the colour of the ceiling light."
    assert description_text(POOL[2]) == ""
    empty = TextIndex([POOL[2]])
    assert empty.similarities("locate the robot").tolist() == [0.0]
    assert empty.similarity("locate the robot", POOL[0]) == 0.0


def test_text_of_a_description_outside_the_pool_is_compared_too() -> None:
    index = TextIndex(POOL[:2])
    inside = index.similarity("where is the mobile robot", POOL[1])
    assert inside == pytest.approx(index.similarities("where is the mobile robot")[1])
    outside = Advertisement(E + "Z", (), label="RobotLocator", comment="Where the mobile robot is.")
    assert 0.0 < index.similarity("where is the mobile robot", outside) <= 1.0


texts = st.lists(st.sampled_from(["robot", "colour", "light", "position", "MobileRobot", "the", "7", "x"]), max_size=6)


@settings(max_examples=80, deadline=None)
@given(st.lists(texts, min_size=1, max_size=4), texts)
def test_text_similarity_lies_in_unit_range_and_a_pool_text_matches_itself(
    pool: list[list[str]], query: list[str]
) -> None:
    ads = [Advertisement(f"{E}ad{i}", (), comment=" ".join(words)) for i, words in enumerate(pool)]
    index = TextIndex(ads)
    values = index.similarities(" ".join(query))
    assert values.shape == (len(ads),)
    assert ((values >= 0) & (values <= 1)).all()
    first = index.similarities(" ".join(pool[0]))[0]
    assert first == pytest.approx(1.0) or first == 0.0  # 0 only for a text without a known word


def test_cbrs_match_offers_the_hybrid() -> None:
    result = CliRunner().invoke(
        cli, ["--store", ":memory:", "match", "req:RobotSelfPosition", "--method", "sem-str-text", "--json"]
    )
    assert result.exit_code == 0, result.output
    data = json.loads(result.output)
    assert data["method"] == "sem-str-text" and "text" in data["candidates"][0]["parts"]
