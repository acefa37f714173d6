from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cbrs.reasoner.config import MatchConfig
from cbrs.reasoner.degrees import Degree, degree_of_match
from cbrs.reasoner.names import core_split, local_name, words
from cbrs.reasoner.similarity import Lin, SemStr, StringMatch, WuPalmer, complement_similarity, rescaled_jaro_winkler
from cbrs.reasoner.taxonomy import ROOT, Link, TaxonomyIndex
from tests.reasoner_examples import E, figure5, positions


def test_figure5_sim_c_e_is_two_thirds() -> None:
    sim = SemStr(figure5())(E + "C", E + "E")
    assert sim.situation == "situation-2"
    assert round(sim.value, 2) == 0.67


def test_figure5_child_of_the_root_is_not_zero() -> None:
    index = figure5()
    assert WuPalmer(index)(E + "B", ROOT).value == 0.0
    sim = SemStr(index)(E + "B", ROOT)
    assert (sim.situation, sim.value) == ("situation-1", 0.5)


def test_figure5_far_apart_through_the_root_is_small() -> None:
    sim = SemStr(figure5())(E + "E", E + "D")
    assert sim.situation == "situation-1"
    assert sim.value == pytest.approx(1 / (1 + 3 + 2))


@pytest.mark.parametrize(
    ("first", "second", "situation", "value"),
    [
        pytest.param("RobotPosition", "RobotPosition", "exact", 1.0, id="exact"),
        # a subclass: Wu-Palmer with C the superclass (depth 3), N1 = 1, N2 = 0
        pytest.param("RobotPosition", "Position", "situation-2", 2 * 3 / (1 + 2 * 3), id="subclass"),
        pytest.param("Position", "RobotPosition", "situation-2", 2 * 3 / (1 + 2 * 3), id="superclass"),
        # a part below its whole: Wu-Palmer would use an unrelated superclass; Situation 1 instead
        pytest.param("XCoordinate", "Position", "situation-1", 0.5, id="part-of-whole"),
        pytest.param("RobotPosition", "ColourOfMarker", "situation-1", 1 / (1 + 4 + 3), id="through-the-root"),
        pytest.param("RobotPosition", "RobotLocation", "situation-2", 2 * 2 / (2 + 2 + 2 * 2), id="position-location"),
        pytest.param("Position", "Location", "situation-2", 2 * 2 / (1 + 1 + 2 * 2), id="siblings"),
    ],
)
def test_sem_str_situations(first: str, second: str, situation: str, value: float) -> None:
    # Definition 1 as the paper gives it: complementary words of unrelated concepts not compared
    sim = SemStr(positions(), MatchConfig(complement_weight=0.0))(E + first, E + second)
    assert sim.situation == situation
    assert sim.value == pytest.approx(value)


def test_unrelated_concepts_with_different_complementary_words_are_further_apart() -> None:
    weight = MatchConfig().complement_weight
    measure = SemStr(positions())
    plain = SemStr(positions(), MatchConfig(complement_weight=0.0))
    # RobotPosition and ColourOfMarker meet at the root; "robot" shares nothing with "colour of"
    far = measure(E + "RobotPosition", E + "ColourOfMarker")
    assert far.value == pytest.approx((1 - weight) * plain(E + "RobotPosition", E + "ColourOfMarker").value)
    assert far.qualified == pytest.approx(1 - weight) and "complementary words differ" in far.explain()
    # the same complementary word: unchanged; a subclass keeps its Wu-Palmer value whatever its words
    assert (
        measure(E + "RobotPosition", E + "RobotLocation").value == plain(E + "RobotPosition", E + "RobotLocation").value
    )
    assert measure(E + "RobotPosition", E + "Position").value == plain(E + "RobotPosition", E + "Position").value


def test_situation_3_uses_core_words() -> None:
    measure = SemStr(positions(), MatchConfig(alpha=0.7, beta=0.3))
    same_core = measure(E + "RobotPlace", E + "PersonPlace")  # neither is in the taxonomy
    other_core = measure(E + "RobotPlace", E + "RobotSpeed")
    assert same_core.situation == other_core.situation == "situation-3"
    assert same_core.value > other_core.value  # the core word weighs more (alpha > beta)
    assert measure(E + "Place", E + "Place").value == 1.0
    # no complementary words on either side: the core words alone decide, no free share
    lone = measure(E + "Status", E + "Temperature")
    assert lone.value < 0.7


def test_situation_3_gives_nothing_for_chance_agreement_between_head_words() -> None:
    # Raw Jaro-Winkler gives "status" and "temperature" 0.68 (shared letters) and door / indoor 0.89:
    # DoorStatus reached 0.74 against an undeclared IndoorTemperature. Below the floor it is chance.
    measure = SemStr(positions())
    assert rescaled_jaro_winkler("status", "temperature", 0.65) < 0.1
    unrelated = measure(E + "DoorStatus", E + "IndoorTemperature")
    assert unrelated.situation == "situation-3" and unrelated.value < 0.3
    raw = SemStr(positions(), MatchConfig(jaro_winkler_floor=0.0))(E + "DoorStatus", E + "IndoorTemperature")
    assert raw.value > 0.5  # what the floor removes


def test_situation_3_a_narrowed_name_keeps_most_of_its_head() -> None:
    # FullyOpened is Opened narrowed by one modifier word: alpha + beta / (1 + 1) of the core's value.
    measure = SemStr(positions())
    assert measure(E + "FullyOpened", E + "Opened").value == pytest.approx(0.7 + 0.3 / 2)
    assert measure(E + "FullyOpened", E + "Closed").value < 0.2  # only as far as the cores agree
    # ... and more than a name whose modifier is unrelated to the other's
    assert measure(E + "FullyOpened", E + "Opened").value > measure(E + "RobotPlace", E + "PersonPlace").value


def test_complementary_words_compare_word_by_word_in_any_order() -> None:
    assert complement_similarity(["fall", "down"], ["down", "fall"], 0.65) == 1.0
    assert complement_similarity(["mobile", "robot"], ["robot"], 0.65) == pytest.approx(2 / 3)
    assert complement_similarity(["obstacle", "detected"], ["person", "fall", "down"], 0.65) == 0.0


def test_names() -> None:
    assert local_name("http://x/onto.owl#RobotPosition") == "RobotPosition"
    assert words("GPSPosition_of-robot") == ["gps", "position", "of", "robot"]
    assert core_split("RobotPosition") == ("position", "robot")
    assert core_split("Position") == ("position", "")


def test_degrees() -> None:
    index = positions()
    assert degree_of_match(index, E + "Position", E + "Position") is Degree.EXACT
    assert degree_of_match(index, E + "Position", E + "RobotPosition") is Degree.SUBCLASS_OF
    assert degree_of_match(index, E + "RobotPosition", E + "Position") is Degree.HAS_SUBCLASS
    assert degree_of_match(index, E + "Position", E + "Location") is Degree.FAIL
    assert degree_of_match(index, E + "Position", E + "XCoordinate") is Degree.FAIL  # parts do not subsume
    assert {d for d in Degree if d.accepted} == {Degree.EXACT, Degree.SUBCLASS_OF, Degree.HAS_SUBCLASS}


def test_config_is_validated() -> None:
    with pytest.raises(ValueError, match="alpha > beta"):
        MatchConfig(alpha=0.3, beta=0.7)
    with pytest.raises(ValueError, match="sum to 1"):
        MatchConfig(subject_weight=0.5)
    with pytest.raises(ValueError, match="jaro_winkler_floor"):
        MatchConfig(jaro_winkler_floor=1.0)
    with pytest.raises(ValueError, match="text_weight"):
        MatchConfig(text_weight=1.5)


# -- properties over random taxonomies ---------------------------------------------------------

NAMES = [f"C{i}" for i in range(12)]


@st.composite
def taxonomies(draw: st.DrawFn) -> TaxonomyIndex:
    links = []
    for i, name in enumerate(NAMES):
        if i and draw(st.booleans()):
            links.append(Link(E + name, E + NAMES[draw(st.integers(0, i - 1))], "is-a"))
        if i > 1 and draw(st.integers(0, 4)) == 0:
            links.append(Link(E + name, E + NAMES[draw(st.integers(0, i - 1))], "has-part"))
    return TaxonomyIndex.from_links(links, terms=[E + n for n in NAMES])


concepts = st.sampled_from([E + n for n in NAMES] + [E + "RobotPlace", E + "Unknown_Thing", ROOT])


@settings(max_examples=150, deadline=None)
@given(taxonomies(), concepts, concepts)
def test_every_measure_is_in_unit_range_and_symmetric(index: TaxonomyIndex, a: str, b: str) -> None:
    for measure in (SemStr(index), WuPalmer(index), Lin(index), StringMatch()):
        forward, backward = measure(a, b).value, measure(b, a).value
        assert 0.0 <= forward <= 1.0
        assert forward == pytest.approx(backward)


@settings(max_examples=80, deadline=None)
@given(taxonomies(), concepts)
def test_exact_gives_one(index: TaxonomyIndex, a: str) -> None:
    for measure in (SemStr(index), WuPalmer(index), Lin(index), StringMatch()):
        assert measure(a, a).value == 1.0


word_lists = st.lists(st.text("abcdeor", min_size=1, max_size=8), max_size=4)


@settings(max_examples=150, deadline=None)
@given(word_lists, word_lists, st.floats(0.0, 0.99))
def test_name_measures_are_in_unit_range_symmetric_and_one_for_equal_words(
    first: list[str], second: list[str], floor: float
) -> None:
    value = complement_similarity(first, second, floor)
    assert 0.0 <= value <= 1.0
    assert value == pytest.approx(complement_similarity(second, first, floor))
    for a, b in zip(first, second, strict=False):
        assert 0.0 <= rescaled_jaro_winkler(a, b, floor) <= 1.0
        assert rescaled_jaro_winkler(a, a, floor) == 1.0
    if first:
        assert complement_similarity(first, first, floor) == 1.0
